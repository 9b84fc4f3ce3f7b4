#pragma once
// The physical object that shader lamps paint ([Raskar02] §5.2): its surface as a
// triangle mesh in world coordinates (from calibration, or a given model registered to
// the rig), with a shading normal per face corner and, when the model is textured, a
// texture coordinate per vertex. Normals are averaged over the faces around a vertex
// that turn less than a crease angle from the face itself, so a tessellated curve shades
// smoothly (the 1/cos θ of eq. 5.4 does not step at every facet) while a box keeps its
// edges.
#include <cstdint>
#include <optional>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/intersect.hpp"

namespace procam::lamps {

struct SurfacePoint {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();   // shading normal, unit, outward as the face is wound
  Vec2 texcoord = Vec2::Zero();  // (0, 0) for an untextured model
  std::uint32_t face = 0;
};

class ObjectModel {
 public:
  static constexpr std::size_t kMaxFaces = 2'000'000;

  // `texcoords`: empty, or one (u, v) in [0, 1] per vertex (v up, as OBJ's vt).
  // kInvalidInput for a mesh without faces, over kMaxFaces, with bad indices or
  // non-finite values, a texcoord count other than 0 or the vertex count, or a crease
  // outside [0, 180] degrees; kDegenerate when a face has no area.
  static Result<ObjectModel> build(geom::TriangleMesh mesh, std::vector<Vec2> texcoords = {},
                                   double crease_deg = 30);

  // The nearest surface point along a ray, with the face's interpolated normal (turned to
  // face the ray's origin) and texture coordinate.
  std::optional<SurfacePoint> intersect(const geom::Ray& ray, geom::RayRange range = {}) const;

  const geom::TriangleMesh& mesh() const { return intersector_.mesh(); }
  bool textured() const { return !texcoords_.empty(); }
  double faceArea(std::uint32_t face) const { return areas_[face]; }
  // Barycentric point of a face (weights of its vertices a, b, c).
  SurfacePoint at(std::uint32_t face, const Vec3& weights) const;

 private:
  explicit ObjectModel(geom::MeshIntersector intersector) : intersector_(std::move(intersector)) {}

  geom::MeshIntersector intersector_;
  std::vector<Vec3> corner_normals_;  // 3 per face
  std::vector<Vec2> texcoords_;       // per vertex
  std::vector<double> areas_;         // per face
};

}  // namespace procam::lamps
