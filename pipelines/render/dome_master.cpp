#include "render/dome_master.hpp"

#include <cmath>

#include "render/viewer_view.hpp"

namespace procam::render {

std::optional<Vec2> DomeMaster::contentPixel(const Vec3& X) const {
  const Vec3 d = frame * (X - eye);  // (right, front, up)
  const double n = d.norm();
  if (!(n > 1e-12)) return std::nullopt;
  const double horizontal = std::hypot(d.x(), d.y());
  const double theta = std::atan2(horizontal, d.z());  // from the zenith
  if (theta > half_fov) return std::nullopt;
  const double r = radius() * theta / half_fov;
  // Straight up: the centre, whatever the azimuth. Straight down (a 360-degree master):
  // the whole rim is the nadir; the front's point of it stands for it.
  if (horizontal < 1e-15 * n) return d.z() > 0 ? centre() : Vec2(centre() + Vec2(0, r));
  return centre() + r * Vec2(d.x(), d.y()) / horizontal;
}

std::optional<Vec3> DomeMaster::direction(const Vec2& c) const {
  const Vec2 q = (c - centre()) / radius();
  const double r = q.norm();
  if (r > 1) return std::nullopt;
  const double theta = r * half_fov;
  const Vec2 azimuth = r > 0 ? Vec2(q / r) : Vec2(0, 1);
  const Vec3 local(std::sin(theta) * azimuth.x(), std::sin(theta) * azimuth.y(), std::cos(theta));
  return frame.transpose() * local;
}

Result<DomeMaster> domeMaster(const Vec3& eye, const Vec3& front, double fov_deg,
                              cv::Size content) {
  if (!eye.allFinite() || !front.allFinite())
    return fail(ErrorCode::kInvalidInput, "dome master: the eye or front is not finite");
  if (!(fov_deg > 0 && fov_deg <= 360))
    return fail(ErrorCode::kInvalidInput, "dome master: field of view outside (0, 360] degrees");
  if (content.width < 1 || content.height < 1)
    return fail(ErrorCode::kInvalidInput, "dome master: empty content");
  const Vec3 up = Vec3::UnitZ();
  Vec3 f = front - front.dot(up) * up;
  if (f.norm() < 1e-6 * std::max(1.0, front.norm()))
    return fail(ErrorCode::kInvalidInput, "dome master: the front is vertical");
  f.normalize();
  DomeMaster m;
  m.eye = eye;
  m.frame.row(0) = f.cross(up).transpose();  // right of a viewer facing the front
  m.frame.row(1) = f.transpose();
  m.frame.row(2) = up.transpose();
  m.half_fov = 0.5 * fov_deg * M_PI / 180;
  m.content = content;
  return m;
}

Result<WarpGrid> lookupGridForDome(const geom::MeshIntersector& surface, const Mat34& projector,
                                   cv::Size size, const DomeMaster& master, int step,
                                   std::shared_ptr<const WarpGrid> post_warp) {
  if (!(master.half_fov > 0) || !master.eye.allFinite())
    return fail(ErrorCode::kInvalidInput, "dome lookup grid: bad dome master");
  return lookupGridThrough(surface, projector, size, step, std::move(post_warp),
                           [&master](const Vec3& X) { return master.contentPixel(X); });
}

}  // namespace procam::render
