#include "camera_calibration_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>

#include "calibration/board_view_set.hpp"
#include "protocol.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

// Fewest views a solve takes: Zhang's method needs 3; one more leaves a check.
constexpr int kMinViews = 4;

bool numberArg(const json& request, const char* key, double lo, double hi, double& out,
               std::string& error) {
  auto it = request.find(key);
  if (it == request.end()) return true;
  if (!it->is_number() || !(it->get<double>() >= lo && it->get<double>() <= hi)) {
    error = std::string("\"") + key + "\" must be a number from " + json(lo).dump() + " to " +
            json(hi).dump();
    return false;
  }
  out = it->get<double>();
  return true;
}

}  // namespace

tl::expected<CameraCalibrationArgs, std::string> parseCameraCalibrationArgs(const json& request) {
  static const char* kKnown[] = {"cmd",       "id",         "action",   "camera",
                                 "board",     "views",      "coverage", "rms_px",
                                 "timeout_s", "interval_s", "min_shift"};
  for (const auto& item : request.items()) {
    // Not a structured binding: clang before 16 cannot capture one in the lambda.
    const std::string& key = item.key();
    if (std::none_of(std::begin(kKnown), std::end(kKnown), [&](const char* k) { return key == k; }))
      return tl::unexpected("unknown argument \"" + key + "\" for calibrate-camera");
  }
  CameraCalibrationArgs a;
  if (auto it = request.find("camera"); it != request.end()) {
    if (!it->is_string() || it->get<std::string>().empty())
      return tl::unexpected(std::string("\"camera\" must be a camera's name"));
    a.camera = it->get<std::string>();
  }
  auto board = request.find("board");
  if (board == request.end()) {
    return tl::unexpected(std::string(
        "\"board\" is needed: the board the installer holds, e.g. \"checker:9x6:0.08\""));
  }
  auto spec = boardArg(*board);
  if (!spec) return tl::unexpected(spec.error());
  a.board = *spec;
  a.board_text = board->get<std::string>();
  std::string error;
  double views = a.views;
  if (!numberArg(request, "views", kMinViews, 100, views, error) ||
      !numberArg(request, "coverage", 0, 1, a.coverage, error) ||
      !numberArg(request, "rms_px", 0.01, 100, a.rms_px, error) ||
      !numberArg(request, "timeout_s", 1, 3600, a.timeout_s, error) ||
      !numberArg(request, "interval_s", 0, 10, a.interval_s, error) ||
      !numberArg(request, "min_shift", 0.005, 0.5, a.min_shift, error)) {
    return tl::unexpected(error);
  }
  if (views != std::floor(views)) return tl::unexpected(std::string("\"views\" must be whole"));
  a.views = int(views);
  return a;
}

json cameraCalibrationJson(const CameraCalibrationStatus& s) {
  json rejected = json::object();
  int total = 0;
  for (const auto& [why, n] : s.rejected) {
    rejected[why] = n;
    total += n;
  }
  return {{"frames", s.frames},     {"views", s.kept},
          {"rejected", total},      {"rejections", rejected},
          {"coverage", s.coverage}, {"rms_px", s.rms_px >= 0 ? json(s.rms_px) : json(nullptr)},
          {"last", s.last}};
}

tl::expected<CameraCalibrationResult, CalibrationFailure> runCameraCalibration(
    const CameraCalibrationPlan& plan, const CalibrationHooks& hooks,
    const std::function<void(const CameraCalibrationStatus&)>& on_frame) {
  const CameraCalibrationArgs& args = plan.args;
  const double diagonal = std::hypot(plan.width, plan.height);
  calib::BoardViewSet set(plan.width, plan.height, args.min_shift * diagonal);
  CameraCalibrationResult result;
  CameraCalibrationStatus& status = result.status;
  std::optional<calib::CameraCalibration> solved;
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    if (hooks.cancelled()) {
      return tl::unexpected(CalibrationFailure{code::kCancelled, "camera calibration cancelled"});
    }
    if (plan.finish && plan.finish->load()) {
      result.stopped = "finish";
      break;
    }
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
        args.timeout_s) {
      result.stopped = "timeout";
      break;
    }
    auto frame = captureGray(plan.camera);
    if (!frame) return tl::unexpected(frame.error());
    ++status.frames;
    if (frame->cols != plan.width || frame->rows != plan.height) {
      return tl::unexpected(CalibrationFailure{
          code::kFailed, "camera '" + plan.camera.name + "' changed its frame size to " +
                             std::to_string(frame->cols) + "x" + std::to_string(frame->rows) +
                             " during the calibration"});
    }
    cv::Mat gray8 = *frame;
    if (gray8.depth() == CV_16U) gray8.convertTo(gray8, CV_8U, 1.0 / 257.0);
    auto view = calib::detectBoard(args.board, gray8);
    if (!view) {
      status.last = "board not found";
      ++status.rejected[status.last];
    } else {
      const calib::ViewVerdict verdict = set.offer(*view);
      status.last = calib::toString(verdict);
      if (verdict != calib::ViewVerdict::kAccepted) {
        ++status.rejected[status.last];
      } else {
        status.kept = int(set.views().size());
        status.coverage = set.coverage();
        if (status.kept >= kMinViews) {
          // The running solve: what the installer watches fall as views come in.
          if (auto c = calib::calibrateCamera(set.views(), plan.width, plan.height)) {
            solved = std::move(*c);
            status.rms_px = solved->rms_px;
          }
        }
      }
    }
    on_frame(status);
    if (hooks.progress) {
      const double f = std::min(double(status.kept) / args.views,
                                args.coverage > 0 ? status.coverage / args.coverage : 1.0);
      hooks.progress({std::clamp(f, 0.0, 1.0), "views", status.frames});
    }
    if (status.kept >= args.views && status.coverage >= args.coverage && solved &&
        status.rms_px <= args.rms_px) {
      result.stopped = "targets";
      break;
    }
    // Bounded work and memory: twice the views asked for is enough to judge by.
    if (status.kept >= 2 * args.views) {
      result.stopped = "views";
      break;
    }
    if (!waitCancellable(args.interval_s, hooks)) continue;  // the loop's check answers
  }
  if (status.kept < kMinViews || !solved) {
    std::string why;
    for (const auto& [reason, n] : status.rejected) {
      why += (why.empty() ? "" : ", ") + std::to_string(n) + " " + reason;
    }
    return tl::unexpected(CalibrationFailure{
        code::kFailed, "camera '" + plan.camera.name + "': " + std::to_string(status.kept) +
                           " board view(s) kept of " + std::to_string(status.frames) + " frames (" +
                           (why.empty() ? "none rejected" : why) + "); at least " +
                           std::to_string(kMinViews) + " are needed: show the board " +
                           args.board_text + " to the camera at several angles"});
  }
  result.calibration = std::move(*solved);
  return result;
}

}  // namespace procam::daemon
