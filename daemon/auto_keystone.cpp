#include "auto_keystone.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "keystone/keystone_solver.hpp"
#include "state_file.hpp"

namespace procam::daemon {

namespace {

bool isRotation(const Mat3& R) {
  return R.allFinite() && (R * R.transpose() - Mat3::Identity()).norm() < 1e-6 &&
         R.determinant() > 0;
}

}  // namespace

Result<TiltMount> mountFromConfig(const KeystoneConfig& config) {
  TiltMount m;
  if (config.mount) {
    for (int i = 0; i < 9; ++i) m.sensor_from_projector(i / 3, i % 3) = (*config.mount)[i];
    if (!isRotation(m.sensor_from_projector)) {
      return fail(ErrorCode::kInvalidInput,
                  "keystone.mount is not a rotation (rows must be orthonormal, det +1)");
    }
  }
  for (int i = 0; i < 3; ++i) {
    m.calibration.offset[i] = config.accel_offset_g[i];
    m.calibration.scale[i] = config.accel_scale[i];
  }
  m.calibration_source = "configuration";
  return m;
}

Result<ProjectorModel> projectorFromRigFile(const std::string& state_dir, const std::string& name) {
  const std::string path = state_dir + "/rig.json";
  auto text = readWholeFile(path);
  if (!text) return tl::unexpected(text.error());
  const nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  const auto bad = [&](const std::string& why) {
    return fail(ErrorCode::kParse, path + ": " + why);
  };
  if (j.is_discarded() || !j.is_object()) return bad("not a JSON object");
  const auto it = j.find("projectors");
  if (it == j.end() || !it->is_array()) return bad("no \"projectors\" array");
  const nlohmann::json* chosen = nullptr;
  for (const auto& p : *it) {
    if (p.is_object() && p.value("name", "") == name) chosen = &p;
  }
  if (!chosen && it->size() == 1) chosen = &(*it)[0];
  if (!chosen) return fail(ErrorCode::kNotFound, path + " has no projector '" + name + "'");
  const auto& p = *chosen;
  const auto K = p.find("K");
  if (K == p.end() || !K->is_array() || K->size() != 9)
    return bad("projector \"K\" needs 9 numbers");
  Mat3 M;
  for (int i = 0; i < 9; ++i) {
    if (!(*K)[i].is_number()) return bad("projector \"K\" needs 9 numbers");
    M(i / 3, i % 3) = (*K)[i].get<double>();
  }
  if (!p.contains("width") || !p.contains("height") || !p["width"].is_number_integer() ||
      !p["height"].is_number_integer()) {
    return bad("projector needs integer \"width\" and \"height\"");
  }
  if (!M.allFinite() || M(2, 2) == 0) return bad("projector \"K\" is not finite");
  ProjectorModel out;
  out.K = geom::Intrinsics::fromMatrix(M);
  out.width = p["width"].get<int>();
  out.height = p["height"].get<int>();
  out.source = path;
  if (out.K.fx <= 0 || out.K.fy <= 0 || out.width <= 0 || out.height <= 0) {
    return bad("projector intrinsics or size are not positive");
  }
  return out;
}

Result<TiltTracker> TiltTracker::create(const KeystoneConfig& config, TiltMount mount) {
  keystone::TiltFilterOptions o;
  o.cutoff_hz = config.cutoff_hz;
  o.hysteresis = config.hysteresis_deg * std::numbers::pi / 180.0;
  auto filter = keystone::TiltFilter::create(o);
  if (!filter) return tl::unexpected(filter.error());
  return TiltTracker(std::move(*filter), std::move(mount));
}

void TiltTracker::reset() {
  filter_.reset();
  last_ns_.reset();
  still_ = false;
  raw_sum_.setZero();
  raw_count_ = 0;
}

void TiltTracker::setCalibration(const keystone::AccelCalibration& calibration,
                                 std::string source) {
  mount_.calibration = calibration;
  mount_.calibration_source = std::move(source);
  reset();
}

std::optional<std::pair<Vec3, long>> TiltTracker::stillMean() const {
  if (!still_ || raw_count_ == 0) return std::nullopt;
  return std::pair<Vec3, long>(raw_sum_ / double(raw_count_), raw_count_);
}

namespace {
constexpr const char* kPoseNames[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
}

Result<std::string> SixPositionCollector::add(const Vec3& mean_g) {
  if (!mean_g.allFinite() || mean_g.norm() < 0.5) {
    return fail(ErrorCode::kInvalidInput, "the reading is not a still 1 g");
  }
  Eigen::Index axis = 0;
  mean_g.cwiseAbs().maxCoeff(&axis);
  const Vec3 u = mean_g.normalized();
  if (std::abs(u[axis]) < std::cos(10.0 * std::numbers::pi / 180.0)) {
    return fail(ErrorCode::kInvalidInput,
                "no sensor axis is within 10 degrees of vertical: hold one straight up or down");
  }
  const int slot = 2 * static_cast<int>(axis) + (u[axis] > 0 ? 0 : 1);
  poses_[slot] = mean_g;
  return std::string(kPoseNames[slot]);
}

std::vector<std::string> SixPositionCollector::filled() const {
  std::vector<std::string> out;
  for (int i = 0; i < 6; ++i) {
    if (poses_[i]) out.emplace_back(kPoseNames[i]);
  }
  return out;
}

std::vector<std::string> SixPositionCollector::missing() const {
  std::vector<std::string> out;
  for (int i = 0; i < 6; ++i) {
    if (!poses_[i]) out.emplace_back(kPoseNames[i]);
  }
  return out;
}

Result<keystone::CalibrationFit> SixPositionCollector::solve() const {
  if (const auto m = missing(); !m.empty()) {
    std::string list;
    for (const auto& name : m) list += (list.empty() ? "" : ", ") + name;
    return fail(ErrorCode::kTooFewPoints,
                "six-position calibration still needs the holds with " + list + " up");
  }
  std::vector<Vec3> readings;
  for (const auto& p : poses_) readings.push_back(*p);
  return keystone::calibrateSixPosition(readings);
}

std::optional<Vec3> TiltTracker::add(const procam_tilt_sample& s) {
  // A timer may poll faster than the sensor delivers: the same sample twice.
  if (last_ns_ && s.timestamp_ns <= *last_ns_) return std::nullopt;
  tilt::TiltSample raw;
  raw.specific_force = Vec3(s.specific_force[0], s.specific_force[1], s.specific_force[2]);
  raw.timestamp_ns = s.timestamp_ns;
  if (!gate_.check(raw)) return std::nullopt;
  last_ns_ = s.timestamp_ns;
  const Vec3 raw_g = raw.specific_force / tilt::kStandardGravity;
  auto out =
      filter_.update(mount_.calibration.apply(raw_g), static_cast<double>(s.timestamp_ns) * 1e-9);
  if (!out) return std::nullopt;  // only non-finite input, which the gate already refused
  if (!out->still) {
    raw_sum_.setZero();
    raw_count_ = 0;
  } else {
    raw_sum_ += raw_g;
    ++raw_count_;
  }
  still_ = out->still;
  if (!out->changed) return std::nullopt;
  // downFromSpecificForce takes the sensor -> projector rotation.
  return keystone::downFromSpecificForce(mount_.sensor_from_projector.transpose(), out->published)
      .normalized();
}

Result<KeystoneEstimate> solveFromDown(const ProjectorModel& projector, const Vec3& down,
                                       int content_width, int content_height) {
  auto angles = keystone::tiltFromDown(down);
  if (!angles) return tl::unexpected(angles.error());
  keystone::KeystoneProblem p;
  p.K = projector.K;
  p.width = projector.width;
  p.height = projector.height;
  p.R = keystone::rotationFromAngles(*angles);
  p.content_width = content_width;
  p.content_height = content_height;
  auto s = keystone::solveKeystone(p);
  if (!s) return tl::unexpected(s.error());
  KeystoneEstimate e;
  e.H = s->H;
  e.down = down;
  e.angles = *angles;
  e.scale = s->scale;
  e.content_width = content_width;
  e.content_height = content_height;
  return e;
}

}  // namespace procam::daemon
