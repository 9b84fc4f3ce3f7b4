#include "keystone/keystone_from_down.hpp"

#include "keystone/keystone_solver.hpp"

namespace procam::keystone {

Result<KeystoneEstimate> solveFromDown(const ProjectorModel& projector, const Vec3& down,
                                       int content_width, int content_height) {
  auto angles = tiltFromDown(down);
  if (!angles) return tl::unexpected(angles.error());
  return solveFromOrientation(projector, rotationFromAngles(*angles), down, content_width,
                              content_height);
}

Result<KeystoneEstimate> solveFromOrientation(const ProjectorModel& projector, const Mat3& R,
                                              const Vec3& down, int content_width,
                                              int content_height) {
  KeystoneProblem p;
  p.K = projector.K;
  p.width = projector.width;
  p.height = projector.height;
  p.R = R;
  p.content_width = content_width;
  p.content_height = content_height;
  auto s = solveKeystone(p);
  if (!s) return tl::unexpected(s.error());
  KeystoneEstimate e;
  e.H = s->H;
  e.down = down;
  e.angles = anglesFromRotation(R);
  e.scale = s->scale;
  e.content_width = content_width;
  e.content_height = content_height;
  return e;
}

}  // namespace procam::keystone
