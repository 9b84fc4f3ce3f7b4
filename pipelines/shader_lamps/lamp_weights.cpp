#include "shader_lamps/lamp_weights.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "core/units.hpp"

namespace procam::lamps {

namespace {

Vec3 toVec(const cv::Vec3f& v) {
  return {v[0], v[1], v[2]};
}

// The dark margin inside a silhouette and around a depth discontinuity, in this
// projector's pixels: the option's, plus the object's position error at its nearest.
int marginPx(const LampView& v, const geom::CameraModel& m, const LampWeightOptions& o) {
  if (!(o.position_error_m > 0)) return o.silhouette_margin_px;
  double nearest = 0;
  cv::Mat hit_distance = v.distance.clone();
  hit_distance.setTo(std::numeric_limits<float>::max(), v.face < 0);
  cv::minMaxLoc(hit_distance, &nearest);
  if (!(nearest > 0) || nearest == std::numeric_limits<float>::max()) return o.silhouette_margin_px;
  const double px = o.position_error_m * std::max(m.K.fx, m.K.fy) / nearest;
  return o.silhouette_margin_px + static_cast<int>(std::min(std::ceil(px), 32.0));
}

// Pixels that light the object: a hit, not grazing, not within the margin of a miss.
cv::Mat usablePixels(const LampView& v, const LampWeightOptions& o, int margin) {
  const float min_cos = static_cast<float>(std::cos(degToRad(o.max_incidence_deg)));
  cv::Mat hit = v.face >= 0;  // 255 / 0
  cv::Mat usable = hit & (v.cosine >= min_cos);
  if (margin > 0) {
    const int k = 2 * margin + 1;
    cv::Mat inner;
    cv::erode(hit, inner, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)),
              cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(255));
    usable &= inner;
  }
  return usable;
}

// Pixels next to a neighbour deeper or shallower than a surface at `deg` allows: where
// a nearer part of the object hides a farther one ([Raskar02] §5.2.5, edges of the
// depth buffer).
cv::Mat depthEdges(const LampView& v, double f, double deg) {
  cv::Mat edges(v.size, CV_8UC1, cv::Scalar(0));
  const double slope = std::tan(degToRad(deg)) / f;  // depth step per pixel, per metre
  constexpr double kFloorM = 0.001;
  for (int y = 0; y < v.size.height; ++y) {
    for (int x = 0; x < v.size.width; ++x) {
      if (!v.hit(x, y)) continue;
      const double d = v.distance.at<float>(y, x);
      const double limit = kFloorM + slope * d;
      const auto steps = [&](int nx, int ny) {
        return v.hit(nx, ny) && std::abs(v.distance.at<float>(ny, nx) - d) > limit;
      };
      if ((x + 1 < v.size.width && steps(x + 1, y)) || (y + 1 < v.size.height && steps(x, y + 1)) ||
          (x > 0 && steps(x - 1, y)) || (y > 0 && steps(x, y - 1)))
        edges.at<std::uint8_t>(y, x) = 255;
    }
  }
  return edges;
}

// Distance of every usable pixel to the nearest pixel that is not, or to the frame's
// edge (a zero border around the frame).
cv::Mat edgeDistance(const cv::Mat& inside) {
  cv::Mat padded, dist;
  cv::copyMakeBorder(inside, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::distanceTransform(padded, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return dist(cv::Rect(1, 1, inside.cols, inside.rows)).clone();
}

// Where projector `lamp` sees `point` on the side `normal` faces: the point's pixel
// when the point faces it and the ray of the nearest pixel meets the object at the
// point's depth (within two pixels' depth on a surface at 60°, tan 60° < 2, plus the
// mesh's rounding). The side matters for a thin part seen from both sides (an open
// tube): a projector lighting its inside does not light its outside.
std::optional<Vec2> sees(const Lamp& lamp, const Vec3& point, const Vec3& normal) {
  if (!lamp.model || !lamp.view || lamp.view->face.empty()) return std::nullopt;
  if (!(normal.dot(lamp.model->pose.center() - point) > 0)) return std::nullopt;
  const auto q = lamp.model->project(point);
  if (!q || !lamp.model->inImage(*q)) return std::nullopt;
  const cv::Mat& depth = lamp.view->distance;
  const int x = std::clamp(static_cast<int>(std::lround(q->x())), 0, depth.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(q->y())), 0, depth.rows - 1);
  const double d = (lamp.model->pose.center() - point).norm();
  const double tolerance = 0.002 + 4 * d / lamp.model->K.fx;
  if (!lamp.view->hit(x, y) || std::abs(depth.at<float>(y, x) - d) > tolerance) return std::nullopt;
  return *q;
}

// Whether it lights the point: seen, and its nearest pixel within its reach.
bool lights(const Lamp& lamp, const cv::Mat& reach, const Vec3& point, const Vec3& normal) {
  const auto q = sees(lamp, point, normal);
  if (!q) return false;
  const int x = std::clamp(static_cast<int>(std::lround(q->x())), 0, reach.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(q->y())), 0, reach.rows - 1);
  return reach.at<float>(y, x) > 0;
}

}  // namespace

float sampleBilinear(const cv::Mat& m, const Vec2& p) {
  const int x0 = static_cast<int>(std::floor(p.x())), y0 = static_cast<int>(std::floor(p.y()));
  const float ax = static_cast<float>(p.x() - x0), ay = static_cast<float>(p.y() - y0);
  const auto at = [&](int x, int y) {
    x = std::clamp(x, 0, m.cols - 1);
    y = std::clamp(y, 0, m.rows - 1);
    return m.at<float>(y, x);
  };
  return (1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
         ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
}

Result<LampWeights> lampWeights(std::span<const Lamp> lamps, const LampWeightOptions& o) {
  if (lamps.empty()) return fail(ErrorCode::kInvalidInput, "no projectors to weigh");
  if (!(o.max_incidence_deg > 0 && o.max_incidence_deg < 90))
    return fail(ErrorCode::kInvalidInput, "the grazing cut-off must lie in (0, 90) degrees");
  if (!(o.discontinuity_deg > o.max_incidence_deg && o.discontinuity_deg < 90))
    return fail(ErrorCode::kInvalidInput,
                "the depth discontinuity angle must lie between the cut-off and 90 degrees");
  if (o.silhouette_margin_px < 0 || o.silhouette_margin_px > 16)
    return fail(ErrorCode::kInvalidInput, "the silhouette margin must lie in [0, 16] pixels");
  if (!(o.position_error_m >= 0 && o.position_error_m <= 0.1))
    return fail(ErrorCode::kInvalidInput, "the position error must lie in [0, 0.1] m");
  if (!(o.smoothing_px >= 0 && o.smoothing_px <= 16))
    return fail(ErrorCode::kInvalidInput, "the weight smoothing must lie in [0, 16] pixels");
  for (const Lamp& l : lamps) {
    if (!l.model || !l.view) return fail(ErrorCode::kInvalidInput, "a projector has no view");
    if (l.view->size != cv::Size(l.model->width, l.model->height) || l.view->face.empty())
      return fail(ErrorCode::kInvalidInput, "a projector's view does not match its size");
    if (!(l.model->K.fx > 0))
      return fail(ErrorCode::kInvalidInput, "a projector has no focal length");
  }
  LampWeights out;
  for (const Lamp& l : lamps) {
    const int margin = marginPx(*l.view, *l.model, o);
    cv::Mat edges = depthEdges(*l.view, l.model->K.fx, o.discontinuity_deg);
    if (margin > 0) {
      // The same margin on both sides of a discontinuity: light meant for the near part
      // spreads onto the far one there, and the far part's onto the near one.
      const int k = 2 * margin + 1;
      cv::dilate(edges, edges, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
    }
    out.reach.push_back(edgeDistance(usablePixels(*l.view, o, margin) & ~edges));
  }
  // Feathering strength: the square of the reach, so a weight leaves zero with zero slope
  // instead of a kink; times how squarely the projector faces the point (0 at the cut-off,
  // 1 head-on), so the projector that sees a point best lights most of it; smoothed over
  // about the footprint of a pixel and its blur. A projector's pixels spread its light
  // over about a pixel; across a kink or a pixel-sized stair of the distance transform
  // that spreading takes light from one side and gives it to the other. Where two edges
  // come close (a narrow overlap on a curved part) the plain distance of eq. 4.3 left a
  // luminance step of 2.5 % on the virtual rig's vase, squared 1.3 %; with both and the
  // smoothing, 1.0 %, and 1.7 % (3.2 % unsmoothed) where two cut-offs cross 4 pixels apart.
  std::vector<cv::Mat> strength;
  const float min_cos = static_cast<float>(std::cos(degToRad(o.max_incidence_deg)));
  for (std::size_t i = 0; i < lamps.size(); ++i) {
    cv::Mat facing = (lamps[i].view->cosine - min_cos) / (1 - min_cos);
    cv::max(facing, 0, facing);
    cv::Mat st = out.reach[i].mul(out.reach[i]).mul(facing);
    if (o.smoothing_px > 0) cv::GaussianBlur(st, st, cv::Size(0, 0), o.smoothing_px);
    st.setTo(0, out.reach[i] <= 0);
    strength.push_back(std::move(st));
  }
  for (std::size_t i = 0; i < lamps.size(); ++i) {
    const LampView& v = *lamps[i].view;
    cv::Mat w(v.size, CV_32FC1, cv::Scalar(0));
    if (lamps[i].enabled) {
      cv::parallel_for_(cv::Range(0, v.size.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
          for (int x = 0; x < v.size.width; ++x) {
            const float own = strength[i].at<float>(y, x);
            if (!(own > 0)) continue;
            const Vec3 point = toVec(v.point.at<cv::Vec3f>(y, x));
            const Vec3 normal = toVec(v.normal.at<cv::Vec3f>(y, x));
            double sum = own;
            for (std::size_t j = 0; j < lamps.size(); ++j) {
              if (j == i || !lamps[j].enabled) continue;
              // Its reach read between pixels, so that it fades to zero over the pixel
              // past its last one as its light does.
              if (const auto q = sees(lamps[j], point, normal))
                sum += sampleBilinear(strength[j], *q);
            }
            w.at<float>(y, x) = static_cast<float>(own / sum);
          }
        }
      });
    }
    out.weight.push_back(std::move(w));
  }
  return out;
}

std::vector<std::optional<Vec2>> lampsSeeing(std::span<const Lamp> lamps, const Vec3& point,
                                             const Vec3& normal) {
  std::vector<std::optional<Vec2>> out;
  for (const Lamp& lamp : lamps) out.push_back(sees(lamp, point, normal));
  return out;
}

Coverage lampCoverage(std::span<const Lamp> lamps, const LampWeights& weights,
                      const ObjectModel& object, double spacing_m) {
  Coverage c;
  if (weights.reach.size() != lamps.size()) return c;  // not these projectors' weights
  const geom::TriangleMesh& m = object.mesh();
  const double spacing = std::max(spacing_m, 1e-6);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto face = static_cast<std::uint32_t>(f);
    const auto& t = m.faces[f];
    const double longest = std::max({(m.vertices[t[1]] - m.vertices[t[0]]).norm(),
                                     (m.vertices[t[2]] - m.vertices[t[1]]).norm(),
                                     (m.vertices[t[0]] - m.vertices[t[2]]).norm()});
    const int n = std::clamp(static_cast<int>(std::ceil(longest / spacing)), 1, 16);
    const double share = object.faceArea(face) / (n * n);
    bool hole = false;
    // Centroids of the n² sub-triangles: upright ones at (i + 1/3, j + 1/3) / n, the
    // others at (i + 2/3, j + 2/3) / n, in the face's (b, c) barycentric coordinates.
    const auto sample = [&](double b, double cc) {
      const SurfacePoint s = object.at(face, Vec3(1 - b - cc, b, cc));
      bool on = false, off = false;
      for (std::size_t i = 0; i < lamps.size(); ++i) {
        if (!lights(lamps[i], weights.reach[i], s.point, s.normal)) continue;
        (lamps[i].enabled ? on : off) = true;
      }
      if (on) {
        c.lit_m2 += share;
      } else if (off) {
        c.unlit_m2 += share;
        hole = true;
      } else {
        c.never_lit_m2 += share;
      }
    };
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i + j < n; ++i) {
        sample((i + 1.0 / 3) / n, (j + 1.0 / 3) / n);
        if (i + j + 1 < n) sample((i + 2.0 / 3) / n, (j + 2.0 / 3) / n);
      }
    }
    if (hole) c.unlit_faces.push_back(face);
  }
  return c;
}

}  // namespace procam::lamps
