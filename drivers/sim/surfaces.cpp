#include "sim/surfaces.hpp"

namespace procam::sim {

std::optional<geom::Hit> intersectShape(const Shape& shape, const geom::Ray& ray,
                                        geom::RayRange range) {
  struct Visitor {
    const geom::Ray& ray;
    geom::RayRange range;
    std::optional<geom::Hit> operator()(const geom::Plane& s) const {
      return geom::intersectPlane(ray, s, range);
    }
    std::optional<geom::Hit> operator()(const geom::Rectangle& s) const {
      return geom::intersectRectangle(ray, s, range);
    }
    std::optional<geom::Hit> operator()(const geom::Box& s) const {
      return geom::intersectBox(ray, s, range);
    }
    std::optional<geom::Hit> operator()(const geom::Cylinder& s) const {
      return geom::intersectCylinder(ray, s, range);
    }
    std::optional<geom::Hit> operator()(const geom::Sphere& s) const {
      return geom::intersectSphere(ray, s, range);
    }
    std::optional<geom::Hit> operator()(const MeshShape& s) const {
      return s.mesh->intersect(ray, range);
    }
  };
  return std::visit(Visitor{ray, range}, shape);
}

std::optional<SurfaceHit> World::intersect(const geom::Ray& ray, geom::RayRange range) const {
  std::optional<SurfaceHit> best;
  for (std::size_t i = 0; i < surfaces_.size(); ++i) {
    auto hit = intersectShape(surfaces_[i].shape, ray, range);
    if (!hit) continue;
    range.t_max = hit->t;  // later surfaces must be nearer to win
    best = SurfaceHit{*hit, static_cast<int>(i)};
  }
  return best;
}

bool World::occluded(const geom::Ray& ray, double t_max, int on_surface) const {
  const geom::RayRange range{1e-9, t_max};
  for (std::size_t i = 0; i < surfaces_.size(); ++i) {
    const Shape& shape = surfaces_[i].shape;
    if (static_cast<int>(i) == on_surface && (std::holds_alternative<geom::Plane>(shape) ||
                                              std::holds_alternative<geom::Rectangle>(shape)))
      continue;
    if (intersectShape(shape, ray, range)) return true;
  }
  return false;
}

}  // namespace procam::sim
