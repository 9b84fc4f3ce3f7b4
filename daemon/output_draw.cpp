#include "output_draw.hpp"

#include <array>
#include <exception>
#include <opencv2/imgproc.hpp>

#include "core/monotonic_clock.hpp"
#include "support/render_abi.hpp"

namespace procam::daemon {
namespace {

std::string reason(const std::array<char, 512>& err, int rc) {
  return err[0] ? std::string(err.data()) : "driver status " + std::to_string(rc);
}

// The plugin's stop callback: the job's flag, set by the loop.
int stopRequested(void* flag) {
  return static_cast<const std::atomic<bool>*>(flag)->load(std::memory_order_relaxed) ? 1 : 0;
}

// A new frame on the output: when it was drawn and shown (as the output says, for one
// that presents when asked) and, drawn from a tilt solution not shown before, how long
// after its reading arrived.
void stampShown(const OutputDraw& j, OutputDrawn& r,
                const std::optional<plugins::PresentTiming>& timing = std::nullopt) {
  if (!r.ok || !r.drawn) return;
  const auto now = std::chrono::steady_clock::now();
  r.ready_ns = timing ? timing->ready_ns : monotonicNs(now);
  r.shown_ns = timing ? timing->shown_ns : monotonicNs(now);
  if (timing) r.vblank_period_ns = timing->period_ns;
  if (j.reading_arrival) {
    // To when it goes on the wall, which an output that queues frames says.
    const int64_t since =
        static_cast<int64_t>(*r.shown_ns) - static_cast<int64_t>(monotonicNs(*j.reading_arrival));
    r.latency_s = static_cast<double>(since) * 1e-9;
  }
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
  render::Content content{j.image.get(), j.mesh.get(), j.version, {}};
  if (j.stop) content.stop = [stop = j.stop] { return stop->load(std::memory_order_relaxed); };
  auto drawn = cpu.render(content);
  if (!drawn) {
    r.stopped = drawn.error().code == ErrorCode::kCancelled;
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
  stampShown(j, r);  // shown: the statistics below are not the wall's wait
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
  r.configure_asked = j.configure;
  r.setup = j.setup;
  r.image = j.image;
  try {
    if (!j.device || !j.device->valid() || !j.setup) {
      r.error = "no device or setup";
      return r;
    }
    if (j.stop && j.stop->load()) {
      r.stopped = true;
      r.error = "stopped before drawing";
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
    const bool presents_at = plugins::outputPresentsAt(raw);
    if (presents_at) (void)raw.ops.output->present_at(raw.self, j.present_at_ns);
    int drawn = 0;
    procam_frame_stats stats{};
    procam_frame_stats* want = j.want_stats ? &stats : nullptr;
    if (j.stop && plugins::outputStops(raw)) {
      // The flag outlives the call: the job holds it.
      auto* flag = const_cast<std::atomic<bool>*>(j.stop.get());
      r.rc = raw.ops.output->render_stoppable(raw.self, &content.get(), &stopRequested, flag,
                                              &drawn, want, err.data(), err.size() - 1);
    } else {
      r.rc = raw.ops.output->render(raw.self, &content.get(), &drawn, want, err.data(),
                                    err.size() - 1);
    }
    // Only a stop the daemon asked for: a driver answering PROCAM_ECANCELED by itself
    // is an error like any other (its frame is not drawn again at once).
    r.stopped = r.rc == PROCAM_ECANCELED && j.stop && j.stop->load();
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
    stampShown(j, r, presents_at ? plugins::outputTiming(raw) : std::nullopt);
  } catch (const std::exception& e) {
    r.ok = false;
    r.error = e.what();
  }
  return r;
}

std::optional<cv::Size> outputMode(const procam_device& raw, int* rc) {
  uint32_t w = 0, h = 0;
  double hz = 0;
  const int got = raw.ops.output->get_mode(raw.self, &w, &h, &hz);
  if (rc) *rc = got;
  if (got != PROCAM_OK || w < 2 || h < 2) {
    return std::nullopt;
  }
  return cv::Size(static_cast<int>(w), static_cast<int>(h));
}

}  // namespace procam::daemon
