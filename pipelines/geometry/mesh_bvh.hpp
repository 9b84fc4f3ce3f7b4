#pragma once
// Bounding volume hierarchy over the triangles of a mesh (binned surface area
// heuristic, nodes flattened depth-first). Used by MeshIntersector above
// kBvhThreshold triangles; gives exactly the nearest hit brute force would give.
#include <cstdint>
#include <optional>
#include <vector>

#include "core/types.hpp"
#include "geometry/intersect.hpp"

namespace procam::geom {

class MeshBvh {
 public:
  // The mesh must already be validated (finite vertices, indices in range).
  static MeshBvh build(const TriangleMesh& mesh);

  std::optional<Hit> intersect(const TriangleMesh& mesh, const Ray& ray, RayRange range) const;

  std::size_t nodeCount() const { return nodes_.size(); }

 private:
  struct Node {
    Vec3 lo, hi;               // bounds of everything below
    std::uint32_t offset = 0;  // leaf: first entry in order_; inner: index of the right child
    std::uint32_t count = 0;   // leaf: number of triangles; inner: 0 (left child follows)
  };
  struct Builder;

  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;  // triangle indices, grouped by leaf
};

}  // namespace procam::geom
