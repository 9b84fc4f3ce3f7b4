#pragma once
// Display and object surfaces of the virtual rig and the nearest-hit / shadow
// queries the renderer needs. Surfaces are static; every surface is opaque and
// two-sided Lambertian.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/types.hpp"
#include "geometry/intersect.hpp"
#include "sim/surface_print.hpp"

namespace procam::sim {

struct MeshShape {
  std::string file;  // as written in the scene (relative to the scene file)
  std::shared_ptr<const geom::MeshIntersector> mesh;  // in world coordinates
};

using Shape =
    std::variant<geom::Plane, geom::Rectangle, geom::Box, geom::Cylinder, geom::Sphere, MeshShape>;

struct Surface {
  std::string name;
  std::string type;  // as in the scene file: plane, rectangle, box, cylinder, sphere, dome, mesh
  Vec3 albedo_rgb = Vec3::Constant(0.8);  // diffuse reflectance per channel, [0, 1]
  Shape shape;
  std::shared_ptr<const SurfacePrint> print;  // a board on a plane or rectangle, if any
  // Moved by scene events since the scene began (world metres): the shape and its print
  // stand where they were read, and rays meet them shifted back by this much.
  Vec3 offset = Vec3::Zero();
};

struct SurfaceHit {
  geom::Hit hit;
  int surface = -1;  // index into the surface list
};

// Nearest-hit and occlusion queries over a list of surfaces.
class World {
 public:
  World() = default;
  explicit World(std::vector<Surface> surfaces) : surfaces_(std::move(surfaces)) {}

  std::optional<SurfaceHit> intersect(const geom::Ray& ray, geom::RayRange range = {}) const;
  // True when anything lies on the ray strictly between t_min and t_max. A planar
  // surface cannot shadow its own points: `on_surface` (the index of the surface the
  // ray ends on, or -1) is skipped when it is a plane or a rectangle.
  bool occluded(const geom::Ray& ray, double t_max, int on_surface = -1) const;

  const std::vector<Surface>& surfaces() const { return surfaces_; }
  // The same world with surface `index` moved by `by` (world metres).
  World moved(std::size_t index, const Vec3& by) const;

 private:
  std::vector<Surface> surfaces_;
};

std::optional<geom::Hit> intersectShape(const Shape& shape, const geom::Ray& ray,
                                        geom::RayRange range);

}  // namespace procam::sim
