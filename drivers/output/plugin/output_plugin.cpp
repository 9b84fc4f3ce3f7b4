// The projector outputs behind the driver plugin ABI (plugins/include/procamd/
// procam_plugin.h): "headless" (EGL surfaceless, frames kept on the GPU) and, when built,
// "kms" (DRM/KMS scan-out). Both render by themselves (output operations version 4): the
// daemon's render setup is drawn by the GLES renderer, content is uploaded only when its
// version changes; "kms" presents at vblank and says when. A frame handed over with
// `show` is shown 1:1 (identity homography).
#include <procamd/procam_plugin.h>

#include <chrono>
#include <climits>
#include <cstring>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "core/monotonic_clock.hpp"
#include "headless/headless_output.hpp"
#include "support/driver_support.hpp"
#include "support/render_abi.hpp"
#if PROCAM_OUTPUT_PLUGIN_KMS
#include "kms/kms_output.hpp"
#endif

namespace procam::output {
namespace {

// Versions of frames shown 1:1 have the top bit set, so that they never equal the
// daemon's content versions in the renderer's upload check.
constexpr uint64_t kShowVersion = 1ull << 63;

struct Device {
  std::unique_ptr<ProjectorOutput> out;
  double refresh_hz = 0;
  cv::Mat rgba;                              // a frame shown 1:1, converted
  uint64_t shown = 0;                        // frames shown 1:1
  bool showing = true;                       // configured for 1:1 frames
  std::optional<render::RenderSetup> setup;  // the daemon's, once configured
  plugins::MeshCache mesh;
  // The next rendered frame goes on screen no earlier than this (CLOCK_MONOTONIC ns, 0:
  // at once); when the last one was ready and shown. An output that presents at vblank
  // times its own frames (ProjectorOutput::vblankTiming); the others are held here.
  uint64_t not_before_ns = 0;
  uint64_t ready_ns = 0, shown_ns = 0;
};

// A rendered frame, drawn: an output that shows it when its drawing ends is held until
// the time asked for. Returns once the frame is on screen.
Result<bool> showAt(Device& d, const render::Content& content) {
  const uint64_t not_before = std::exchange(d.not_before_ns, 0);
  d.out->presentAt(not_before);
  auto drawn = d.out->show(content);
  if (!drawn || !*drawn) return drawn;
  if (auto t = d.out->vblankTiming()) {
    d.ready_ns = t->ready_ns;
    d.shown_ns = t->shown_ns;
    return drawn;
  }
  d.ready_ns = monotonicNowNs();
  if (not_before > d.ready_ns) {
    std::this_thread::sleep_for(std::chrono::nanoseconds(not_before - d.ready_ns));
  }
  d.shown_ns = std::max(d.ready_ns, not_before);
  return drawn;
}

int getMode(void* self, uint32_t* w, uint32_t* h, double* hz) {
  auto* d = static_cast<Device*>(self);
  const cv::Size s = d->out->size();
  if (w) *w = static_cast<uint32_t>(s.width);
  if (h) *h = static_cast<uint32_t>(s.height);
  if (hz) *hz = d->refresh_hz;
  return PROCAM_OK;
}

Result<void> configureOneToOne(Device& d) {
  render::RenderSetup setup;
  setup.output_size = setup.content_size = d.out->size();
  if (auto ok = d.out->configure(setup); !ok) return ok;
  d.showing = true;
  return {};
}

int show(void* self, const procam_image* frame, char* err, size_t err_len) {
  try {
    auto* d = static_cast<Device*>(self);
    const cv::Size s = d->out->size();
    if (!frame || !frame->data || int(frame->width) != s.width || int(frame->height) != s.height) {
      return plugins::report(err, err_len, "frame must match the output mode", PROCAM_EINVAL);
    }
    const int type = frame->format == PROCAM_PIXEL_RGBA8   ? CV_8UC4
                     : frame->format == PROCAM_PIXEL_RGB8  ? CV_8UC3
                     : frame->format == PROCAM_PIXEL_GRAY8 ? CV_8UC1
                                                           : -1;
    if (type < 0) {
      return plugins::report(err, err_len, "outputs take RGBA8, RGB8 or GRAY8 frames",
                             PROCAM_EINVAL);
    }
    if (!d->showing) {
      if (auto ok = configureOneToOne(*d); !ok) return plugins::report(err, err_len, ok.error());
    }
    const cv::Mat in(s, type, frame->data, frame->stride);
    if (type == CV_8UC4) {
      d->rgba = in;  // no copy: the renderer uploads it during show
    } else {
      cv::cvtColor(in, d->rgba, type == CV_8UC3 ? cv::COLOR_RGB2RGBA : cv::COLOR_GRAY2RGBA);
    }
    auto shown = d->out->show({&d->rgba, nullptr, kShowVersion | ++d->shown});
    d->rgba.release();
    if (!shown) return plugins::report(err, err_len, shown.error());
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return plugins::report(err, err_len, e.what(), PROCAM_EINTERNAL);
  }
}

int configure(void* self, const procam_render_setup* setup, char* err, size_t err_len) {
  try {
    auto* d = static_cast<Device*>(self);
    if (!setup) return plugins::report(err, err_len, "no render setup", PROCAM_EINVAL);
    auto s = plugins::setupFromAbi(*setup);
    if (!s) return plugins::report(err, err_len, s.error());
    if (s->output_size != d->out->size()) {
      return plugins::report(err, err_len, "render setup size differs from the output mode",
                             PROCAM_EINVAL);
    }
    d->showing = false;  // whatever the outcome, the 1:1 setup is gone
    d->setup.reset();
    if (auto ok = d->out->configure(*s); !ok) return plugins::report(err, err_len, ok.error());
    d->setup = std::move(*s);
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return plugins::report(err, err_len, e.what(), PROCAM_EINTERNAL);
  }
}

int renderStoppable(void* self, const procam_content* content, int (*stop)(void*), void* stop_ctx,
                    int* out_drawn, procam_frame_stats* stats, char* err, size_t err_len) {
  try {
    auto* d = static_cast<Device*>(self);
    if (out_drawn) *out_drawn = 0;
    if (!d->setup) return plugins::report(err, err_len, "render before configure", PROCAM_EINVAL);
    if (!content) return plugins::report(err, err_len, "no content", PROCAM_EINVAL);
    if (d->showing) {
      // A 1:1 frame was shown meanwhile: back to the daemon's setup, drawn again.
      d->showing = false;
      if (auto ok = d->out->configure(*d->setup); !ok) {
        d->setup.reset();
        return plugins::report(err, err_len, ok.error());
      }
    }
    cv::Mat header;
    auto c = plugins::contentFromAbi(*content, *d->setup, header, d->mesh);
    if (!c) return plugins::report(err, err_len, c.error());
    if (stop) c->stop = [stop, stop_ctx] { return stop(stop_ctx) != 0; };
    auto drawn = showAt(*d, *c);
    if (!drawn) return plugins::report(err, err_len, drawn.error());
    if (out_drawn) *out_drawn = *drawn ? 1 : 0;
    if (stats) {
      cv::Mat frame;
      if (auto ok = d->out->readFrame(frame); !ok) return plugins::report(err, err_len, ok.error());
      auto st = plugins::abiFrameStats(frame);
      if (!st) return plugins::report(err, err_len, st.error());
      *stats = *st;
    }
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return plugins::report(err, err_len, e.what(), PROCAM_EINTERNAL);
  }
}

int noPollFd(void*) {
  return -1;
}
void destroy(void* self) {
  delete static_cast<Device*>(self);
}

int render(void* self, const procam_content* content, int* out_drawn, procam_frame_stats* stats,
           char* err, size_t err_len) {
  return renderStoppable(self, content, nullptr, nullptr, out_drawn, stats, err, err_len);
}

int presentAt(void* self, uint64_t not_before_ns) {
  static_cast<Device*>(self)->not_before_ns = not_before_ns;
  return PROCAM_OK;
}

int getTiming(void* self, uint64_t* ready_ns, uint64_t* shown_ns, uint64_t* period_ns) {
  auto* d = static_cast<Device*>(self);
  const auto t = d->out->vblankTiming();
  if (ready_ns) *ready_ns = d->ready_ns;
  if (shown_ns) *shown_ns = d->shown_ns;
  if (period_ns) *period_ns = t ? t->period_ns : 0;
  return PROCAM_OK;
}

const procam_output_ops kOps = {
    PROCAM_OUTPUT_OPS_VERSION, &getMode,   &show,     &configure, &render,
    &renderStoppable,          &presentAt, &getTiming};

int finish(std::unique_ptr<Device> d, procam_device* out, char* err, size_t err_len) {
  if (auto ok = configureOneToOne(*d); !ok) return plugins::report(err, err_len, ok.error());
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
    const plugins::DriverOptions o("headless output", config);
    auto w = o.integer("width");
    auto h = o.integer("height");
    auto hz = o.number("refresh_hz");
    for (const auto* v : {&w, &h})
      if (!*v) return plugins::report(err, err_len, v->error());
    if (!hz) return plugins::report(err, err_len, hz.error());
    const long width = w->value_or(1920), height = h->value_or(1080);
    if (width < 1 || height < 1 || width > INT_MAX || height > INT_MAX)
      return plugins::report(err, err_len, "headless output: width and height must be >= 1",
                             PROCAM_EINVAL);
    auto made = HeadlessOutput::create({int(width), int(height)});
    if (!made) return plugins::report(err, err_len, made.error());
    auto d = std::make_unique<Device>();
    d->out = std::move(*made);
    d->refresh_hz = hz->value_or(60);
    return finish(std::move(d), out, err, err_len);
  } catch (const std::exception& e) {
    return plugins::report(err, err_len, std::string("headless output: ") + e.what(),
                           PROCAM_EINTERNAL);
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
    const plugins::DriverOptions o("kms output", config);
    c.request.connector = o.text("connector").value_or("");
    c.request.mode = o.text("mode").value_or("preferred");
    auto made = kms::KmsOutput::create(c);
    if (!made) return plugins::report(err, err_len, made.error());
    auto d = std::make_unique<Device>();
    d->out = std::move(*made);
    return finish(std::move(d), out, err, err_len);
  } catch (const std::exception& e) {
    return plugins::report(err, err_len, std::string("kms output: ") + e.what(), PROCAM_EINTERNAL);
  }
}
#endif

const procam_driver_factory kFactories[] = {
    {PROCAM_FAMILY_OUTPUT, "headless", "EGL surfaceless output, frames kept in memory",
     &probeHeadless, &createHeadless, nullptr},
#if PROCAM_OUTPUT_PLUGIN_KMS
    {PROCAM_FAMILY_OUTPUT, "kms", "DRM/KMS scan-out with GBM and EGL", &probeKms, &createKms,
     nullptr},
#endif
};

const procam_plugin_table kTable = {PROCAM_PLUGIN_ABI_VERSION, "output", "0.1",
                                    sizeof(kFactories) / sizeof(kFactories[0]), kFactories};

}  // namespace
}  // namespace procam::output

extern "C" const procam_plugin_table* procam_output_plugin_entry(void) {
  return &procam::output::kTable;
}
