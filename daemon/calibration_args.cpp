// The calibrate request's arguments (calibration_job.hpp, PROTOCOL.md).
#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "calibration_job.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

// An integer argument in [lo, hi]; false (with `error` set) when present and wrong.
bool integerArg(const json& request, const char* key, int lo, int hi, int& out,
                std::string& error) {
  auto it = request.find(key);
  if (it == request.end()) return true;
  if (!it->is_number_integer() || it->get<int64_t>() < lo || it->get<int64_t>() > hi) {
    error = std::string("\"") + key + "\" must be an integer from " + std::to_string(lo) + " to " +
            std::to_string(hi);
    return false;
  }
  out = it->get<int>();
  return true;
}

// A list of 1 to `most` different non-empty names of at most 256 characters.
std::optional<std::vector<std::string>> distinctNames(const json& list, std::size_t most) {
  if (!list.is_array() || list.empty() || list.size() > most) return std::nullopt;
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (const json& n : list) {
    if (!n.is_string() || n.get<std::string>().empty() || n.get<std::string>().size() > 256)
      return std::nullopt;
    out.push_back(n.get<std::string>());
    seen.insert(out.back());
  }
  if (seen.size() != out.size()) return std::nullopt;
  return out;
}

}  // namespace

tl::expected<calib::BoardSpec, std::string> boardArg(const json& value) {
  const std::string text = value.is_string() ? value.get<std::string>() : std::string();
  auto spec = !text.empty() && text.size() <= 64
                  ? calib::parseBoard(text)
                  : Result<calib::BoardSpec>(tl::unexpect, Error{ErrorCode::kParse, "not a board"});
  if (!spec) {
    return tl::unexpected(
        "\"board\" must be a board: aprilgrid:COLSxROWS:TAG_M[:GAP_M], "
        "checker:COLSxROWS:SQUARE_M or charuco:COLSxROWS:SQUARE_M:MARKER_M (metres): " +
        spec.error().message);
  }
  // Bounded: the detector's work and memory grow with the board's cells.
  if (spec->cols > 64 || spec->rows > 64 || !(spec->square_m >= 0.001 && spec->square_m <= 10) ||
      !(spec->gap_m >= 0 && spec->gap_m <= 10 * spec->square_m) ||
      (spec->kind == calib::BoardKind::kAprilGrid && spec->cols * spec->rows > 587)) {
    return tl::unexpected(
        std::string("\"board\" must have at most 64 x 64 cells of 1 mm to 10 m, a gap of at "
                    "most 10 cells and, for aprilgrid, at most 587 tags (tag36h11)"));
  }
  return *spec;
}

tl::expected<CalibrationArgs, std::string> parseCalibrationArgs(const json& request,
                                                                const CalibrationConfig& defaults) {
  CalibrationArgs a;
  a.settle_frames = defaults.settle_frames;
  a.auto_settle = defaults.auto_settle;
  static const char* const kKeys[] = {"mode",          "step",       "phase_steps", "grid",
                                      "settle_frames", "output",     "cameras",     "plane",
                                      "board",         "projectors", "response"};
  for (const auto& [key, value] : request.items()) {
    if (key == "cmd" || key == "id") continue;
    bool known = false;
    for (const char* k : kKeys) known = known || key == k;
    if (!known) return tl::unexpected("unknown argument \"" + key + "\" for calibrate");
  }
  std::string error;
  if (auto it = request.find("mode"); it != request.end()) {
    if (*it == "apriltag" || *it == "adaptive") {
      a.tags = true;
      a.adaptive = *it == "adaptive";
      for (const char* gray_only : {"step", "phase_steps", "grid"}) {
        if (request.contains(gray_only)) {
          return tl::unexpected("\"" + std::string(gray_only) +
                                "\" is for Gray-code scans, not \"mode\": \"" +
                                it->get<std::string>() + "\"");
        }
      }
    } else {
      auto mode = it->is_string() ? sl::parseMode(it->get<std::string>()) : Result<sl::Mode>{};
      if (!it->is_string() || !mode) {
        return tl::unexpected(
            std::string("\"mode\" must be \"gray\", \"gray+phase\", \"apriltag\" or \"adaptive\""));
      }
      a.mode = *mode;
    }
  }
  if (!integerArg(request, "step", 1, 256, a.step, error) ||
      !integerArg(request, "phase_steps", 3, 64, a.phase_steps, error) ||
      !integerArg(request, "grid", 1, 1024, a.grid, error)) {
    return tl::unexpected(error);
  }
  if (auto it = request.find("settle_frames"); it != request.end() && *it == "auto") {
    a.auto_settle = true;
  } else if (!integerArg(request, "settle_frames", 0, 600, a.settle_frames, error)) {
    return tl::unexpected(error + " or \"auto\"");
  } else if (it != request.end()) {
    a.auto_settle = false;
  }
  if (request.contains("phase_steps") && a.mode != sl::Mode::kGrayPhase) {
    return tl::unexpected(std::string("\"phase_steps\" needs \"mode\": \"gray+phase\""));
  }
  if (auto it = request.find("output"); it != request.end()) {
    if (!it->is_string() || it->get<std::string>().empty()) {
      return tl::unexpected(std::string("\"output\" must be a device name"));
    }
    a.output = it->get<std::string>();
  }
  if (auto it = request.find("projectors"); it != request.end()) {
    // The outputs the projectors are bound to, at most 64, no name twice; or "all".
    if (*it == "all") {
      a.all_outputs = true;
    } else {
      auto names = distinctNames(*it, 64);
      if (!names) {
        return tl::unexpected(std::string(
            "\"projectors\" must be \"all\" or a list of 1 to 64 different output names"));
      }
      a.outputs = std::move(*names);
    }
    if (request.contains("output")) {
      return tl::unexpected(std::string("give either \"output\" or \"projectors\""));
    }
  }
  if (auto it = request.find("response"); it != request.end()) {
    if (!it->is_boolean()) return tl::unexpected(std::string("\"response\" must be true or false"));
    a.response = it->get<bool>();
    if (a.tags && *a.response) {
      return tl::unexpected(std::string(
          "\"response\" measures the projector over the pixels a Gray-code scan decoded: not "
          "with \"mode\": \"apriltag\" or \"adaptive\""));
    }
  }
  if (a.tags) a.response = false;
  if (auto it = request.find("cameras"); it != request.end()) {
    auto names = distinctNames(*it, kMaxCalibrationCameras);
    if (!names) {
      return tl::unexpected(
          "\"cameras\" must name one camera (route b′), two (route a, or route b′ from both "
          "with \"plane\") or up to " +
          std::to_string(kMaxCalibrationCameras) +
          " different ones (route b′ from cameras at several positions)");
    }
    a.cameras = std::move(*names);
  }
  if (auto it = request.find("plane"); it != request.end()) {
    // a x + b y + c z + d = 0 in the world frame, as rig.json's surface.plane.
    const bool numbers =
        it->is_array() && it->size() == 4 &&
        std::all_of(it->begin(), it->end(), [](const json& v) { return v.is_number(); });
    if (numbers) {
      a.plane = geom::planeFromCoefficients((*it)[0].get<double>(), (*it)[1].get<double>(),
                                            (*it)[2].get<double>(), (*it)[3].get<double>());
    }
    if (!a.plane) {
      return tl::unexpected(std::string(
          "\"plane\" must be 4 finite numbers [a, b, c, d] (a x + b y + c z + d = 0, world "
          "metres) with a non-zero normal"));
    }
  }
  if (auto it = request.find("board"); it != request.end()) {
    auto spec = boardArg(*it);
    if (!spec) return tl::unexpected(spec.error());
    if (a.plane) {
      return tl::unexpected(
          std::string("give either \"plane\" or \"board\": both say where the display plane is"));
    }
    if (a.cameras.size() >= 2) {
      return tl::unexpected(
          std::string("\"board\" is for route (b′) with one camera; \"cameras\" names more"));
    }
    a.board = *spec;
    a.board_text = it->get<std::string>();
  }
  return a;
}

}  // namespace procam::daemon
