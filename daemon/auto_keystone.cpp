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
}

std::optional<Vec3> TiltTracker::add(const procam_tilt_sample& s) {
  // A timer may poll faster than the sensor delivers: the same sample twice.
  if (last_ns_ && s.timestamp_ns <= *last_ns_) return std::nullopt;
  tilt::TiltSample raw;
  raw.specific_force = Vec3(s.specific_force[0], s.specific_force[1], s.specific_force[2]);
  raw.timestamp_ns = s.timestamp_ns;
  if (!gate_.check(raw)) return std::nullopt;
  last_ns_ = s.timestamp_ns;
  const Vec3 g = mount_.calibration.apply(raw.specific_force / tilt::kStandardGravity);
  auto out = filter_.update(g, static_cast<double>(s.timestamp_ns) * 1e-9);
  if (!out) return std::nullopt;  // only non-finite input, which the gate already refused
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
