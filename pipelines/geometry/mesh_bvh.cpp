#include "geometry/mesh_bvh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace procam::geom {
namespace {

constexpr int kBins = 16;
constexpr std::uint32_t kLeafMin = 2;    // never split below this
constexpr std::uint32_t kLeafMax = 8;    // always split above this
constexpr int kSahDepthLimit = 48;       // below this depth: object-median splits
constexpr std::size_t kStackSize = 128;  // > kSahDepthLimit + log2(2^32)

struct Bounds {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());

  void grow(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void grow(const Bounds& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  double area() const {
    if (!(hi.x() >= lo.x())) return 0;
    const Vec3 e = hi - lo;
    return 2 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
  }
};

// Rounding bound of the slab distances (Ize 2013, as used by PBRT): widening the
// interval by 2*gamma(3) keeps the box test conservative.
constexpr double kEps = std::numeric_limits<double>::epsilon() * 0.5;
constexpr double kGamma3 = 3 * kEps / (1 - 3 * kEps);

}  // namespace

struct MeshBvh::Builder {
  const TriangleMesh& mesh;
  MeshBvh& bvh;
  std::vector<Bounds> tri_bounds;
  std::vector<Vec3> centroids;

  Bounds boundsOf(std::uint32_t begin, std::uint32_t end) const {
    Bounds b;
    for (std::uint32_t i = begin; i < end; ++i) b.grow(tri_bounds[bvh.order_[i]]);
    return b;
  }

  void makeLeaf(std::uint32_t node, std::uint32_t begin, std::uint32_t end) {
    bvh.nodes_[node].offset = begin;
    bvh.nodes_[node].count = end - begin;
  }

  // Returns the split position in order_, or `begin` for "make a leaf".
  std::uint32_t sahSplit(std::uint32_t begin, std::uint32_t end, const Bounds& node_bounds) {
    Bounds cb;
    for (std::uint32_t i = begin; i < end; ++i) cb.grow(centroids[bvh.order_[i]]);
    const std::uint32_t n = end - begin;
    double best_cost = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_bin = -1;
    for (int axis = 0; axis < 3; ++axis) {
      const double lo = cb.lo[axis];
      const double extent = cb.hi[axis] - lo;
      if (!(extent > 0)) continue;
      std::array<Bounds, kBins> bins;
      std::array<std::uint32_t, kBins> counts{};
      const double scale = kBins / extent;
      for (std::uint32_t i = begin; i < end; ++i) {
        const std::uint32_t tri = bvh.order_[i];
        const int bin = std::min(kBins - 1, static_cast<int>((centroids[tri][axis] - lo) * scale));
        bins[bin].grow(tri_bounds[tri]);
        ++counts[bin];
      }
      std::array<double, kBins> right_cost{};
      Bounds acc;
      std::uint32_t cnt = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.grow(bins[b]);
        cnt += counts[b];
        right_cost[b] = acc.area() * cnt;
      }
      acc = Bounds{};
      cnt = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        acc.grow(bins[b]);
        cnt += counts[b];
        if (cnt == 0 || cnt == n) continue;
        const double cost = acc.area() * cnt + right_cost[b + 1];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_bin = b;
        }
      }
    }
    // Cost model: one box test per node, one triangle test per triangle.
    const double parent_area = node_bounds.area();
    const double leaf_cost = parent_area * n;
    if (best_axis < 0 || (n <= kLeafMax && parent_area + best_cost >= leaf_cost)) {
      return best_axis < 0 && n > kLeafMax ? medianSplit(begin, end, cb) : begin;
    }
    const double lo = cb.lo[best_axis];
    const double scale = kBins / (cb.hi[best_axis] - lo);
    auto* first = bvh.order_.data() + begin;
    auto* mid = std::partition(first, bvh.order_.data() + end, [&](std::uint32_t tri) {
      return std::min(kBins - 1, static_cast<int>((centroids[tri][best_axis] - lo) * scale)) <=
             best_bin;
    });
    return begin + static_cast<std::uint32_t>(mid - first);
  }

  // Object median on the widest centroid axis; with all centroids equal the
  // index range is simply halved. Always makes progress.
  std::uint32_t medianSplit(std::uint32_t begin, std::uint32_t end, const Bounds& cb) {
    const std::uint32_t mid = begin + (end - begin) / 2;
    int axis = 0;
    const Vec3 extent = cb.hi - cb.lo;
    extent.maxCoeff(&axis);
    auto* base = bvh.order_.data();
    std::nth_element(base + begin, base + mid, base + end, [&](std::uint32_t a, std::uint32_t b) {
      return centroids[a][axis] < centroids[b][axis];
    });
    return mid;
  }

  void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth) {
    const Bounds b = boundsOf(begin, end);
    // Pad by a relative amount so rounding in the slab test can never cull a hit
    // that the triangle test itself would report.
    const Vec3 pad = (b.hi - b.lo + b.lo.cwiseAbs().cwiseMax(b.hi.cwiseAbs())) * 1e-12;
    bvh.nodes_[node].lo = b.lo - pad;
    bvh.nodes_[node].hi = b.hi + pad;
    const std::uint32_t n = end - begin;
    if (n <= kLeafMin) return makeLeaf(node, begin, end);
    std::uint32_t split;
    if (depth >= kSahDepthLimit) {
      Bounds cb;
      for (std::uint32_t i = begin; i < end; ++i) cb.grow(centroids[bvh.order_[i]]);
      split = medianSplit(begin, end, cb);
    } else {
      split = sahSplit(begin, end, b);
    }
    if (split == begin || split == end) return makeLeaf(node, begin, end);
    const auto left = static_cast<std::uint32_t>(bvh.nodes_.size());
    bvh.nodes_.emplace_back();
    build(left, begin, split, depth + 1);
    const auto right = static_cast<std::uint32_t>(bvh.nodes_.size());
    bvh.nodes_.emplace_back();
    bvh.nodes_[node].offset = right;
    bvh.nodes_[node].count = 0;
    build(right, split, end, depth + 1);
  }
};

MeshBvh MeshBvh::build(const TriangleMesh& mesh) {
  MeshBvh bvh;
  const auto n = static_cast<std::uint32_t>(mesh.faces.size());
  Builder builder{mesh, bvh, {}, {}};
  builder.tri_bounds.resize(n);
  builder.centroids.resize(n);
  bvh.order_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const Eigen::Vector3i& f = mesh.faces[i];
    Bounds b;
    for (int k = 0; k < 3; ++k) b.grow(mesh.vertices[f[k]]);
    builder.tri_bounds[i] = b;
    builder.centroids[i] = 0.5 * (b.lo + b.hi);
    bvh.order_[i] = i;
  }
  bvh.nodes_.reserve(n > 0 ? 2 * n : 1);
  bvh.nodes_.emplace_back();
  builder.build(0, 0, n, 0);
  return bvh;
}

namespace {

// Conservative slab test; returns the entry distance or +inf on a miss.
double enterBox(const Vec3& lo, const Vec3& hi, const Vec3& o, const Vec3& inv, double t_min,
                double t_max) {
  double t_near = t_min, t_far = t_max;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(inv[i])) {  // zero (or subnormal) component: parallel to the slab
      if (o[i] < lo[i] || o[i] > hi[i]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double t0 = (lo[i] - o[i]) * inv[i];
    double t1 = (hi[i] - o[i]) * inv[i];
    if (t0 > t1) std::swap(t0, t1);
    t1 *= 1 + 2 * kGamma3;
    t0 *= t0 > 0 ? 1 - 2 * kGamma3 : 1 + 2 * kGamma3;
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
    if (t_near > t_far) return std::numeric_limits<double>::infinity();
  }
  return t_near;
}

}  // namespace

std::optional<Hit> MeshBvh::intersect(const TriangleMesh& mesh, const Ray& ray,
                                      RayRange range) const {
  if (nodes_.empty() || order_.empty()) return std::nullopt;
  const Vec3& o = ray.origin;
  const Vec3& d = ray.dir;
  const Vec3 inv(1.0 / d.x(), 1.0 / d.y(), 1.0 / d.z());  // inf for zero components
  std::optional<Hit> best;
  struct Entry {
    std::uint32_t node;
    double t_enter;
  };
  constexpr double kMiss = std::numeric_limits<double>::infinity();
  std::array<Entry, kStackSize> stack;
  std::size_t top = 0;
  const double t_root = enterBox(nodes_[0].lo, nodes_[0].hi, o, inv, range.t_min, range.t_max);
  if (t_root == kMiss) return std::nullopt;
  stack[top++] = {0, t_root};
  while (top > 0) {
    const Entry entry = stack[--top];
    if (entry.t_enter > range.t_max) continue;  // a nearer hit was found meanwhile
    const Node& node = nodes_[entry.node];
    if (node.count > 0) {
      for (std::uint32_t i = node.offset; i < node.offset + node.count; ++i) {
        const std::uint32_t tri = order_[i];
        const Eigen::Vector3i& f = mesh.faces[tri];
        if (auto hit = intersectTriangle(ray, mesh.vertices[f[0]], mesh.vertices[f[1]],
                                         mesh.vertices[f[2]], range)) {
          hit->primitive = tri;
          range.t_max = hit->t;
          best = hit;
        }
      }
      continue;
    }
    const std::uint32_t left = entry.node + 1;
    const std::uint32_t right = node.offset;
    const double tl = enterBox(nodes_[left].lo, nodes_[left].hi, o, inv, range.t_min, range.t_max);
    const double tr =
        enterBox(nodes_[right].lo, nodes_[right].hi, o, inv, range.t_min, range.t_max);
    // Push the far child first so the near one is visited first and shrinks t_max.
    const Entry near = tl <= tr ? Entry{left, tl} : Entry{right, tr};
    const Entry far = tl <= tr ? Entry{right, tr} : Entry{left, tl};
    if (far.t_enter != kMiss) stack[top++] = far;
    if (near.t_enter != kMiss) stack[top++] = near;
  }
  return best;
}

}  // namespace procam::geom
