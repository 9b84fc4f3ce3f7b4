#include "keystone/rig_keystone.hpp"

#include <cmath>

namespace procam::keystone {

Result<KeystoneSolution> solveRigKeystone(const RigKeystoneProblem& p) {
  const geom::PlaneBasis& stored = p.projector_to_plane.basis;
  const Mat3& H = p.projector_to_plane.H;
  if (!stored.origin.allFinite() || !stored.u.allFinite() || !stored.v.allFinite() ||
      std::abs(stored.u.norm() - 1) > 1e-6 || std::abs(stored.v.norm() - 1) > 1e-6 ||
      std::abs(stored.u.dot(stored.v)) > 1e-6)
    return fail(ErrorCode::kInvalidInput, "the plane basis is not orthonormal");
  if (!H.allFinite()) return fail(ErrorCode::kInvalidInput, "the collineation is not finite");
  // Re-expressed in the upright basis of the same plane and side, same origin.
  const Vec3 n = stored.normal();
  const geom::Plane plane{n, -n.dot(stored.origin)};
  auto upright = geom::uprightBasis(plane, stored.origin + n, stored.origin);
  if (!upright) return tl::unexpected(upright.error());
  auto change = geom::changeOfBasis(stored, *upright);
  if (!change) return tl::unexpected(change.error());
  Mat3 to_wall = *change * H;
  // Orient so that the framebuffer's centre lies in front (w > 0); corners that
  // then have w <= 0 are beyond the wall's horizon.
  const Vec2 centre(0.5 * (p.width - 1), 0.5 * (p.height - 1));
  if ((to_wall * centre.homogeneous()).z() < 0) to_wall = -to_wall;
  const Eigen::FullPivLU<Mat3> lu(to_wall);
  if (!lu.isInvertible()) return fail(ErrorCode::kInvalidInput, "the collineation is singular");
  return solveOnWall(lu.inverse(), p.width, p.height, p.content_width, p.content_height,
                     p.inscribe);
}

}  // namespace procam::keystone
