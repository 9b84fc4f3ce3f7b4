#pragma once
// Keyframed device or viewer motion: time -> pose, positions interpolated linearly
// and orientations by quaternion slerp. Before the first keyframe the first pose
// holds, after the last the last one (or the motion repeats when `loop` is set).
// With kSmooth easing each segment follows the minimum-jerk profile of a hand's
// movement (Flash and Hogan 1985: s = 10u^3 - 15u^4 + 6u^5 of the segment's time
// fraction u): it starts and ends at rest with no jump of speed or acceleration.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::sim {

struct Keyframe {
  double time = 0;                 // seconds
  Vec3 center = Vec3::Zero();      // device origin in world, metres
  Eigen::Quaterniond orientation;  // world-from-device rotation (unit)
};

enum class Easing { kLinear, kSmooth };

class Trajectory {
 public:
  // Keyframes must have finite, strictly increasing times (kInvalidInput otherwise).
  static Result<Trajectory> create(std::string name, std::vector<Keyframe> keys, bool loop,
                                   Easing easing = Easing::kLinear);

  geom::Pose poseAt(double time) const;  // world -> device
  Vec3 centerAt(double time) const;

  const std::string& name() const { return name_; }
  const std::vector<Keyframe>& keyframes() const { return keys_; }
  bool loops() const { return loop_; }
  Easing easing() const { return easing_; }
  double duration() const { return keys_.back().time - keys_.front().time; }

 private:
  Keyframe sample(double time) const;

  std::string name_;
  std::vector<Keyframe> keys_;
  bool loop_ = false;
  Easing easing_ = Easing::kLinear;
};

}  // namespace procam::sim
