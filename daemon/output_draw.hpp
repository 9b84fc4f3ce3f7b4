#pragma once
// Drawing the outputs. Each output renders its own frame from a render setup and content
// (procam_plugin.h, output operations version 2; 3 to stop midway): the setup is handed over only
// when the geometry changed, the content with a version that changes only when the content does. An
// output whose driver lacks those operations gets its frame from a CPU reference renderer kept for
// it (its warp map built once per setup) through `show`. The daemon plans on the loop
// (daemon_keystone.cpp) and draws on its compute worker.
#include <atomic>
#include <chrono>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "driver.hpp"
#include "render/cpu_renderer.hpp"
#include "render/frame_stats.hpp"
#include "render/render_setup.hpp"

namespace procam::daemon {

struct OutputDraw {
  std::string name;
  std::shared_ptr<plugins::Device> device;  // kept alive while the draw runs
  std::shared_ptr<const render::RenderSetup> setup;
  bool configure = false;                // hand the setup over first (the geometry changed)
  std::shared_ptr<const cv::Mat> image;  // RGBA content (image paths)
  std::shared_ptr<const render::ColoredMesh> mesh;  // planar 3D path
  uint64_t version = 0;                             // of the content
  bool want_stats = false;
  std::string source;                             // FrameStats::source of this frame
  std::string path;                               // render::toString of setup->path
  std::optional<Mat34> viewer;                    // world -> content pixels, if any
  std::optional<Mat3> homography;                 // content -> framebuffer (homography path)
  int tile = -1;                                  // of a display across outputs
  std::shared_ptr<render::CpuRenderer> fallback;  // set: the output does not render itself
  // Set by the loop when a newer request made this frame obsolete: the draw stops before
  // the output or, where the driver can (output operations version 3), midway.
  std::shared_ptr<const std::atomic<bool>> stop;
  // Set when the homography is a tilt solution not shown before: its reading's arrival,
  // from which the draw measures when the frame is shown (keystone_latency.hpp).
  std::optional<std::chrono::steady_clock::time_point> reading_arrival;
  // For an output that presents when asked (output operations version 4): the earliest
  // time the frame goes on screen (CLOCK_MONOTONIC ns; 0: when drawn). Asked every
  // frame, so that no earlier request lingers.
  uint64_t present_at_ns = 0;
};

struct OutputDrawn {
  std::string name;
  std::string source;
  std::string path;
  std::optional<Mat34> viewer;
  std::optional<Mat3> homography;
  int tile = -1;
  bool ok = false;
  bool drawn = false;            // a new frame is shown
  bool configured = false;       // the setup was handed over and taken
  bool stopped = false;          // stopped by `stop`: nothing shown, the frame before stays
  bool configure_asked = false;  // the job was to hand the setup over
  int rc = 0;                    // the driver's status when !ok (PROCAM_ENODEV: gone)
  std::string error;
  std::optional<render::FrameStats> stats;
  std::optional<double> latency_s;  // reading_arrival to shown, when a new frame was shown
  // A new frame: when it went on screen (CLOCK_MONOTONIC ns): as the output says for one
  // that presents when asked (at a vblank when vblank_period_ns > 0), else when its
  // render returned.
  std::optional<uint64_t> shown_ns;
  uint64_t ready_ns = 0;  // its drawing ended (CLOCK_MONOTONIC)
  uint64_t vblank_period_ns = 0;
  // What the output shows when ok: the job's setup and content (the drift check draws it
  // again to know what a camera should see).
  std::shared_ptr<const render::RenderSetup> setup;
  std::shared_ptr<const cv::Mat> image;
};

// Runs on a worker; never throws.
OutputDrawn drawOutput(const OutputDraw& job);

// The output's mode (framebuffer size); nullopt when it does not answer or is below 2x2.
// `rc`: the driver's answer.
std::optional<cv::Size> outputMode(const procam_device& output, int* rc = nullptr);

}  // namespace procam::daemon
