#pragma once
// Dome-master content: the fisheye image planetarium and dome media come in. The
// content is the image the viewer should see ([Raskar02] §4.1.5), and on a dome the
// viewer looks everywhere, so it is the sky around the eye rather than one pinhole's
// view: the image centre is the zenith (world +Z), the distance from it grows in
// proportion to the angle from the zenith (azimuthal equidistant projection, the
// inscribed circle's edge at half the field of view), the front of the dome at the
// bottom of the circle and its right at the right. A projector pixel shows the content
// pixel of the direction from the eye to the surface point it lights (the lookup warp
// of §4.1.5, with this projection in place of the eye's pinhole).
#include <memory>
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/intersect.hpp"
#include "render/warp_map.hpp"

namespace procam::render {

struct DomeMaster {
  Vec3 eye = Vec3::Zero();
  Mat3 frame = Mat3::Identity();  // rows: right, front, zenith (world directions)
  double half_fov = 0;            // radians from the zenith to the circle's edge
  cv::Size content;

  // The circle: centre (pixel centres at integers) and radius in content pixels (its
  // edge on the pixel edges of the shorter side).
  Vec2 centre() const { return {0.5 * (content.width - 1), 0.5 * (content.height - 1)}; }
  double radius() const { return 0.5 * std::min(content.width, content.height); }

  // The content pixel of world point X seen from the eye; nullopt outside the field
  // of view or at the eye.
  std::optional<Vec2> contentPixel(const Vec3& X) const;
  // The world direction (unit) content pixel c shows; nullopt outside the circle.
  std::optional<Vec3> direction(const Vec2& c) const;
};

// `front`: the horizontal direction the bottom of the circle faces (its vertical part is
// ignored); `fov_deg` in (0, 360]. kInvalidInput for a non-finite eye, a front that is
// (nearly) vertical, a field of view outside (0, 360] or an empty content size.
Result<DomeMaster> domeMaster(const Vec3& eye, const Vec3& front, double fov_deg, cv::Size content);

// The lookup warp of a projector onto dome-master content: nodes every `step`
// framebuffer pixels (render::framebufferGrid) holding the content pixel each shows;
// nodes whose ray misses the surface or that fall outside the field of view hold
// kOutside. `projector` and `post_warp` as lookupGridForViewer takes them.
Result<WarpGrid> lookupGridForDome(const geom::MeshIntersector& surface, const Mat34& projector,
                                   cv::Size projector_size, const DomeMaster& master, int step = 8,
                                   std::shared_ptr<const WarpGrid> post_warp = nullptr);

}  // namespace procam::render
