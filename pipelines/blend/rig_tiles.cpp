#include "blend/rig_tiles.hpp"

#include <Eigen/LU>
#include <cmath>

namespace procam::blend {

Result<DisplayTile> displayTile(const rig::RigProjector& p, const rig::RigSurface& surface) {
  if (p.width < 2 || p.height < 2)
    return fail(ErrorCode::kInvalidInput, "projector '" + p.name + "': no framebuffer size");
  if (p.plane_homography) return DisplayTile{*p.plane_homography, p.width, p.height};
  if (!p.intrinsics_known || !p.pose_known || !p.scale_known || !surface.plane) {
    return fail(ErrorCode::kNotFound,
                "projector '" + p.name +
                    "' has no collineation with a display plane (route (b') plane_homography, "
                    "or a metric pose and a planar surface)");
  }
  const geom::Plane& plane = *surface.plane;
  const Vec3 centre = p.pose.center();
  const Vec3 foot = centre - plane.signedDistance(centre) * plane.n;
  auto basis = geom::uprightBasis(plane, centre, foot);
  if (!basis) return tl::unexpected(basis.error());
  auto to_image = geom::planeToImage(p.K, p.pose, *basis);
  if (!to_image) return tl::unexpected(to_image.error());
  const Eigen::FullPivLU<Mat3> lu(*to_image);
  if (!lu.isInvertible())
    return fail(ErrorCode::kDegenerate, "projector '" + p.name + "': sees the plane edge-on");
  return DisplayTile{geom::PlaneHomography{*basis, lu.inverse()}, p.width, p.height};
}

std::optional<ProjectorResponse> projectorResponse(const rig::RigProjector& projector) {
  const nlohmann::json& ph = projector.photometric;
  if (!ph.is_object()) return std::nullopt;
  const auto number = [&](const char* key) {
    const auto it = ph.find(key);
    return it != ph.end() && it->is_number() ? it->get<double>() : std::nan("");
  };
  ProjectorResponse r;
  r.gamma = number("response_gamma");
  r.black = number("black");
  r.white = number("white");
  if (!(r.gamma >= 1 && r.gamma <= 4) || !std::isfinite(r.black) || !(r.white > r.black)) {
    return std::nullopt;
  }
  if (const auto it = ph.find("camera"); it != ph.end() && it->is_string())
    r.camera = it->get<std::string>();
  if (const auto it = ph.find("brightness"); it != ph.end()) {
    auto map = brightnessFromJson(*it);
    if (map && map->width == projector.width && map->height == projector.height)
      r.brightness = std::move(*map);
  }
  return r;
}

}  // namespace procam::blend
