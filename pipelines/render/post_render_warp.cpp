#include "render/post_render_warp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace procam::render {
namespace {

bool goodGrid(cv::Size size, int step) {
  return size.width >= 2 && size.height >= 2 && size.width <= 16384 && size.height <= 16384 &&
         step >= 1;
}

// Nodes without a value take their nearest valued node's (OpenCV's distance transform
// labels each node with its nearest valued one): the warp stays smooth past the measured
// region's edge. False when no node has a value.
bool fillFromNearest(WarpGrid& g, std::vector<Vec2>& shift) {
  cv::Mat unknown(g.rows, g.cols, CV_8UC1);
  for (std::size_t k = 0; k < shift.size(); ++k) unknown.data[k] = shift[k].allFinite() ? 0 : 255;
  if (cv::countNonZero(unknown) == static_cast<int>(shift.size())) return false;
  cv::Mat distance, labels;
  cv::distanceTransform(unknown, distance, labels, cv::DIST_L2, cv::DIST_MASK_5,
                        cv::DIST_LABEL_PIXEL);
  std::vector<std::size_t> node_of(shift.size() + 1);  // label -> its valued node
  const int* label = labels.ptr<int>();
  for (std::size_t k = 0; k < shift.size(); ++k) {
    if (!unknown.data[k]) node_of[static_cast<std::size_t>(label[k])] = k;
  }
  for (int j = 0; j < g.rows; ++j) {
    for (int i = 0; i < g.cols; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * g.cols + i;
      g.source[k] = g.node(i, j) + shift[node_of[static_cast<std::size_t>(label[k])]];
    }
  }
  return true;
}

}  // namespace

Result<PostRenderWarp> measuredPostRenderWarp(const geom::TriangleMesh& mesh, const Mat34& P,
                                              cv::Size size, int step) {
  if (!goodGrid(size, step) || !P.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "post-rendering warp: bad size, step or matrix");
  }
  if (mesh.uv.size() != mesh.vertices.size() || mesh.vertices.empty()) {
    return fail(ErrorCode::kInvalidInput,
                "post-rendering warp: the mesh has no projector pixel for its vertices");
  }
  // m'' - m per vertex (NaN behind the projector).
  const Vec2 none = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<Vec2> moved(mesh.vertices.size(), none);
  PostRenderWarp out;
  double sum = 0;
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
    const Vec3 h = P * mesh.vertices[k].homogeneous();
    if (!(h.z() > 0) || !mesh.uv[k].allFinite()) continue;
    moved[k] = h.hnormalized() - mesh.uv[k];
    if (!moved[k].allFinite()) {
      moved[k] = none;
      continue;
    }
    const double d = moved[k].norm();
    sum += d * d;
    out.max_px = std::max(out.max_px, d);
    ++out.points;
  }
  if (out.points > 0) out.rms_px = std::sqrt(sum / out.points);
  // A lens and a unified surface move a projector's pixels by a few; far more means the
  // vertices' u v are not this projector's pixels.
  if (out.rms_px > kMaxMeasuredShiftPx) {
    return fail(ErrorCode::kDegenerate,
                "post-rendering warp: the mesh's pixels lie " + std::to_string(out.rms_px) +
                    " px RMS from where the projector's matrix puts its vertices: not its "
                    "pixels");
  }

  // Every node inside a triangle (in projector space) takes the triangle's linear
  // interpolation of its corners' shifts.
  out.grid = framebufferGrid(size, step);
  WarpGrid& g = out.grid;
  std::vector<Vec2> shift(g.source.size(), none);
  const int n = static_cast<int>(mesh.vertices.size());
  for (const auto& f : mesh.faces) {
    if (f.minCoeff() < 0 || f.maxCoeff() >= n) {
      return fail(ErrorCode::kInvalidInput, "post-rendering warp: a face's vertex is out of range");
    }
    const Vec2 &a = mesh.uv[f[0]], &b = mesh.uv[f[1]], &c = mesh.uv[f[2]];
    const Vec2 &sa = moved[f[0]], &sb = moved[f[1]], &sc = moved[f[2]];
    if (!sa.allFinite() || !sb.allFinite() || !sc.allFinite()) continue;
    const double area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (!(std::abs(area) > 1e-9)) continue;
    const double lo_x = std::min({a.x(), b.x(), c.x()}), hi_x = std::max({a.x(), b.x(), c.x()});
    const double lo_y = std::min({a.y(), b.y(), c.y()}), hi_y = std::max({a.y(), b.y(), c.y()});
    // Node range, clamped in double before the cast (a pixel far off the frame).
    const auto first = [](double v, int count) {
      return std::max(0, static_cast<int>(std::clamp(std::ceil(v), -1.0, double(count))));
    };
    const auto last = [](double v, int count) {
      return std::min(count - 1, static_cast<int>(std::clamp(std::floor(v), -1.0, double(count))));
    };
    const int i0 = first(lo_x / g.step.x(), g.cols), i1 = last(hi_x / g.step.x(), g.cols);
    const int j0 = first(lo_y / g.step.y(), g.rows), j1 = last(hi_y / g.step.y(), g.rows);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const Vec2 p = g.node(i, j);
        const double wb = ((p - a).x() * (c - a).y() - (p - a).y() * (c - a).x()) / area;
        const double wc = ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x()) / area;
        const double wa = 1 - wb - wc;
        constexpr double kEdge = -1e-9;
        if (wa < kEdge || wb < kEdge || wc < kEdge) continue;
        shift[static_cast<std::size_t>(j) * g.cols + i] = wa * sa + wb * sb + wc * sc;
      }
    }
  }
  if (!fillFromNearest(g, shift)) {
    return fail(ErrorCode::kTooFewPoints,
                "post-rendering warp: no triangle of the mesh lies in front of the projector");
  }
  return out;
}

Result<PostRenderWarp> lensPostRenderWarp(const geom::CameraModel& projector, int step) {
  const cv::Size size(projector.width, projector.height);
  if (!goodGrid(size, step)) {
    return fail(ErrorCode::kInvalidInput, "post-rendering warp: bad size or step");
  }
  PostRenderWarp out;
  out.source = PostRenderWarp::Source::kLens;
  out.grid = framebufferGrid(size, step);
  WarpGrid& g = out.grid;
  const Vec2 none = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<Vec2> shift(g.source.size(), none);
  double sum = 0;
  int nodes = 0;
  for (int j = 0; j < g.rows; ++j) {
    for (int i = 0; i < g.cols; ++i) {
      const Vec2 m = g.node(i, j);
      const auto ideal = projector.undistortPixel(m);
      if (!ideal || !ideal->allFinite()) continue;
      const Vec2 d = *ideal - m;
      shift[static_cast<std::size_t>(j) * g.cols + i] = d;
      sum += d.squaredNorm();
      out.max_px = std::max(out.max_px, d.norm());
      ++nodes;
    }
  }
  if (!fillFromNearest(g, shift)) {
    return fail(ErrorCode::kInvalidInput, "post-rendering warp: the lens model inverts nowhere");
  }
  out.rms_px = std::sqrt(sum / nodes);
  return out;
}

Result<std::shared_ptr<const PostRenderWarp>> projectorPostRenderWarp(
    const geom::CameraModel& projector, const geom::TriangleMesh* own_mesh, int step) {
  const auto shared =
      [](Result<PostRenderWarp> w) -> Result<std::shared_ptr<const PostRenderWarp>> {
    if (!w) return tl::unexpected(w.error());
    return std::make_shared<const PostRenderWarp>(std::move(*w));
  };
  if (own_mesh && !own_mesh->uv.empty()) {
    return shared(measuredPostRenderWarp(*own_mesh, projector.projectionMatrix(),
                                         cv::Size(projector.width, projector.height), step));
  }
  if (!projector.dist.isZero()) return shared(lensPostRenderWarp(projector, step));
  return std::shared_ptr<const PostRenderWarp>();
}

}  // namespace procam::render
