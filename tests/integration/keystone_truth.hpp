#pragma once
// A keystone the daemon reports, judged against the true projector on a wall of
// the wall frame (keystone/orientation.hpp: the plane Y = const facing -Y, +Z up),
// with procamd's keystone accuracy bounds in mind (ARCHITECTURE.md: corner <= 0.5
// px, aspect within 0.1 %, area within 0.5 % of the largest upright rectangle).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "keystone/display_error.hpp"
#include "keystone/keystone_solver.hpp"
#include "sim/scene.hpp"

namespace procam::itest {

inline Mat3 matrixOf(const nlohmann::json& rows) {
  Mat3 H;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) H(r, c) = rows[r][c].get<double>();
  }
  return H;
}

// How far a plane [a, b, c, d] (a x + b y + c z + d = 0) a reply reports is from the
// wall y = `wall_y`: its normal's angle to the wall's (degrees) and its offset (mm).
struct PlaneOff {
  double angle_deg = 0, offset_mm = 0;
};
inline PlaneOff planeOffTheWall(const nlohmann::json& plane, double wall_y) {
  const Vec3 n(plane[0].get<double>(), plane[1].get<double>(), plane[2].get<double>());
  const double sign = n.y() < 0 ? -1.0 : 1.0;
  return {std::acos(std::min(1.0, sign * n.normalized().y())) * 180 / M_PI,
          std::abs(sign * plane[3].get<double>() / n.norm() + wall_y) * 1000};
}

// The content's outer corners (pixel edges) through H: what solveKeystone reports.
inline std::array<Vec2, 4> outerCorners(const Mat3& H, int w, int h) {
  const std::array<Vec2, 4> c = {Vec2(-0.5, -0.5), Vec2(w - 0.5, -0.5), Vec2(w - 0.5, h - 0.5),
                                 Vec2(-0.5, h - 0.5)};
  std::array<Vec2, 4> out;
  for (int i = 0; i < 4; ++i) out[i] = (H * c[i].homogeneous()).hnormalized();
  return out;
}

struct Measured {
  double corner_px = 0, aspect_rel = 0, area_rel = 0;
};

// `H` (content pixels -> framebuffer, as the daemon reports it) against the ideal
// solution of the true projector (K, R: wall frame -> projector): the largest
// corner distance to the ideal rectangle and to the upright rectangle through the
// shown corners (framebuffer pixels), the aspect error and the area against the
// largest upright rectangle inside the true footprint.
inline Measured measureAgainstTruth(const geom::Intrinsics& K, const Mat3& R, int width, int height,
                                    const Mat3& H, int content_width, int content_height) {
  keystone::KeystoneProblem p;
  p.K = K;
  p.width = width;
  p.height = height;
  p.R = R;
  p.content_width = content_width;
  p.content_height = content_height;
  auto truth = keystone::solveKeystone(p);
  EXPECT_TRUE(truth) << truth.error().message;
  if (!truth) return {1e9, 1e9, 1e9};
  const auto got = outerCorners(H, content_width, content_height);
  Measured m;
  for (int i = 0; i < 4; ++i)
    m.corner_px = std::max(m.corner_px, (got[i] - truth->corners[i]).norm());
  const auto err = keystone::displayError(p.K, p.R, got);
  m.corner_px = std::max(m.corner_px, err.max_corner_px);
  m.aspect_rel = std::abs(err.aspect / (double(content_width) / content_height) - 1);
  m.area_rel = std::abs(err.area / truth->rect.area() - 1);
  return m;
}

// An event with a keystone `homography` and `content_size` on a handheld scene (projector
// "proj" before the wall y = 2.5 facing -y: the world frame is the wall frame) against
// the truth at time t.
inline Measured handheldAgainstTruthAt(const sim::Scene& scene, const nlohmann::json& event,
                                       double t) {
  const sim::SceneState state = scene.at(t);
  const sim::ProjectorState* proj = state.projector("proj");
  EXPECT_TRUE(proj);
  if (!proj) return {1e9, 1e9, 1e9};
  return measureAgainstTruth(proj->spec.K, proj->model.pose.R, proj->spec.width, proj->spec.height,
                             matrixOf(event["homography"]), event["content_size"][0].get<int>(),
                             event["content_size"][1].get<int>());
}

// A keystone event of the daemon on a handheld scene (projector "proj" before the wall
// y = 2.5 facing -y, which makes the world frame the wall frame of
// keystone/orientation.hpp, so the pose's rotation, yaw included, is R) against the
// truth at the time it was solved for: the tilt sample's time plus the lead the daemon
// predicted the turn over (0 unless the gyroscope carries a turn).
inline Measured handheldEventAgainstTruth(const sim::Scene& scene, const nlohmann::json& event) {
  return handheldAgainstTruthAt(scene, event, event["estimate"]["display_time"].get<double>());
}

// A `keystone_shown` event (a frame on the output, its homography and the time it went
// on the wall, on the tilt sensor's clock) against the truth at that time.
inline Measured handheldShownAgainstTruth(const sim::Scene& scene, const nlohmann::json& shown) {
  return handheldAgainstTruthAt(scene, shown, shown["display_time"].get<double>());
}

}  // namespace procam::itest
