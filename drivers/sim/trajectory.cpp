#include "sim/trajectory.hpp"

#include <algorithm>
#include <cmath>

#include "sim/orientation.hpp"

namespace procam::sim {

Result<Trajectory> Trajectory::create(std::string name, std::vector<Keyframe> keys, bool loop,
                                      Easing easing) {
  if (keys.empty())
    return fail(ErrorCode::kInvalidInput, "trajectory '" + name + "' has no keyframes");
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!std::isfinite(keys[i].time) || !keys[i].center.allFinite())
      return fail(ErrorCode::kInvalidInput, "trajectory '" + name + "': non-finite keyframe");
    if (i > 0 && !(keys[i].time > keys[i - 1].time))
      return fail(ErrorCode::kInvalidInput,
                  "trajectory '" + name + "': keyframe times must increase strictly");
    keys[i].orientation.normalize();
  }
  Trajectory traj;
  traj.name_ = std::move(name);
  traj.keys_ = std::move(keys);
  traj.loop_ = loop && traj.keys_.size() > 1;
  traj.easing_ = easing;
  return traj;
}

Keyframe Trajectory::sample(double time) const {
  const double t0 = keys_.front().time;
  const double t1 = keys_.back().time;
  if (!std::isfinite(time)) time = t0;
  if (loop_) {
    const double span = t1 - t0;
    time = t0 + std::fmod(std::fmod(time - t0, span) + span, span);
  }
  if (time <= t0) return keys_.front();
  if (time >= t1) return keys_.back();
  const auto next = std::upper_bound(keys_.begin(), keys_.end(), time,
                                     [](double t, const Keyframe& k) { return t < k.time; });
  const Keyframe& b = *next;
  const Keyframe& a = *(next - 1);
  const double u = (time - a.time) / (b.time - a.time);
  const double s = easing_ == Easing::kSmooth ? u * u * u * (10.0 + u * (6.0 * u - 15.0)) : u;
  Keyframe out;
  out.time = time;
  out.center = (1.0 - s) * a.center + s * b.center;
  out.orientation = a.orientation.slerp(s, b.orientation);
  return out;
}

geom::Pose Trajectory::poseAt(double time) const {
  const Keyframe k = sample(time);
  return poseFromCenter(k.center, k.orientation.toRotationMatrix());
}

Vec3 Trajectory::centerAt(double time) const {
  return sample(time).center;
}

}  // namespace procam::sim
