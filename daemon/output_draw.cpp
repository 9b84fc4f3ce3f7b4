#include "output_draw.hpp"

#include <array>
#include <exception>
#include <opencv2/imgproc.hpp>

#include "support/render_abi.hpp"

namespace procam::daemon {
namespace {

std::string reason(const std::array<char, 512>& err, int rc) {
  return err[0] ? std::string(err.data()) : "driver status " + std::to_string(rc);
}

// Outputs with operations version 1 show RGB8 frames drawn here.
void drawFallback(const OutputDraw& j, OutputDrawn& r) {
  render::CpuRenderer& cpu = *j.fallback;
  if (j.configure) {
    if (auto ok = cpu.configure(*j.setup); !ok) {
      r.error = ok.error().message;
      return;
    }
    r.configured = true;
  }
  auto drawn = cpu.render({j.image.get(), j.mesh.get(), j.version});
  if (!drawn) {
    r.error = drawn.error().message;
    return;
  }
  // Shown every time: a 1:1 frame (calibration, latency probe) may have replaced it.
  cv::Mat rgb;
  cv::cvtColor(cpu.frame(), rgb, cv::COLOR_RGBA2RGB);
  const procam_image image{static_cast<uint32_t>(rgb.cols),
                           static_cast<uint32_t>(rgb.rows),
                           static_cast<uint32_t>(rgb.step[0]),
                           PROCAM_PIXEL_RGB8,
                           rgb.data,
                           0};
  const procam_device& raw = j.device->raw();
  std::array<char, 512> err{};
  r.rc = raw.ops.output->show(raw.self, &image, err.data(), err.size() - 1);
  if (r.rc != PROCAM_OK) {
    r.error = reason(err, r.rc);
    return;
  }
  r.ok = true;
  r.drawn = *drawn;
  if (j.want_stats) {
    if (auto st = render::frameStats(cpu.frame())) r.stats = *st;
  }
}

}  // namespace

OutputDrawn drawOutput(const OutputDraw& j) {
  OutputDrawn r;
  r.name = j.name;
  r.source = j.source;
  r.path = j.path;
  r.viewer = j.viewer;
  r.homography = j.homography;
  r.tile = j.tile;
  try {
    if (!j.device || !j.device->valid() || !j.setup) {
      r.error = "no device or setup";
      return r;
    }
    if (j.fallback) {
      drawFallback(j, r);
      return r;
    }
    const procam_device& raw = j.device->raw();
    std::array<char, 512> err{};
    if (j.configure) {
      const plugins::RenderSetupView setup(*j.setup);
      r.rc = raw.ops.output->configure(raw.self, &setup.get(), err.data(), err.size() - 1);
      if (r.rc != PROCAM_OK) {
        r.error = "render setup refused: " + reason(err, r.rc);
        return r;
      }
      r.configured = true;
    }
    const plugins::ContentView content(j.image.get(), j.mesh.get(), j.version);
    int drawn = 0;
    procam_frame_stats stats{};
    r.rc = raw.ops.output->render(raw.self, &content.get(), &drawn, j.want_stats ? &stats : nullptr,
                                  err.data(), err.size() - 1);
    if (r.rc != PROCAM_OK) {
      r.error = reason(err, r.rc);
      return r;
    }
    r.ok = true;
    r.drawn = drawn != 0;
    if (j.want_stats) {
      r.stats = render::FrameStats{stats.lit_fraction,
                                   {stats.mean_rgb[0], stats.mean_rgb[1], stats.mean_rgb[2]}};
    }
  } catch (const std::exception& e) {
    r.ok = false;
    r.error = e.what();
  }
  return r;
}

std::optional<cv::Size> outputMode(const procam_device& raw) {
  uint32_t w = 0, h = 0;
  double hz = 0;
  if (raw.ops.output->get_mode(raw.self, &w, &h, &hz) != PROCAM_OK || w < 2 || h < 2) {
    return std::nullopt;
  }
  return cv::Size(static_cast<int>(w), static_cast<int>(h));
}

}  // namespace procam::daemon
