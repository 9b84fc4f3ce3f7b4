#include "misregistration.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "geometry/homography.hpp"

namespace procam::drift {
namespace {

// A tile's shift in two steps: phase correlation (whole pixels and a coarse fraction,
// from `start`), then Lucas-Kanade on translation with a gain and offset (the camera's
// response, the wall's albedo and the ambient light differ from the frame's code
// values): seen(q + d) = a shown(q) + b, solved by Gauss-Newton. Phase correlation's
// peak interpolation alone scatters by a quarter pixel on the camera's blurred,
// noisy view; the least-squares fit reaches the noise floor.
struct TileFit {
  Vec2 shift = Vec2::Zero();  // seen(q) = shown(q - shift), work pixels
  double response = 0;
  bool converged = false;
};

TileFit registerTile(const cv::Mat& shown_roi, const cv::Mat& seen, const cv::Point2f& centre,
                     const cv::Mat& window, const Vec2& start) {
  TileFit fit;
  const cv::Mat shown_tile = shown_roi.clone();  // continuous: read as one array below
  cv::Mat seen_tile;
  const auto at = [&](const Vec2& d) {
    cv::getRectSubPix(seen, shown_tile.size(),
                      centre + cv::Point2f(static_cast<float>(d.x()), static_cast<float>(d.y())),
                      seen_tile, CV_32F);
  };
  at(start);
  double response = 0;
  // phaseCorrelate applies the window in place (OpenCV 4.6): it gets copies.
  const cv::Point2d coarse =
      cv::phaseCorrelate(shown_roi.clone(), seen_tile.clone(), window, &response);
  if (!std::isfinite(coarse.x) || !std::isfinite(coarse.y)) return fit;
  fit.response = response;
  Vec2 d = start + Vec2(coarse.x, coarse.y);
  const int n = shown_tile.rows * shown_tile.cols;
  for (int iter = 0; iter < 8; ++iter) {
    at(d);
    cv::Mat gx, gy;
    cv::Sobel(seen_tile, gx, CV_32F, 1, 0, 3, 1.0 / 8);
    cv::Sobel(seen_tile, gy, CV_32F, 0, 1, 3, 1.0 / 8);
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    Eigen::Vector4d b = Eigen::Vector4d::Zero();
    const float* s = shown_tile.ptr<float>(0);
    const float* c = seen_tile.ptr<float>(0);
    const float* px = gx.ptr<float>(0);
    const float* py = gy.ptr<float>(0);
    const float* w = window.ptr<float>(0);
    // The border rows and columns have one-sided gradients: left out.
    const int cols = shown_tile.cols;
    for (int i = 0; i < n; ++i) {
      const int x = i % cols, y = i / cols;
      if (x == 0 || y == 0 || x == cols - 1 || y == shown_tile.rows - 1) continue;
      const Eigen::Vector4d j(px[i], py[i], -s[i], -1.0);
      A += w[i] * j * j.transpose();
      b -= w[i] * j * c[i];
    }
    const Eigen::Vector4d step = A.ldlt().solve(b);
    if (!step.allFinite()) return fit;
    d += step.head<2>();
    if (step.head<2>().norm() < 1e-3) {
      fit.converged = true;
      break;
    }
  }
  fit.shift = d;
  return fit;
}

// The smaller eigenvalue of the tile's windowed structure tensor (sums of gx^2, gx gy,
// gy^2) over the larger, 0 for a tile with no gradient ([ShiTomasi94]).
double isotropy(const cv::Mat& tile, const cv::Mat& window) {
  cv::Mat gx, gy;
  cv::Sobel(tile, gx, CV_32F, 1, 0, 3);
  cv::Sobel(tile, gy, CV_32F, 0, 1, 3);
  double sxx = 0, sxy = 0, syy = 0;
  for (int y = 1; y + 1 < tile.rows; ++y) {
    const float* px = gx.ptr<float>(y);
    const float* py = gy.ptr<float>(y);
    const float* w = window.ptr<float>(y);
    for (int x = 1; x + 1 < tile.cols; ++x) {
      sxx += w[x] * px[x] * px[x];
      sxy += w[x] * px[x] * py[x];
      syy += w[x] * py[x] * py[x];
    }
  }
  const double half = (sxx + syy) / 2;
  const double disc = std::sqrt(std::max(0.0, half * half - (sxx * syy - sxy * sxy)));
  return half + disc > 0 ? (half - disc) / (half + disc) : 0.0;
}

// The shift of the whole view, at a quarter of the work grid (a bumped projector moves
// its content tens of pixels; the tiles then search around it).
Vec2 globalShift(const cv::Mat& shown, const cv::Mat& seen, const cv::Mat& seen_mask) {
  const cv::Scalar fill = cv::mean(seen, seen_mask);
  cv::Mat filled = seen.clone();
  filled.setTo(fill, ~seen_mask);
  cv::Mat a, b, window;
  const cv::Size quarter(std::max(8, shown.cols / 4), std::max(8, shown.rows / 4));
  cv::resize(shown, a, quarter, 0, 0, cv::INTER_AREA);
  cv::resize(filled, b, quarter, 0, 0, cv::INTER_AREA);
  cv::createHanningWindow(window, quarter, CV_32F);
  double response = 0;
  const cv::Point2d d = cv::phaseCorrelate(a, b, window, &response);
  if (!std::isfinite(d.x) || !std::isfinite(d.y)) return Vec2::Zero();
  return {d.x * shown.cols / quarter.width, d.y * shown.rows / quarter.height};
}

}  // namespace

void fitShiftField(std::vector<TileShift> tiles, const MisregistrationOptions& options,
                   Misregistration& m) {
  if (tiles.size() >= 4) {
    std::vector<cv::Point2f> from, to;
    for (const TileShift& t : tiles) {
      from.emplace_back(static_cast<float>(t.drawn.x()), static_cast<float>(t.drawn.y()));
      to.emplace_back(static_cast<float>(t.seen_at.x()), static_cast<float>(t.seen_at.y()));
    }
    std::vector<unsigned char> inliers;
    const cv::Mat H = cv::findHomography(from, to, cv::RANSAC, options.ransac_px, inliers);
    // No consensus: no tile is trusted (the check then reports too little to tell).
    for (std::size_t i = 0; i < tiles.size(); ++i) {
      tiles[i].inlier = !H.empty() && i < inliers.size() && inliers[i] != 0;
    }
  }
  // The misregistration is the collineation's over the inlier tiles: each tile's own
  // shift scatters by about 0.2 px on a camera with 1 DN of noise, their fit by a
  // tenth of that.
  std::vector<Vec2> drawn, seen_at;
  double response = 0;
  for (const TileShift& t : tiles) {
    if (!t.inlier) continue;
    drawn.push_back(t.drawn);
    seen_at.push_back(t.seen_at);
    response += std::min(1.0, t.response);  // the peak's sum can pass 1 by rounding
  }
  m.tiles_used = static_cast<int>(drawn.size());
  if (m.tiles_used < options.min_tiles) m.too_plain = true;
  auto field = m.tiles_used >= 4 ? geom::fitHomography(drawn, seen_at)
                                 : Result<geom::HomographyFit>(fail(ErrorCode::kTooFewPoints, ""));
  if (!field || !field->H.allFinite()) {
    m.too_plain = true;
  } else {
    m.drawn_to_seen = field->H / field->H(2, 2);
    m.tile_rms_px = field->rms;
    double sum_sq = 0;
    for (const Vec2& p : drawn) {
      const Vec3 q = m.drawn_to_seen * Vec3(p.x(), p.y(), 1.0);
      const double len = (q.head<2>() / q.z() - p).norm();
      sum_sq += len * len;
      m.max_px = std::max(m.max_px, len);
    }
    const double n = static_cast<double>(drawn.size());
    m.rms_px = std::sqrt(sum_sq / n);
    m.confidence = (n / std::max(1, m.tiles_textured)) * (response / n);
  }
  m.tiles = std::move(tiles);
}

Result<Misregistration> measureMisregistration(const cv::Mat& frame_light, const cv::Mat& camera,
                                               const cv::Mat& map, const WorkGrid& grid,
                                               const MisregistrationOptions& options,
                                               const cv::Mat& usable) {
  const cv::Size size = grid.size();
  if (frame_light.type() != CV_32F || frame_light.size() != size || map.type() != CV_32FC2 ||
      map.size() != size || camera.type() != CV_32F || camera.empty()) {
    return fail(ErrorCode::kInvalidInput,
                "drift check: the shown frame and the map must be CV_32F / CV_32FC2 of the work "
                "grid's size, the camera frame CV_32F");
  }
  if (!usable.empty() && (usable.type() != CV_8U || usable.size() != size)) {
    return fail(ErrorCode::kInvalidInput, "drift check: the usable mask must be CV_8U of the grid");
  }
  if (options.tile < 16 || options.tile > 512) {
    return fail(ErrorCode::kInvalidInput, "drift check: tiles of 16 to 512 pixels");
  }
  if (!(options.min_isotropy >= 0 && options.min_isotropy <= 1)) {
    return fail(ErrorCode::kInvalidInput, "drift check: min_isotropy outside [0, 1]");
  }
  if (!(options.reference_blur_px >= 0 && options.reference_blur_px <= kMaxReferenceBlurPx)) {
    return fail(ErrorCode::kInvalidInput, "drift check: reference blur outside [0, 8] work pixels");
  }
  // What the camera should see: the frame's light through the blur it is seen with.
  cv::Mat blurred;
  if (options.reference_blur_px > 0) {
    cv::GaussianBlur(frame_light, blurred, cv::Size(), options.reference_blur_px,
                     options.reference_blur_px, cv::BORDER_REPLICATE);
  }
  const cv::Mat& shown = blurred.empty() ? frame_light : blurred;
  // The camera's view on the framebuffer grid; -1 where the camera does not see it.
  cv::Mat seen;
  cv::remap(camera, seen, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(-1));
  cv::Mat seen_mask;
  cv::extractChannel(map, seen_mask, 0);
  seen_mask = seen_mask >= 0;
  cv::Mat seen_count;
  cv::integral(seen_mask / 255, seen_count, CV_32S);

  // Pixels of `r` the camera sees (r clipped to the grid first).
  const auto seenIn = [&](cv::Rect r) {
    const cv::Rect clipped = r & cv::Rect(0, 0, size.width, size.height);
    if (clipped.area() < r.area()) return false;
    const int n = seen_count.at<int>(clipped.br()) - seen_count.at<int>(clipped.y, clipped.br().x) -
                  seen_count.at<int>(clipped.br().y, clipped.x) +
                  seen_count.at<int>(clipped.y, clipped.x);
    return n == r.area();
  };
  const Vec2 global = globalShift(shown, seen, seen_mask);

  const int T = options.tile;
  const int margin = T / 4;  // how far a tile's shift may differ from the global one
  cv::Mat window;
  cv::createHanningWindow(window, cv::Size(T, T), CV_32F);
  Misregistration m;
  std::vector<TileShift> tiles;
  for (int y0 = 0; y0 + T <= size.height; y0 += T) {
    for (int x0 = 0; x0 + T <= size.width; x0 += T) {
      const cv::Point2f centre(x0 + (T - 1) / 2.0f, y0 + (T - 1) / 2.0f);
      const auto around = [&](const Vec2& d, int pad) {
        return cv::Rect(static_cast<int>(std::floor(x0 + d.x())) - pad,
                        static_cast<int>(std::floor(y0 + d.y())) - pad, T + 1 + 2 * pad,
                        T + 1 + 2 * pad);
      };
      if (!seenIn(around(global, margin))) continue;  // partly outside the camera's view
      if (!usable.empty() && cv::countNonZero(usable(cv::Rect(x0, y0, T, T))) < T * T) continue;
      ++m.tiles_seen;
      const cv::Mat shown_tile = shown(cv::Rect(x0, y0, T, T));
      cv::Scalar mean, sd;
      cv::meanStdDev(shown_tile, mean, sd);
      if (sd[0] < options.min_texture || isotropy(shown_tile, window) < options.min_isotropy) {
        continue;
      }
      ++m.tiles_textured;
      const TileFit fit = registerTile(shown_tile, seen, centre, window, global);
      if (!fit.converged || fit.response < options.min_response ||
          (fit.shift - global).cwiseAbs().maxCoeff() > margin || !seenIn(around(fit.shift, 1))) {
        continue;
      }
      const Vec2 c(centre.x, centre.y);
      TileShift t;
      t.drawn = grid.toFramebuffer(c);
      t.seen_at = grid.toFramebuffer(c + fit.shift);
      t.response = fit.response;
      tiles.push_back(t);
    }
  }
  m.too_plain = m.tiles_textured < options.min_textured_share * m.tiles_seen;
  fitShiftField(std::move(tiles), options, m);
  return m;
}

}  // namespace procam::drift
