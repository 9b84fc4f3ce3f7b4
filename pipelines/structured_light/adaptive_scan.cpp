#include "structured_light/adaptive_scan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "geometry/homography.hpp"

namespace procam::sl {
namespace {

struct BlockSum {
  double x = 0, y = 0;
  int count = 0;
  bool touches_border = false;
};

// Calls f(x, y, block) for every camera pixel decoded without a flag; `block` is the
// row-major index of the coarse block its projector column and row fall in.
template <class F>
void forEachDecodedPixel(const PatternSet& coarse, const Decoded& d, F&& f) {
  const int bx = coarse.columns.cells, by = coarse.rows.cells;
  for (int y = 0; y < d.u.rows; ++y) {
    const float* u = d.u.ptr<float>(y);
    const float* v = d.v.ptr<float>(y);
    const std::uint8_t* flags = d.flags.ptr<std::uint8_t>(y);
    for (int x = 0; x < d.u.cols; ++x) {
      if (flags[x] != 0) continue;
      const int i = std::clamp(static_cast<int>(u[x]) / coarse.columns.cell, 0, bx - 1);
      const int j = std::clamp(static_cast<int>(v[x]) / coarse.rows.cell, 0, by - 1);
      f(x, y, static_cast<std::size_t>(j) * bx + i);
    }
  }
}

std::string format(const char* fmt, auto... args) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

}  // namespace

Result<PatternSet> coarsePatternSet(const AdaptiveOptions& o) {
  if (o.blocks_x < 2 || o.blocks_y < 2)
    return fail(ErrorCode::kInvalidInput, "the coarse pass needs at least 2x2 blocks");
  if (o.full.width < o.blocks_x || o.full.height < o.blocks_y)
    return fail(ErrorCode::kInvalidInput, "projector smaller than the coarse block grid");
  PatternOptions c;
  c.width = o.full.width;
  c.height = o.full.height;
  c.mode = Mode::kGray;
  c.step = (o.full.width + o.blocks_x - 1) / o.blocks_x;
  c.step_rows = (o.full.height + o.blocks_y - 1) / o.blocks_y;
  return makePatternSet(c);
}

Result<PlanarityTest> testPlanarity(const PatternSet& coarse, const Decoded& d,
                                    const AdaptiveOptions& o) {
  const int bx = coarse.columns.cells, by = coarse.rows.cells;
  std::vector<BlockSum> blocks(static_cast<std::size_t>(bx) * by);
  const int w = d.u.cols, h = d.u.rows;
  forEachDecodedPixel(coarse, d, [&](int x, int y, std::size_t block) {
    BlockSum& b = blocks[block];
    b.x += x;
    b.y += y;
    ++b.count;
    b.touches_border |= x == 0 || y == 0 || x == w - 1 || y == h - 1;
  });
  std::vector<int> counts;
  for (const BlockSum& b : blocks)
    if (b.count > 0 && !b.touches_border) counts.push_back(b.count);
  if (counts.size() < 8)
    return fail(
        ErrorCode::kTooFewPoints,
        format("coarse pass: only %zu whole projector blocks are visible (need 8)", counts.size()));
  std::nth_element(counts.begin(), counts.begin() + counts.size() / 2, counts.end());
  const int median = counts[counts.size() / 2];

  PlanarityTest t;
  for (int j = 0; j < by; ++j)
    for (int i = 0; i < bx; ++i) {
      const BlockSum& b = blocks[static_cast<std::size_t>(j) * bx + i];
      // A block seen only in part (shadow edge, occlusion, clipped projector edge
      // cell) has a centroid that is not the image of its centre.
      if (b.touches_border || b.count < 0.6 * median || b.count < 4) continue;
      Vec2 cam(b.x / b.count, b.y / b.count);
      if (o.undistort) cam = o.undistort(cam);
      const int x0 = i * coarse.columns.cell, y0 = j * coarse.rows.cell;
      const int cw = std::min(coarse.columns.cell, coarse.columns.extent - x0);
      const int ch = std::min(coarse.rows.cell, coarse.rows.extent - y0);
      t.camera.push_back(cam);
      t.projector.emplace_back(x0 + (cw - 1) * 0.5, y0 + (ch - 1) * 0.5);
    }
  if (t.camera.size() < 8)
    return fail(
        ErrorCode::kTooFewPoints,
        format("coarse pass: only %zu fully decoded projector blocks (need 8)", t.camera.size()));
  auto fit = geom::fitHomography(t.camera, t.projector);
  if (!fit) return tl::unexpected(fit.error());
  t.H = fit->H;
  t.rms_px = fit->rms;
  // A block's camera centroid is not the image of its centre: perspective (and lens
  // distortion) weight its pixels unevenly, a second-order bias that grows with the
  // block and the obliquity. Refine: map every undistorted pixel of a kept block
  // through H, weighted by the projector area it covers (|det J_H| ~ 1/w^3), so the
  // weighted mean is the block centre for the true H; the camera point is H^-1 of
  // that mean, and H is refitted to those points.
  std::vector<int> kept(blocks.size(), -1);
  std::vector<double> areas;  // projector pixels of each kept block
  for (int j = 0; j < by; ++j)
    for (int i = 0; i < bx; ++i) {
      const BlockSum& b = blocks[static_cast<std::size_t>(j) * bx + i];
      if (b.touches_border || b.count < 0.6 * median || b.count < 4) continue;
      kept[static_cast<std::size_t>(j) * bx + i] = static_cast<int>(areas.size());
      areas.push_back(static_cast<double>(std::min(
                          coarse.columns.cell, coarse.columns.extent - i * coarse.columns.cell)) *
                      std::min(coarse.rows.cell, coarse.rows.extent - j * coarse.rows.cell));
    }
  struct Pixel {
    Vec2 p;
    int block;
  };
  std::vector<Pixel> pixels;
  forEachDecodedPixel(coarse, d, [&](int x, int y, std::size_t block) {
    const int b = kept[block];
    if (b >= 0) pixels.push_back({o.undistort ? o.undistort(Vec2(x, y)) : Vec2(x, y), b});
  });
  // Blocks partly hidden (cut by the edge of the surface or an occluder) have
  // centres no weighting can recover: a block keeps its place in the fit only with
  // at least 90% of the camera pixels H predicts for it (its projector area over
  // |det J_H|).
  std::vector<int> seen(t.camera.size(), 0);
  for (const Pixel& px : pixels) ++seen[static_cast<std::size_t>(px.block)];
  const Points2 all_projector = t.projector;
  Points2 all_camera = t.camera;
  for (int round = 0; round < 3; ++round) {
    std::vector<Vec3> sums(all_camera.size(), Vec3::Zero());  // weighted x, y and weight
    for (const Pixel& px : pixels) {
      const Vec3 q = t.H * px.p.homogeneous();
      if (std::abs(q.z()) < 1e-12) continue;
      const double weight = 1.0 / std::abs(q.z() * q.z() * q.z());
      sums[static_cast<std::size_t>(px.block)] +=
          Vec3(weight * q.x() / q.z(), weight * q.y() / q.z(), weight);
    }
    const Mat3 Hinv = t.H.inverse();
    const double det = std::abs(t.H.determinant());
    Points2 camera, projector;
    for (std::size_t b = 0; b < sums.size(); ++b) {
      auto c = sums[b].z() > 0 ? geom::applyHomography(Hinv, sums[b].head<2>() / sums[b].z())
                               : std::optional<Vec2>();
      if (c) all_camera[b] = *c;
      const double w = std::abs((t.H * all_camera[b].homogeneous()).z());
      const double expected = areas[b] * w * w * w / std::max(det, 1e-300);
      if (seen[b] < 0.9 * expected) continue;
      camera.push_back(all_camera[b]);
      projector.push_back(all_projector[b]);
    }
    if (camera.size() < 8) break;
    auto refit = geom::fitHomography(camera, projector);
    if (!refit) break;
    t.camera = std::move(camera);
    t.projector = std::move(projector);
    t.H = refit->H;
    t.rms_px = refit->rms;
  }
  // The camera locates a block only to a fraction of its own pixel: the tolerance is
  // at least camera_tolerance_px camera pixels at the projector-per-camera-pixel
  // scale sqrt|det J_H| of the median block.
  std::vector<double> scales;
  const double det = std::abs(t.H.determinant());
  for (const Vec2& c : t.camera) {
    const double w = std::abs((t.H * c.homogeneous()).z());
    if (w > 0) scales.push_back(std::sqrt(det / (w * w * w)));
  }
  double scale = 0;
  if (!scales.empty()) {
    std::nth_element(scales.begin(), scales.begin() + scales.size() / 2, scales.end());
    scale = scales[scales.size() / 2];
  }
  t.tolerance_px = std::max(o.planar_tolerance * std::min(coarse.columns.cell, coarse.rows.cell),
                            o.camera_tolerance_px * scale);
  t.planar = t.rms_px <= t.tolerance_px;
  return t;
}

Result<AdaptiveResult> scanAdaptive(const AdaptiveOptions& o, const CaptureFn& capture) {
  auto full_set = makePatternSet(o.full);
  if (!full_set) return tl::unexpected(full_set.error());
  auto coarse = coarsePatternSet(o);
  if (!coarse) return tl::unexpected(coarse.error());
  auto coarse_captures = capture(*coarse);
  if (!coarse_captures) return tl::unexpected(coarse_captures.error());
  auto coarse_decoded = decode(*coarse, *coarse_captures, o.decode);
  if (!coarse_decoded) return tl::unexpected(coarse_decoded.error());
  auto test = testPlanarity(*coarse, *coarse_decoded, o);
  if (!test) return tl::unexpected(test.error());

  AdaptiveResult r;
  r.coarse = *test;
  r.planar = test->planar;
  const int coarse_frames = static_cast<int>(coarse->frames.size());
  if (r.planar) {
    r.frames_used = coarse_frames;
    r.reason = format(
        "planar: %zu coarse blocks fit one homography with %.3f px RMS (tolerance %.3f px); "
        "stopped after the %d-frame coarse pass",
        test->camera.size(), test->rms_px, test->tolerance_px, coarse_frames);
    return r;
  }
  auto full_captures = capture(*full_set);
  if (!full_captures) return tl::unexpected(full_captures.error());
  auto full_decoded = decode(*full_set, *full_captures, o.decode);
  if (!full_decoded) return tl::unexpected(full_decoded.error());
  r.full = std::move(*full_decoded);
  r.frames_used = coarse_frames + static_cast<int>(full_set->frames.size());
  r.reason = format(
      "non-planar: coarse homography RMS %.3f px exceeds %.3f px over %zu blocks; "
      "%d coarse + %zu full-resolution frames",
      test->rms_px, test->tolerance_px, test->camera.size(), coarse_frames,
      full_set->frames.size());
  return r;
}

}  // namespace procam::sl
