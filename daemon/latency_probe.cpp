#include "latency_probe.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>
#include <optional>

#include "output_frames.hpp"
#include "protocol.hpp"

namespace procam::daemon {

namespace code = proto::code;
using nlohmann::json;

namespace {

// CLOCK_MONOTONIC (steady_clock), the clock of the plugin ABI's frame timestamps.
double monotonicNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

class Probe {
 public:
  Probe(const LatencyPlan& plan, const CalibrationHooks& hooks) : plan_(plan), hooks_(hooks) {
    const int w = static_cast<int>(plan.width), h = static_cast<int>(plan.height);
    black_ = cv::Mat(h, w, CV_8UC3, cv::Scalar::all(0));
    white_ = cv::Mat(h, w, CV_8UC3, cv::Scalar::all(255));
  }

  std::optional<CalibrationFailure> show(bool white, double& at) {
    procam_image frame = rgbImage(white ? white_ : black_);
    const auto& raw = plan_.output.device->raw();
    char err[256] = {};
    at = monotonicNow();  // when the switch is handed to the output
    if (int rc = raw.ops.output->show(raw.self, &frame, err, sizeof err - 1); rc != PROCAM_OK) {
      return deviceFailure("output", plan_.output.name, rc, "show a frame", err);
    }
    return std::nullopt;
  }

  // Adds one frame's mean level, unless the frame is not newer than the last one
  // (a driver handing out a buffered frame twice).
  std::optional<CalibrationFailure> capture(const CalibrationDevice& cam,
                                            std::vector<sl::BrightnessSample>& samples) {
    const auto& raw = cam.device->raw();
    procam_image img{};
    char err[256] = {};
    if (int rc = raw.ops.camera->capture(raw.self, 5000, &img, err, sizeof err - 1);
        rc != PROCAM_OK) {
      return deviceFailure("camera", cam.name, rc, "capture", err);
    }
    const double t =
        img.timestamp_ns ? static_cast<double>(img.timestamp_ns) * 1e-9 : monotonicNow();
    const cv::Mat gray = grayImage(img);
    if (gray.empty()) {
      return CalibrationFailure{code::kIo,
                                "camera '" + cam.name + "' returned an unknown pixel format"};
    }
    // 16-bit cameras write 10..16-bit codes: thresholds in 12-bit units.
    scale_ = gray.depth() == CV_16U ? 16.0 : 1.0;
    if (samples.empty() || t > samples.back().time) samples.push_back({t, cv::mean(gray)[0]});
    return std::nullopt;
  }

  // Captures the settled level, switches the output and captures until the
  // change has settled or the timeout has passed.
  // `s` holds the frames of the settled level already captured (the end of the
  // previous switch), if any; on return, the frames of this one.
  // `contrast`: the level difference of the camera's previous switch (0: none).
  tl::expected<sl::Transition, CalibrationFailure> transition(
      const CalibrationDevice& cam, bool to_white, double contrast,
      std::vector<sl::BrightnessSample>& s) {
    while (s.size() < 2) {
      if (auto f = capture(cam, s)) return tl::unexpected(*f);
    }
    double shown = 0;
    if (auto f = show(to_white, shown)) return tl::unexpected(*f);
    sl::TransitionOptions options;
    // The frame mean has little noise but drifts with the scene (a hand-held
    // projector): a new level is half the contrast of the camera's last switch
    // away, or 8 DN for its first.
    options.min_contrast = std::max(8.0 * scale_, 0.5 * contrast);
    const double deadline = shown + plan_.timeout_s;
    int past_deadline = 0;
    while (!sl::transitionSettled(s, shown, options) && past_deadline < options.settled_samples) {
      if (hooks_.cancelled()) return tl::unexpected(cancelled());
      if (auto f = capture(cam, s)) return tl::unexpected(*f);
      if (s.back().time > deadline) ++past_deadline;
    }
    auto t = sl::findTransition(s, shown, options);
    if (!t) {
      return tl::unexpected(CalibrationFailure{
          code::kFailed, "camera '" + cam.name + "' did not see output '" + plan_.output.name +
                             "' change from " + (to_white ? "black to white" : "white to black") +
                             " within " + std::to_string(plan_.timeout_s) +
                             " s (does it see the projection?): " + t.error().message + " (" +
                             std::to_string(s.size()) + " frames over " +
                             std::to_string(s.back().time - s.front().time) + " s)"});
    }
    return *t;
  }

  static CalibrationFailure cancelled() {
    return {code::kCancelled, "latency measurement cancelled"};
  }

 private:
  const LatencyPlan& plan_;
  const CalibrationHooks& hooks_;
  cv::Mat black_, white_;
  double scale_ = 1.0;
};

}  // namespace

tl::expected<LatencyArgs, std::string> parseLatencyArgs(const json& request,
                                                        const CalibrationConfig& defaults) {
  LatencyArgs a;
  a.repeats = defaults.latency_repeats;
  a.timeout_s = defaults.latency_timeout_s;
  a.margin_frames = defaults.margin_frames;
  static const char* const kKeys[] = {"output", "cameras", "repeats", "timeout_s", "margin_frames"};
  for (const auto& item : request.items()) {
    const std::string& key = item.key();
    if (key == "cmd" || key == "id") continue;
    if (std::none_of(std::begin(kKeys), std::end(kKeys), [&](const char* k) { return key == k; })) {
      return tl::unexpected("unknown argument \"" + key + "\" for latency");
    }
  }
  auto integer = [&](const char* key, int lo, int hi, int& out) {
    auto it = request.find(key);
    if (it == request.end()) return true;
    if (!it->is_number_integer() || it->get<int64_t>() < lo || it->get<int64_t>() > hi)
      return false;
    out = it->get<int>();
    return true;
  };
  if (!integer("repeats", 1, 20, a.repeats)) {
    return tl::unexpected(std::string("\"repeats\" must be an integer from 1 to 20"));
  }
  if (!integer("margin_frames", 0, 60, a.margin_frames)) {
    return tl::unexpected(std::string("\"margin_frames\" must be an integer from 0 to 60"));
  }
  if (auto it = request.find("timeout_s"); it != request.end()) {
    if (!it->is_number() || !(it->get<double>() >= 0.05 && it->get<double>() <= 10.0)) {
      return tl::unexpected(std::string("\"timeout_s\" must be a number from 0.05 to 10"));
    }
    a.timeout_s = it->get<double>();
  }
  if (auto it = request.find("output"); it != request.end()) {
    if (!it->is_string() || it->get<std::string>().empty()) {
      return tl::unexpected(std::string("\"output\" must be a device name"));
    }
    a.output = it->get<std::string>();
  }
  if (auto it = request.find("cameras"); it != request.end()) {
    bool ok = it->is_array() && !it->empty();
    for (const auto& c : ok ? *it : json::array()) {
      ok = ok && c.is_string() && !c.get<std::string>().empty() &&
           std::count(it->begin(), it->end(), c) == 1;
    }
    if (!ok) return tl::unexpected(std::string("\"cameras\" must name one or more cameras"));
    for (const auto& c : *it) a.cameras.push_back(c.get<std::string>());
  }
  return a;
}

tl::expected<LatencyResult, CalibrationFailure> runLatencyProbe(const LatencyPlan& plan,
                                                                const CalibrationHooks& hooks) {
  Probe probe(plan, hooks);
  // Black long enough for any latency looked for to have passed.
  double shown = 0;
  if (auto f = probe.show(false, shown)) return tl::unexpected(*f);
  if (!waitCancellable(plan.timeout_s, hooks)) return tl::unexpected(Probe::cancelled());
  LatencyResult result;
  const int total = static_cast<int>(plan.cameras.size()) * plan.repeats * 2;
  int done = 0;
  for (const auto& cam : plan.cameras) {
    CameraLatency c;
    c.camera = cam.name;
    double contrast = 0, last_contrast = 0;
    std::vector<double> periods;
    std::vector<sl::BrightnessSample> samples;
    for (int r = 0; r < plan.repeats; ++r) {
      for (bool to_white : {true, false}) {
        if (hooks.cancelled()) return tl::unexpected(Probe::cancelled());
        auto t = probe.transition(cam, to_white, last_contrast, samples);
        if (!t) return tl::unexpected(t.error());
        c.latencies.push_back(t->latency);
        last_contrast = std::abs(t->new_level - t->old_level);
        contrast += last_contrast;
        for (std::size_t i = 1; i < samples.size(); ++i) {
          periods.push_back(samples[i].time - samples[i - 1].time);
        }
        // The settled frames at the new level are the old level of the next switch.
        samples.erase(samples.begin(), samples.end() - 2);
        ++done;
        hooks.progress({static_cast<double>(done) / total, "latency", done});
      }
    }
    c.contrast = contrast / static_cast<double>(c.latencies.size());
    auto stats = sl::latencyStats(c.latencies);
    if (!stats) return tl::unexpected(CalibrationFailure{code::kFailed, stats.error().message});
    c.stats = *stats;
    c.settle_frames = sl::settleFrames(c.stats.median, plan.refresh_hz, plan.margin_frames);
    if (auto p = sl::latencyStats(periods)) {
      c.frame_period_s = p->median;
      c.frame_period_max_s = p->max;
    }
    result.latency_s = std::max(result.latency_s, c.stats.median);
    result.settle_frames = std::max(result.settle_frames, c.settle_frames);
    result.cameras.push_back(std::move(c));
  }
  return result;
}

json latencyJson(const LatencyResult& result, const LatencyPlan& plan) {
  json cameras = json::array();
  for (const auto& c : result.cameras) {
    cameras.push_back({{"name", c.camera},
                       {"latency_s",
                        {{"median", c.stats.median},
                         {"spread", c.stats.spread},
                         {"min", c.stats.min},
                         {"max", c.stats.max}}},
                       {"samples", c.latencies},
                       {"settle_frames", c.settle_frames},
                       {"contrast", c.contrast},
                       {"frame_period_s", c.frame_period_s},
                       {"frame_period_max_s", c.frame_period_max_s}});
  }
  return {{"output", plan.output.name},
          {"latency_s", result.latency_s},
          {"settle_frames", result.settle_frames},
          {"refresh_hz", plan.refresh_hz},
          {"margin_frames", plan.margin_frames},
          {"repeats", plan.repeats},
          {"cameras", cameras}};
}

}  // namespace procam::daemon
