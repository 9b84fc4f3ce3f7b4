// The projector outputs behind the driver plugin ABI (plugins/include/procamd/
// procam_plugin.h): "headless" (EGL surfaceless, frames kept in memory) and, when built,
// "kms" (DRM/KMS scan-out). A frame handed over the ABI is shown 1:1: the output's
// renderer runs the identity homography and the final stage.
#include <procamd/procam_plugin.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>

#include "headless/headless_output.hpp"
#if PROCAM_OUTPUT_PLUGIN_KMS
#include "kms/kms_output.hpp"
#endif

namespace procam::output {
namespace {

struct Device {
  std::unique_ptr<ProjectorOutput> out;
  double refresh_hz = 0;
  cv::Mat rgba;
  uint64_t version = 0;
};

void writeError(char* err, size_t len, const std::string& msg) {
  if (err && len > 0) std::snprintf(err, len, "%s", msg.c_str());
}

int statusOf(ErrorCode code) {
  switch (code) {
    case ErrorCode::kNotFound:
      return PROCAM_ENODEV;
    case ErrorCode::kInvalidInput:
    case ErrorCode::kParse:
      return PROCAM_EINVAL;
    case ErrorCode::kIo:
      return PROCAM_EIO;
    default:
      return PROCAM_EINTERNAL;
  }
}

std::string option(const procam_config* config, const char* key, const std::string& fallback) {
  for (size_t i = 0; config && i < config->n_options; ++i) {
    if (config->options[i].key && std::strcmp(config->options[i].key, key) == 0 &&
        config->options[i].value) {
      return config->options[i].value;
    }
  }
  return fallback;
}

int getMode(void* self, uint32_t* w, uint32_t* h, double* hz) {
  auto* d = static_cast<Device*>(self);
  const cv::Size s = d->out->size();
  if (w) *w = static_cast<uint32_t>(s.width);
  if (h) *h = static_cast<uint32_t>(s.height);
  if (hz) *hz = d->refresh_hz;
  return PROCAM_OK;
}

int show(void* self, const procam_image* frame, char* err, size_t err_len) {
  try {
    auto* d = static_cast<Device*>(self);
    const cv::Size s = d->out->size();
    if (!frame || !frame->data || int(frame->width) != s.width || int(frame->height) != s.height) {
      writeError(err, err_len, "frame must match the output mode");
      return PROCAM_EINVAL;
    }
    const int type = frame->format == PROCAM_PIXEL_RGB8    ? CV_8UC3
                     : frame->format == PROCAM_PIXEL_GRAY8 ? CV_8UC1
                                                           : -1;
    if (type < 0) {
      writeError(err, err_len, "outputs take RGB8 or GRAY8 frames");
      return PROCAM_EINVAL;
    }
    const cv::Mat in(s, type, frame->data, frame->stride);
    cv::cvtColor(in, d->rgba, type == CV_8UC3 ? cv::COLOR_RGB2RGBA : cv::COLOR_GRAY2RGBA);
    auto shown = d->out->show({&d->rgba, nullptr, ++d->version});
    if (!shown) {
      writeError(err, err_len, shown.error().message);
      return statusOf(shown.error().code);
    }
    return PROCAM_OK;
  } catch (const std::exception& e) {
    writeError(err, err_len, e.what());
    return PROCAM_EINTERNAL;
  }
}

int noPollFd(void*) {
  return -1;
}
void destroy(void* self) {
  delete static_cast<Device*>(self);
}

const procam_output_ops kOps = {&getMode, &show};

int finish(std::unique_ptr<Device> d, procam_device* out, char* err, size_t err_len) {
  render::RenderSetup setup;
  setup.output_size = setup.content_size = d->out->size();
  if (auto ok = d->out->configure(setup); !ok) {
    writeError(err, err_len, ok.error().message);
    return statusOf(ok.error().code);
  }
  out->family = PROCAM_FAMILY_OUTPUT;
  out->self = d.release();
  out->poll_fd = &noPollFd;
  out->destroy = &destroy;
  out->ops.output = &kOps;
  return PROCAM_OK;
}

int probeHeadless(const procam_device_desc* desc) {
  return desc && desc->family == PROCAM_FAMILY_OUTPUT && desc->subsystem &&
                 std::strcmp(desc->subsystem, "headless") == 0
             ? 50
             : 0;
}

int createHeadless(const procam_device_desc*, const procam_config* config, procam_device* out,
                   char* err, size_t err_len) {
  try {
    const int w = std::stoi(option(config, "width", "1920"));
    const int h = std::stoi(option(config, "height", "1080"));
    auto o = HeadlessOutput::create({w, h});
    if (!o) {
      writeError(err, err_len, o.error().message);
      return statusOf(o.error().code);
    }
    auto d = std::make_unique<Device>();
    d->out = std::move(*o);
    d->refresh_hz = std::stod(option(config, "refresh_hz", "60"));
    return finish(std::move(d), out, err, err_len);
  } catch (const std::exception& e) {
    writeError(err, err_len, std::string("headless output: bad option: ") + e.what());
    return PROCAM_EINVAL;
  }
}

#if PROCAM_OUTPUT_PLUGIN_KMS
int probeKms(const procam_device_desc* desc) {
  return desc && desc->family == PROCAM_FAMILY_OUTPUT && desc->subsystem &&
                 std::strcmp(desc->subsystem, "drm") == 0
             ? 50
             : 0;
}

int createKms(const procam_device_desc* desc, const procam_config* config, procam_device* out,
              char* err, size_t err_len) {
  try {
    kms::KmsConfig c;
    c.device = desc && desc->devnode ? desc->devnode : "";
    c.request.connector = option(config, "connector", "");
    c.request.mode = option(config, "mode", "preferred");
    auto o = kms::KmsOutput::create(c);
    if (!o) {
      writeError(err, err_len, o.error().message);
      return statusOf(o.error().code);
    }
    auto d = std::make_unique<Device>();
    d->out = std::move(*o);
    return finish(std::move(d), out, err, err_len);
  } catch (const std::exception& e) {
    writeError(err, err_len, std::string("kms output: ") + e.what());
    return PROCAM_EINTERNAL;
  }
}
#endif

const procam_driver_factory kFactories[] = {
    {PROCAM_FAMILY_OUTPUT, "headless", "EGL surfaceless output, frames kept in memory",
     &probeHeadless, &createHeadless},
#if PROCAM_OUTPUT_PLUGIN_KMS
    {PROCAM_FAMILY_OUTPUT, "kms", "DRM/KMS scan-out with GBM and EGL", &probeKms, &createKms},
#endif
};

const procam_plugin_table kTable = {PROCAM_PLUGIN_ABI_VERSION, "output", "0.1",
                                    sizeof(kFactories) / sizeof(kFactories[0]), kFactories};

}  // namespace
}  // namespace procam::output

extern "C" const procam_plugin_table* procam_output_plugin_entry(void) {
  return &procam::output::kTable;
}
