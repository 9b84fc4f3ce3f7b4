#include "tracker_state.hpp"

#include <cmath>
#include <vector>

#include "json_matrix.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

constexpr size_t kMaxPoints = 10000;  // far more than any registration needs

// A JSON array of exactly `n` finite numbers.
bool finiteNumbers(const json& j, size_t n, double* out) {
  if (!j.is_array() || j.size() != n) return false;
  for (size_t i = 0; i < n; ++i) {
    if (!j[i].is_number() || !std::isfinite(j[i].get<double>())) return false;
    out[i] = j[i].get<double>();
  }
  return true;
}

Result<Vec3> point(const json& j, const std::string& key) {
  if (auto v = vectorFromJson(j)) return *v;
  return fail(ErrorCode::kInvalidInput, "\"" + key + "\" must be [x, y, z] (metres)");
}

Result<size_t> index(const json& request, const char* key, size_t count) {
  auto it = request.find(key);
  if (it == request.end()) {
    return fail(ErrorCode::kInvalidInput, std::string("screen mode needs \"") + key + "\"");
  }
  if (!it->is_number_integer() || it->get<int64_t>() < 0 ||
      static_cast<uint64_t>(it->get<int64_t>()) >= count) {
    return fail(ErrorCode::kInvalidInput, std::string("\"") + key + "\" must index one of the " +
                                              std::to_string(count) + " points");
  }
  return static_cast<size_t>(it->get<int64_t>());
}

}  // namespace

json registrationJson(const TrackerRegistrationRecord& r) {
  const geom::Pose& p = r.fit.tracker_to_world;
  json R = json::array();
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) R.push_back(p.R(i, k));
  return {{"source", r.source},
          {"rms_m", r.fit.rms},
          {"points", r.points},
          {"scale", r.fit.scale},
          {"R", R},
          {"t", {p.t.x(), p.t.y(), p.t.z()}}};
}

std::string trackerFileText(const TrackerRegistrations& registrations) {
  json trackers = json::object();
  for (const auto& [name, r] : registrations) trackers[name] = registrationJson(r);
  return json{{"trackers", trackers}}.dump(2) + "\n";
}

Result<TrackerRegistrations> trackerFileFromText(std::string_view text) {
  const json doc = json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("trackers") ||
      !doc["trackers"].is_object()) {
    return fail(ErrorCode::kParse, "not a tracker.json document (an object with \"trackers\")");
  }
  TrackerRegistrations out;
  for (const auto& [name, j] : doc["trackers"].items()) {
    const std::string where = "tracker '" + name + "': ";
    double R[9], t[3];
    if (!j.is_object() || !j.contains("R") || !finiteNumbers(j["R"], 9, R) || !j.contains("t") ||
        !finiteNumbers(j["t"], 3, t)) {
      return fail(ErrorCode::kParse, where + "\"R\" (9 numbers) and \"t\" (3) are required");
    }
    TrackerRegistrationRecord r;
    Mat3& Rm = r.fit.tracker_to_world.R;
    for (int i = 0; i < 9; ++i) Rm(i / 3, i % 3) = R[i];
    if ((Rm.transpose() * Rm - Mat3::Identity()).norm() > 1e-6 || Rm.determinant() < 0) {
      return fail(ErrorCode::kParse, where + "\"R\" is not a rotation matrix");
    }
    r.fit.tracker_to_world.t = Vec3(t[0], t[1], t[2]);
    r.fit.scale = j.value("scale", 1.0);
    r.fit.rms = j.value("rms_m", 0.0);
    r.source = j.value("source", "points");
    r.points = j.value("points", 0);
    if (!(r.fit.scale > 0) || !std::isfinite(r.fit.scale)) {
      return fail(ErrorCode::kParse, where + "\"scale\" must be a positive number");
    }
    out[name] = r;
  }
  return out;
}

Result<TrackerRegistrationRecord> fitRegistrationRequest(const json& request) {
  const std::string mode = request.value("mode", std::string("points"));
  if (mode != "points" && mode != "screen") {
    return fail(ErrorCode::kInvalidInput, "\"mode\" must be \"points\" or \"screen\"");
  }
  auto it = request.find("points");
  if (it == request.end() || !it->is_array() || it->size() > kMaxPoints) {
    return fail(ErrorCode::kInvalidInput,
                mode == "points" ? "\"points\" must be a list of {tracker: [x, y, z], world: "
                                   "[x, y, z]}"
                                 : "\"points\" must be a list of {tracker: [x, y, z]}");
  }
  std::vector<Vec3> tracker, world;
  for (size_t i = 0; i < it->size(); ++i) {
    const json& p = (*it)[i];
    const std::string key = "points[" + std::to_string(i) + "]";
    if (!p.is_object() || !p.contains("tracker")) {
      return fail(ErrorCode::kInvalidInput, "\"" + key + "\" needs \"tracker\"");
    }
    auto t = point(p["tracker"], key + ".tracker");
    if (!t) return tl::unexpected(t.error());
    tracker.push_back(*t);
    if (mode == "points") {
      if (!p.contains("world")) {
        return fail(ErrorCode::kInvalidInput, "\"" + key + "\" needs \"world\"");
      }
      auto w = point(p["world"], key + ".world");
      if (!w) return tl::unexpected(w.error());
      world.push_back(*w);
    }
  }
  TrackerRegistrationRecord r;
  r.source = mode;
  r.points = static_cast<int>(tracker.size());
  Result<tracking::TrackerRegistration> fit;
  if (mode == "points") {
    fit = tracking::registerTracker(tracker, world);
  } else {
    // §4.2.5: the screen defines the world frame (origin, x axis, z = its normal).
    if (tracker.size() < 4) {
      return fail(ErrorCode::kTooFewPoints, "screen registration needs >= 4 tracker readings");
    }
    auto origin = index(request, "origin", tracker.size());
    if (!origin) return tl::unexpected(origin.error());
    auto x_axis = index(request, "x_axis", tracker.size());
    if (!x_axis) return tl::unexpected(x_axis.error());
    if (!request.contains("viewer_side")) {
      return fail(ErrorCode::kInvalidInput, "screen mode needs \"viewer_side\" [x, y, z]");
    }
    auto side = point(request["viewer_side"], "viewer_side");
    if (!side) return tl::unexpected(side.error());
    fit = tracking::registerTrackerToScreen(tracker, *origin, *x_axis, *side);
  }
  if (!fit) return tl::unexpected(fit.error());
  r.fit = *fit;
  return r;
}

}  // namespace procam::daemon
