#pragma once
// A synthetic planar wall of cols x rows projectors (1280x800, f = 1500 px, 2 m throw,
// ~15 % overlaps, each turned up to 2 degrees) with exactly known geometry, camera
// views that each see a block of them, the matches a decoder would give, and the seam
// error of estimated projector-to-wall collineations. Shared by the homography-tree
// tests and the multi-projector bench.
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/homography_tree.hpp"
#include "geometry/plane_homography.hpp"

namespace procam::testing {

struct SyntheticWall {
  // The wall y = 3, seen from y < 3: u = +X, v = +Z (u x v = -Y faces the projectors).
  geom::PlaneBasis basis{Vec3(0, 3, 0), Vec3::UnitX(), Vec3::UnitZ()};
  int cols = 1, rows = 1;
  std::vector<geom::CameraModel> projectors;  // row-major, row 0 at the top
  double image_w = 0, image_h = 0;            // one projector's image on the wall, metres
  double pitch_x = 0, pitch_z = 0;            // projector centre to centre, metres
  double pixel_m = 0;                         // a projector pixel on the wall

  // Truth: projector pixels -> wall (u, v) in metres.
  Mat3 projectorToWall(std::size_t p) const {
    return geom::planeToImage(projectors[p].K, projectors[p].pose, basis)->inverse();
  }
};

inline SyntheticWall syntheticWall(int cols, int rows, std::mt19937& rng) {
  constexpr int kW = 1280, kH = 800;
  constexpr double kF = 1500, kThrow = 2.0;
  SyntheticWall w;
  w.cols = cols;
  w.rows = rows;
  w.image_w = kW / kF * kThrow;
  w.image_h = kH / kF * kThrow;
  w.pitch_x = 0.85 * w.image_w;
  w.pitch_z = 0.85 * w.image_h;
  w.pixel_m = kThrow / kF;
  std::uniform_real_distribution<double> turn(-2.0, 2.0);
  const double deg = M_PI / 180;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      geom::CameraModel p;
      p.width = kW;
      p.height = kH;
      p.K.fx = p.K.fy = kF;
      p.K.cx = 0.5 * (kW - 1);
      p.K.cy = 0.5 * (kH - 1);
      const Vec3 eye((c - 0.5 * (cols - 1)) * w.pitch_x, 3.0 - kThrow,
                     1.5 + (0.5 * (rows - 1) - r) * w.pitch_z);
      const Vec3 target = eye + Vec3(std::tan(turn(rng) * deg), 1, std::tan(turn(rng) * deg));
      const Vec3 up = Vec3(std::sin(turn(rng) * deg), 0, 1).normalized();
      p.pose = geom::Pose::lookAt(eye, target, up);
      w.projectors.push_back(p);
    }
  }
  return w;
}

// One 1920x1200 camera per `block` x `block` group of projectors, the groups one
// projector apart (neighbouring views share projectors), each 2.5 m from the wall, off
// the group's centre by up to 0.4 m and aimed at it so the group fills ~85 % of the
// image. View 0 sees the top-left group. A wall no larger than one group gets one view.
inline std::vector<geom::CameraModel> blockViews(const SyntheticWall& w, int block,
                                                 std::mt19937& rng) {
  std::vector<geom::CameraModel> views;
  const int bx = std::min(block, w.cols), by = std::min(block, w.rows);
  const double span_w = (bx - 1) * w.pitch_x + w.image_w;
  const double span_h = (by - 1) * w.pitch_z + w.image_h;
  const double d = 2.5;
  std::uniform_real_distribution<double> off(-0.4, 0.4);
  for (int r0 = 0; r0 + by <= w.rows; ++r0) {
    for (int c0 = 0; c0 + bx <= w.cols; ++c0) {
      const double cx = (c0 + 0.5 * (bx - 1) - 0.5 * (w.cols - 1)) * w.pitch_x;
      const double cz = 1.5 + (0.5 * (w.rows - 1) - r0 - 0.5 * (by - 1)) * w.pitch_z;
      geom::CameraModel cam;
      cam.width = 1920;
      cam.height = 1200;
      const double f = 0.85 * std::min(cam.width / (span_w / d), cam.height / (span_h / d));
      cam.K.fx = cam.K.fy = f;
      cam.K.cx = 0.5 * (cam.width - 1);
      cam.K.cy = 0.5 * (cam.height - 1);
      const Vec3 target(cx, 3.0, cz);
      cam.pose = geom::Pose::lookAt(target + Vec3(off(rng), -d, off(rng)), target, Vec3::UnitZ());
      views.push_back(cam);
    }
  }
  return views;
}

// Wall (u, v) -> ideal pixels of `cam`.
inline Mat3 wallToImage(const SyntheticWall& w, const geom::CameraModel& cam) {
  return *geom::planeToImage(cam.K, cam.pose, w.basis);
}

// The projector nodes every `step` px (centres at step/2) that each view sees inside its
// image (a 2 px margin), with Gaussian noise of `noise_px` on the view side: what a
// decoder's sampled nodes give.
inline std::vector<geom::ViewProjectorMatches> viewMatches(
    const SyntheticWall& w, const std::vector<geom::CameraModel>& views, int step, double noise_px,
    std::mt19937& rng) {
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<geom::ViewProjectorMatches> out;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const Mat3 to_view = wallToImage(w, views[v]);
    for (std::size_t p = 0; p < w.projectors.size(); ++p) {
      const Mat3 H = to_view * w.projectorToWall(p);
      geom::ViewProjectorMatches m;
      m.view = v;
      m.projector = p;
      for (int y = step / 2; y < w.projectors[p].height; y += step) {
        for (int x = step / 2; x < w.projectors[p].width; x += step) {
          const Vec2 seen = (H * Vec3(x, y, 1)).hnormalized();
          if (seen.x() < 2 || seen.y() < 2 || seen.x() > views[v].width - 3 ||
              seen.y() > views[v].height - 3)
            continue;
          m.projector_px.push_back(Vec2(x, y));
          m.view_px.push_back(seen + Vec2(noise(rng), noise(rng)));
        }
      }
      if (!m.projector_px.empty()) out.push_back(std::move(m));
    }
  }
  return out;
}

struct SeamError {
  double rms_px = 0, max_px = 0;  // projector pixels
  long points = 0;
};

// Seams of estimated projector -> wall collineations: wall points (every `spacing`
// projector pixels) that two projectors show by the estimate; where the TRUE projectors
// put the two pixels, apart, in projector pixels.
inline SeamError seamError(const SyntheticWall& w, const std::vector<Mat3>& projector_to_wall,
                           double spacing = 4) {
  SeamError out;
  std::vector<Mat3> to_pixel, truth;
  for (std::size_t p = 0; p < w.projectors.size(); ++p) {
    to_pixel.push_back(projector_to_wall[p].inverse());
    truth.push_back(w.projectorToWall(p));
  }
  const double half_w = 0.5 * ((w.cols - 1) * w.pitch_x + w.image_w) + 0.1;
  const double lo_z = 1.5 - 0.5 * ((w.rows - 1) * w.pitch_z + w.image_h) - 0.1;
  const double hi_z = 3.0 - lo_z;
  const double ds = spacing * w.pixel_m;
  double sq = 0;
  std::vector<Vec2> shown;
  for (double z = lo_z; z < hi_z; z += ds) {
    for (double x = -half_w; x < half_w; x += ds) {
      shown.clear();
      for (std::size_t p = 0; p < w.projectors.size(); ++p) {
        const Vec3 h = to_pixel[p] * Vec3(x, z, 1);
        if (!(h.z() > 0)) continue;
        const Vec2 px = h.hnormalized();
        if (px.x() < 0 || px.y() < 0 || px.x() > w.projectors[p].width - 1 ||
            px.y() > w.projectors[p].height - 1)
          continue;
        shown.push_back((truth[p] * px.homogeneous()).hnormalized());
      }
      for (std::size_t i = 0; i < shown.size(); ++i) {
        for (std::size_t j = i + 1; j < shown.size(); ++j) {
          const double e = (shown[i] - shown[j]).norm() / w.pixel_m;
          sq += e * e;
          out.max_px = std::max(out.max_px, e);
          ++out.points;
        }
      }
    }
  }
  out.rms_px = out.points ? std::sqrt(sq / double(out.points)) : 0;
  return out;
}

}  // namespace procam::testing
