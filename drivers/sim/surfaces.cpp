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

namespace {

// The ray as a surface moved by `offset` sees it: shifted back by the offset (t and the
// direction are unchanged, so hits compare across surfaces).
geom::Ray shiftedBack(const geom::Ray& ray, const Vec3& offset) {
  return offset.isZero() ? ray : geom::Ray{ray.origin - offset, ray.dir};
}

}  // namespace

std::optional<SurfaceHit> World::intersect(const geom::Ray& ray, geom::RayRange range) const {
  std::optional<SurfaceHit> best;
  for (std::size_t i = 0; i < surfaces_.size(); ++i) {
    const Vec3& offset = surfaces_[i].offset;
    auto hit = intersectShape(surfaces_[i].shape, shiftedBack(ray, offset), range);
    if (!hit) continue;
    hit->point += offset;
    range.t_max = hit->t;  // later surfaces must be nearer to win
    best = SurfaceHit{*hit, static_cast<int>(i)};
  }
  return best;
}

World World::moved(std::size_t index, const Vec3& by) const {
  World out = *this;
  if (index < out.surfaces_.size()) out.surfaces_[index].offset += by;
  return out;
}

bool World::occluded(const geom::Ray& ray, double t_max, int on_surface) const {
  const geom::RayRange range{1e-9, t_max};
  for (std::size_t i = 0; i < surfaces_.size(); ++i) {
    const Shape& shape = surfaces_[i].shape;
    if (static_cast<int>(i) == on_surface && (std::holds_alternative<geom::Plane>(shape) ||
                                              std::holds_alternative<geom::Rectangle>(shape)))
      continue;
    if (intersectShape(shape, shiftedBack(ray, surfaces_[i].offset), range)) return true;
  }
  return false;
}

}  // namespace procam::sim
