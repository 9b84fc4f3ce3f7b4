#include "keystone/six_position.hpp"

#include <cmath>

#include "core/units.hpp"

namespace procam::keystone {

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
  if (std::abs(u[axis]) < std::cos(degToRad(10.0))) {
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

Result<CalibrationFit> SixPositionCollector::solve() const {
  if (const auto m = missing(); !m.empty()) {
    std::string list;
    for (const auto& name : m) list += (list.empty() ? "" : ", ") + name;
    return fail(ErrorCode::kTooFewPoints,
                "six-position calibration still needs the holds with " + list + " up");
  }
  std::vector<Vec3> readings;
  for (const auto& p : poses_) readings.push_back(*p);
  return calibrateSixPosition(readings);
}

}  // namespace procam::keystone
