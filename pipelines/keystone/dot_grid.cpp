#include "keystone/dot_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

namespace procam::keystone {

namespace {

constexpr int kWindowRadius = 3;  // 7 x 7 moments window
// The weighted centroid: a 9 x 9 window (its border gives the background) and a weight
// about as wide as a dot in the camera.
constexpr int kWeightRadius = 4;
constexpr double kWeightSigma = 1.5;

// The median of `v` (reordered).
double median(std::vector<float>& v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The median of the border of the window of radius r about (x0, y0), inside `grey`:
// the background under a dot.
double borderMedian(const cv::Mat& grey, int x0, int y0, int r) {
  std::vector<float> border;
  border.reserve(static_cast<std::size_t>(8 * r + 4));
  for (int k = -r; k <= r; ++k) {
    border.push_back(grey.at<float>(y0 - r, x0 + k));
    border.push_back(grey.at<float>(y0 + r, x0 + k));
    border.push_back(grey.at<float>(y0 + k, x0 - r));
    border.push_back(grey.at<float>(y0 + k, x0 + r));
  }
  return median(border);
}

// The Gaussian-weighted centroid from `c` (iterated: for a symmetric spot its fixed
// point is the spot's centre, whatever the weight's width): the plain moments over a
// window weigh the noise of its outer pixels by their distance and cut the spot's tails
// unevenly with the pixel phase; at the 6 cm baseline of a handheld projector's camera a
// few thousandths of a pixel that change across the image turn the fitted wall by a
// milliradian.
std::optional<Vec2> weightedCentre(const cv::Mat& grey, Vec2 c) {
  constexpr int r = kWeightRadius;
  constexpr double kInv2S2 = 1.0 / (2 * kWeightSigma * kWeightSigma);
  const int x0 = static_cast<int>(std::lround(c.x())), y0 = static_cast<int>(std::lround(c.y()));
  if (x0 - r < 0 || y0 - r < 0 || x0 + r >= grey.cols || y0 + r >= grey.rows) return std::nullopt;
  const double bg = borderMedian(grey, x0, y0, r);
  for (int iteration = 0; iteration < 20; ++iteration) {
    double sw = 0, sx = 0, sy = 0;
    for (int y = y0 - r + 1; y < y0 + r; ++y) {
      const float* row = grey.ptr<float>(y);
      for (int x = x0 - r + 1; x < x0 + r; ++x) {
        const double dx = x - c.x(), dy = y - c.y();
        const double w = (row[x] - bg) * std::exp(-(dx * dx + dy * dy) * kInv2S2);
        sw += w, sx += w * x, sy += w * y;
      }
    }
    if (!(sw > 0)) return std::nullopt;
    const Vec2 next(sx / sw, sy / sw);
    if ((next - Vec2(x0, y0)).cwiseAbs().maxCoeff() > 1.5) return std::nullopt;  // ran off
    const bool done = (next - c).norm() < 1e-5;
    c = next;
    if (done) break;
  }
  return c;
}

// Refines a blob's seed by intensity moments (see detectDots); nullopt when the window
// leaves the image or holds no light above its border.
std::optional<Vec2> refineCentre(const cv::Mat& grey, Vec2 c) {
  constexpr int r = kWindowRadius;
  for (int iteration = 0; iteration < 3; ++iteration) {
    const int x0 = static_cast<int>(std::lround(c.x())), y0 = static_cast<int>(std::lround(c.y()));
    if (x0 - r < 0 || y0 - r < 0 || x0 + r >= grey.cols || y0 + r >= grey.rows) return std::nullopt;
    const double bg = borderMedian(grey, x0, y0, r);
    double sw = 0, sx = 0, sy = 0;
    for (int y = y0 - r; y <= y0 + r; ++y) {
      const float* row = grey.ptr<float>(y);
      for (int x = x0 - r; x <= x0 + r; ++x) {
        const double w = row[x] - bg;
        sw += w, sx += w * x, sy += w * y;
      }
    }
    if (!(sw > 0)) return std::nullopt;
    c = Vec2(sx / sw, sy / sw);
  }
  return weightedCentre(grey, c);
}

}  // namespace

Result<DotGrid> makeDotGrid(int width, int height) {
  if (width < 64 || height < 64 || width > 16384 || height > 16384) {
    return fail(ErrorCode::kInvalidInput,
                "a dot grid needs a framebuffer of 64 to 16384 px a side");
  }
  const double scale = width / 1920.0;
  const int spacing = std::max(8, static_cast<int>(std::lround(45 * scale)));
  DotGrid d;
  d.sigma_px = std::max(1.0, 3 * scale);
  const int reach = static_cast<int>(std::ceil(4 * d.sigma_px));
  const int inset_x = static_cast<int>(std::lround(105 * scale));
  const int inset_y = static_cast<int>(std::lround(90 * scale));
  const int columns = (width - 2 * inset_x) / spacing + 1;
  const int rows = (height - 2 * inset_y) / spacing + 1;
  if (columns < 4 || rows < 4) {
    return fail(ErrorCode::kInvalidInput, "the framebuffer is too narrow for a dot grid");
  }
  const int x0 = (width - (columns - 1) * spacing) / 2;
  const int y0 = (height - (rows - 1) * spacing) / 2;
  d.image = cv::Mat::zeros(height, width, CV_8UC1);
  const double k = -1.0 / (2 * d.sigma_px * d.sigma_px);
  for (int gy = 0; gy < rows; ++gy) {
    for (int gx = 0; gx < columns; ++gx) {
      const int cx = x0 + spacing * gx, cy = y0 + spacing * gy;
      d.centres.emplace_back(cx, cy);
      for (int y = std::max(0, cy - reach); y <= std::min(height - 1, cy + reach); ++y) {
        for (int x = std::max(0, cx - reach); x <= std::min(width - 1, cx + reach); ++x) {
          const double r2 = double((x - cx) * (x - cx) + (y - cy) * (y - cy));
          d.image.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(255 * std::exp(k * r2));
        }
      }
    }
  }
  return d;
}

std::vector<Vec2> detectDots(const cv::Mat& grey, const DotDetectOptions& options) {
  std::vector<Vec2> dots;
  if (grey.empty() || grey.type() != CV_32FC1) return dots;
  cv::Mat continuous = grey.isContinuous() ? grey : grey.clone();
  std::vector<float> all(continuous.begin<float>(), continuous.end<float>());
  const double background = median(all);  // dots cover a few % of the image
  for (float& v : all) v = std::abs(v - static_cast<float>(background));
  const double sigma = 1.4826 * median(all);  // the MAD of a normal distribution
  const cv::Mat mask = grey > background + std::max(options.noise_sigmas * sigma,
                                                    options.min_rise * options.full_scale);
  cv::Mat labels, stats, seeds;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, seeds, 8);
  dots.reserve(static_cast<std::size_t>(n));
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) < 3) continue;  // a noise speck
    if (auto c = refineCentre(grey, Vec2(seeds.at<double>(i, 0), seeds.at<double>(i, 1)))) {
      dots.push_back(*c);
    }
  }
  return dots;
}

DotMatches matchDots(const std::vector<Vec2>& centres, const std::vector<Vec2>& detected,
                     const geom::Intrinsics& projector,
                     const geom::CameraModel& camera_in_projector, const Vec3& m, double gate) {
  DotMatches out;
  const Mat3 Kp_inv = projector.matrix().inverse();
  // Detected dots bucketed by camera pixel cells of the gate's size: a prediction looks
  // in its cell and the eight around it.
  const double cell = std::max(1.0, gate);
  const int cols = static_cast<int>(camera_in_projector.width / cell) + 1;
  const int rows = static_cast<int>(camera_in_projector.height / cell) + 1;
  std::vector<std::vector<int>> buckets(static_cast<std::size_t>(cols) * rows);
  auto cellOf = [&](const Vec2& q, int& cx, int& cy) {
    cx = static_cast<int>(std::floor(q.x() / cell));
    cy = static_cast<int>(std::floor(q.y() / cell));
    return cx >= 0 && cy >= 0 && cx < cols && cy < rows;
  };
  for (std::size_t i = 0; i < detected.size(); ++i) {
    int cx, cy;
    if (cellOf(detected[i], cx, cy)) {
      buckets[static_cast<std::size_t>(cy) * cols + cx].push_back(static_cast<int>(i));
    }
  }
  for (const Vec2& p : centres) {
    const Vec3 ray = Kp_inv * p.homogeneous();
    const double s = m.dot(ray);
    if (!(s > 0)) continue;
    const auto q = camera_in_projector.project(ray / s);
    if (!q || !(q->x() > -gate && q->y() > -gate && q->x() < camera_in_projector.width + gate &&
                q->y() < camera_in_projector.height + gate)) {
      continue;
    }
    int cx, cy;
    cellOf(*q, cx, cy);
    const Vec2* best = nullptr;
    double best_d = gate;
    for (int y = cy - 1; y <= cy + 1; ++y) {
      for (int x = cx - 1; x <= cx + 1; ++x) {
        if (x < 0 || y < 0 || x >= cols || y >= rows) continue;
        for (int i : buckets[static_cast<std::size_t>(y) * cols + x]) {
          const double d = (detected[static_cast<std::size_t>(i)] - *q).norm();
          if (d <= best_d) best_d = d, best = &detected[static_cast<std::size_t>(i)];
        }
      }
    }
    if (!best) continue;
    auto ideal = camera_in_projector.undistortPixel(*best);
    if (!ideal) continue;
    out.projector.push_back(p);
    out.camera.push_back(*ideal);
  }
  return out;
}

namespace {

// Camera residual (pixels) of pair i under the plane m.X = 1 (projector frame).
double residual(const Vec3& m, const Mat3& Kp_inv, const Mat3& Kc, const geom::Pose& pose,
                const Vec2& xp, const Vec2& xc) {
  const Vec3 ray = Kp_inv * xp.homogeneous();
  const double s = m.dot(ray);
  if (!(s > 0)) return INFINITY;
  const Vec3 c = Kc * (pose.R * (ray / s) + pose.t);
  if (!(c.z() > 0)) return INFINITY;
  return (c.hnormalized() - xc).norm();
}

DotMatches inliers(const DotMatches& pairs, const Vec3& m, const Mat3& Kp_inv, const Mat3& Kc,
                   const geom::Pose& pose, double limit) {
  DotMatches out;
  for (std::size_t i = 0; i < pairs.projector.size(); ++i) {
    if (residual(m, Kp_inv, Kc, pose, pairs.projector[i], pairs.camera[i]) > limit) continue;
    out.projector.push_back(pairs.projector[i]);
    out.camera.push_back(pairs.camera[i]);
  }
  return out;
}

}  // namespace

Result<WallFromDots> wallFromDots(const DotGrid& grid, const cv::Mat& grey,
                                  const geom::Intrinsics& projector,
                                  const geom::CameraModel& camera_in_projector,
                                  const WallFromDotsOptions& options) {
  if (!(options.nominal_distance > 0) || !(options.gate > 0) || !(options.first_gate > 0)) {
    return fail(ErrorCode::kInvalidInput, "wall from dots: distances and gates must be positive");
  }
  if (grey.empty() || grey.type() != CV_32FC1) {
    return fail(ErrorCode::kInvalidInput, "wall from dots: the camera image must be CV_32FC1");
  }
  WallFromDots out;
  out.shown = grid.centres.size();
  const std::vector<Vec2> dots = detectDots(grey, options.detect);
  out.detected = dots.size();
  const geom::Pose& pose = camera_in_projector.pose;
  const Mat3 Kp_inv = projector.matrix().inverse(), Kc = camera_in_projector.K.matrix();
  auto tooFew = [&](std::size_t n, const char* what) {
    return fail(ErrorCode::kTooFewPoints,
                "the camera " + std::string(what) + " " + std::to_string(n) + " of " +
                    std::to_string(out.shown) + " dots (" + std::to_string(out.detected) +
                    " found); at least " + std::to_string(options.min_matches) + " are needed");
  };
  auto fit = [&](const DotMatches& pairs) {
    return wallFromCorrespondences(projector, camera_in_projector.K, pose, pairs.projector,
                                   pairs.camera);
  };
  // Identified at the nominal distance; the pairs may hold dots on another surface (a
  // floor) and dots identified wrongly where the wall is far from that distance, so the
  // first plane is the one most pairs agree with: RANSAC over three-pair samples.
  const DotMatches first =
      matchDots(grid.centres, dots, projector, camera_in_projector,
                Vec3(0, 0, 1.0 / options.nominal_distance), options.first_gate);
  if (first.projector.size() < options.min_matches)
    return tooFew(first.projector.size(), "identified");
  // A floor meeting the wall is off its plane by only a few pixels at this baseline (6 cm,
  // 560 px: 34 px of disparity per 1/m), so the bound is a few times the centroid noise
  // of a dot in a mean of frames (0.02-0.1 px), not a matching gate.
  constexpr double kInlierPx = 0.5;
  constexpr int kSamples = 64;  // 25 % outliers: all three inliers in 42 % of samples
  std::uint64_t state = 0x9e3779b97f4a7c15ull;  // fixed: the same image gives the same wall
  auto next = [&](std::size_t n) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<std::size_t>((state >> 33) % n);
  };
  std::optional<Vec3> best;
  std::size_t best_count = 0;
  const std::size_t n = first.projector.size();
  for (int k = 0; k < kSamples; ++k) {
    DotMatches sample;
    for (std::size_t i : {next(n), next(n), next(n)}) {
      sample.projector.push_back(first.projector[i]);
      sample.camera.push_back(first.camera[i]);
    }
    auto plane = fit(sample);
    if (!plane) continue;  // a repeated or collinear sample
    const Vec3 m = plane->normal / plane->distance;
    const std::size_t count = inliers(first, m, Kp_inv, Kc, pose, kInlierPx).projector.size();
    if (count > best_count) best_count = count, best = m;
  }
  if (!best || best_count < options.min_matches) return tooFew(best_count, "agreed on a plane for");
  auto plane = fit(inliers(first, *best, Kp_inv, Kc, pose, kInlierPx));
  if (!plane) return tl::unexpected(plane.error());
  // Then identified again through the plane with the tight gate until the count settles;
  // pairs off the plane by over 3 x the fit's RMS are left out (the RMS shrinks as a
  // floor's dots go, so the rounds close in on the wall; 0.05 px at least, for images
  // without noise).
  constexpr double kTrimFloorPx = 0.05;
  std::size_t used = 0;
  for (int round = 0; round < 8; ++round) {
    const Vec3 m = plane->normal / plane->distance;
    const DotMatches pairs =
        matchDots(grid.centres, dots, projector, camera_in_projector, m, options.gate);
    // Judged by the plane of the pairs kept so far, not by a fit the others pulled.
    const DotMatches kept =
        inliers(pairs, m, Kp_inv, Kc, pose, std::max(kTrimFloorPx, 3 * plane->rms));
    if (kept.projector.size() < options.min_matches) {
      return tooFew(kept.projector.size(), "identified");
    }
    plane = fit(kept);
    if (!plane) return tl::unexpected(plane.error());
    const bool settled = kept.projector.size() == used;
    used = kept.projector.size();
    if (settled) break;
  }
  out.plane = *plane;
  out.matched = used;
  return out;
}

}  // namespace procam::keystone
