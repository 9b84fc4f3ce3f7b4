#pragma once
// Ray intersection with the surface primitives of the virtual rig and of surface
// models ([Raskar02] §3.1.1: M = TV ∧ D). All return the nearest hit with t in
// (t_min, t_max), or nullopt.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/plane_fit.hpp"

namespace procam::geom {

struct Hit {
  double t = 0;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit, facing against the ray (dot(normal, dir) <= 0)
  std::uint32_t primitive = 0;  // triangle index for meshes, face id otherwise
};

struct RayRange {
  double t_min = 1e-9;
  double t_max = 1e300;
};

std::optional<Hit> intersectPlane(const Ray& ray, const Plane& plane, RayRange range = {});

// Bounded rectangle: origin + a*u + b*v with a in [0, |u|], b in [0, |v|]; u ⟂ v.
struct Rectangle {
  Vec3 origin = Vec3::Zero();
  Vec3 u = Vec3::UnitX();
  Vec3 v = Vec3::UnitY();
};
std::optional<Hit> intersectRectangle(const Ray& ray, const Rectangle& rect, RayRange range = {});

// Oriented box: centre, half extents along the columns of `axes` (a rotation).
struct Box {
  Vec3 center = Vec3::Zero();
  Vec3 half = Vec3::Ones();
  Mat3 axes = Mat3::Identity();
};
std::optional<Hit> intersectBox(const Ray& ray, const Box& box, RayRange range = {});

// Finite cylinder around the axis base + s*axis, s in [0, height]; side wall only
// (open ends), hit from outside or inside.
struct Cylinder {
  Vec3 base = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();  // unit
  double radius = 1;
  double height = 1;
};
std::optional<Hit> intersectCylinder(const Ray& ray, const Cylinder& cyl, RayRange range = {});

// Sphere, optionally restricted to the cap {x : dot(x - center, cap_axis) >= cap_min}
// (a dome is a sphere with cap_min = 0); hit from outside or inside.
struct Sphere {
  Vec3 center = Vec3::Zero();
  double radius = 1;
  Vec3 cap_axis = Vec3::UnitZ();
  double cap_min = -1e300;
};
std::optional<Hit> intersectSphere(const Ray& ray, const Sphere& sphere, RayRange range = {});

// Single triangle (Möller–Trumbore), two-sided. A triangle whose angle at `a` has a
// sine below 1e-8 counts as degenerate (its plane is not resolvable in doubles), and
// a ray within ~1e-12 rad of the triangle's plane is a miss.
std::optional<Hit> intersectTriangle(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c,
                                     RayRange range = {});

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<Eigen::Vector3i> faces;  // indices into vertices
  // Per vertex, when the file gives them (PLY u v): a measured display surface's
  // projector pixel that lit the vertex. Empty otherwise.
  std::vector<Vec2> uv;
  // Per vertex, when the file gives them (OBJ vt, PLY s t): texture coordinates, u right,
  // v up. Empty otherwise.
  std::vector<Vec2> texcoord;
};

// Mesh intersector: brute force for small meshes, a BVH (SAH-binned) above
// kBvhThreshold triangles. Immutable after build, safe to share between threads.
class MeshIntersector {
 public:
  static constexpr std::size_t kBvhThreshold = 2000;

  // kInvalidInput for out-of-range indices or non-finite vertices.
  static Result<MeshIntersector> build(TriangleMesh mesh);

  std::optional<Hit> intersect(const Ray& ray, RayRange range = {}) const;
  bool usesBvh() const;
  const TriangleMesh& mesh() const;

  MeshIntersector(MeshIntersector&&) noexcept;
  MeshIntersector& operator=(MeshIntersector&&) noexcept;
  ~MeshIntersector();

 private:
  struct Impl;
  explicit MeshIntersector(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace procam::geom
