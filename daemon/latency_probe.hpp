#pragma once
// The display-to-capture latency of an output seen by cameras (projector–camera
// synchronisation, [Raskar02] §4.1.1): on a worker, shows black and white in turn on
// the output, captures each camera across every switch and finds when the
// change appears (sl::findTransition); the median over the repeats gives the
// settle frames `calibrate` waits after showing a pattern.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calibration_job.hpp"
#include "config.hpp"
#include "structured_light/display_latency.hpp"
#include "tl/expected.hpp"

namespace procam::daemon {

// The latency request's arguments (PROTOCOL.md).
struct LatencyArgs {
  std::string output;                // empty: the first usable output
  std::vector<std::string> cameras;  // empty: every usable camera
  int repeats = 3;                   // black -> white -> black cycles per camera
  double timeout_s = 1.0;            // the longest latency looked for
  int margin_frames = 1;             // settle = ceil(latency * refresh) + margin
};

// `defaults` from [calibration] of procamd.toml; the message names the bad key.
tl::expected<LatencyArgs, std::string> parseLatencyArgs(const nlohmann::json& request,
                                                        const CalibrationConfig& defaults);

struct LatencyPlan {
  CalibrationDevice output;
  uint32_t width = 0, height = 0;  // the output's mode
  double refresh_hz = 60;
  std::vector<CalibrationDevice> cameras;
  int repeats = 3;
  double timeout_s = 1.0;
  int margin_frames = 1;
};

struct CameraLatency {
  std::string camera;
  std::vector<double> latencies;  // s, one per switch (two per repeat)
  sl::LatencyStats stats;
  int settle_frames = 0;
  double contrast = 0;  // |white - black| of the frame mean, camera DN
  // Median time between the frames it captured: the resolution of the latency; and the
  // longest, which bounds one switch's error on a camera that drops frames.
  double frame_period_s = 0;
  double frame_period_max_s = 0;
};

struct LatencyResult {
  std::vector<CameraLatency> cameras;
  double latency_s = 0;   // the largest camera median
  int settle_frames = 0;  // what it implies at the output's refresh rate
};

// Runs on a worker: blocks on the devices; never touches daemon state. Leaves
// the output black (the daemon shows its frame again afterwards).
tl::expected<LatencyResult, CalibrationFailure> runLatencyProbe(const LatencyPlan& plan,
                                                                const CalibrationHooks& hooks);

// {latency_s, settle_frames, refresh_hz, margin_frames, cameras: [{name,
// latency_s: {median, spread, min, max}, samples, settle_frames, contrast,
// frame_period_s, frame_period_max_s}]}.
nlohmann::json latencyJson(const LatencyResult& result, const LatencyPlan& plan);

}  // namespace procam::daemon
