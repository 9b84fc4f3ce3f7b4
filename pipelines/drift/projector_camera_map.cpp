#include "projector_camera_map.hpp"

#include <Eigen/LU>
#include <cmath>
#include <vector>

namespace procam::drift {

namespace {

// A point a camera sees must be the first the surface puts on its ray: a mesh's own
// points lie on it to rounding, so a hit within this much before the point is the point.
constexpr double kSelfHitM = 1e-3;
// A mesh's map: cast every kLattice work pixels, interpolated within kLatticeTolPx camera
// pixels (a hundredth of the tiles' 0.2 px scatter on a 1 DN camera).
constexpr int kLattice = 4;
constexpr double kLatticeTolPx = 0.002;

bool hidden(const geom::MeshIntersector& surface, const geom::CameraModel& camera,
            const Vec3& point) {
  const Vec3 c = camera.pose.center();
  const Vec3 d = point - c;
  const double dist = d.norm();
  if (!(dist > 2 * kSelfHitM)) return false;
  return surface.intersect({c, d / dist}, {1e-9, dist - kSelfHitM}).has_value();
}

}  // namespace

LitSurface planeLitSurface(const geom::PlaneHomography& projector_to_plane, cv::Size framebuffer) {
  const Mat3 H = projector_to_plane.H;
  const geom::PlaneBasis basis = projector_to_plane.basis;
  // Pixels whose rays miss the plane map to points behind the projector: the
  // homogeneous scale changes sign from the frame's centre (which lights the plane).
  const Vec3 centre((framebuffer.width - 1) / 2.0, (framebuffer.height - 1) / 2.0, 1.0);
  const double lit_sign = (H * centre).z() >= 0 ? 1.0 : -1.0;
  LitSurface out;
  out.point = [H, basis, lit_sign](const Vec2& fb) -> std::optional<Vec3> {
    const Vec3 ab = H * Vec3(fb.x(), fb.y(), 1.0);
    if (!(ab.z() * lit_sign > 1e-12)) return std::nullopt;  // at or past the plane's horizon
    return basis.toWorld({ab.x() / ab.z(), ab.y() / ab.z()});
  };
  return out;
}

Result<cv::Mat> projectorCameraMap(const LitSurface& surface, const geom::CameraModel& camera,
                                   const WorkGrid& grid) {
  if (grid.factor < 1 || grid.factor > 8 || grid.size().width < 1 || grid.size().height < 1) {
    return fail(ErrorCode::kInvalidInput,
                "drift map: a framebuffer of at least the sampling "
                "factor (1 to 8) on each side is needed");
  }
  if (!surface.point) return fail(ErrorCode::kInvalidInput, "drift map: no display surface");
  if (!camera.pose.R.allFinite() || !camera.pose.t.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "drift map: the rig model's mapping is not finite");
  }
  const cv::Size size = grid.size();
  cv::Mat map(size, CV_32FC2, cv::Scalar(-1, -1));
  bool finite = true;
  const auto cast = [&](int x, int y) -> cv::Vec2f {
    const auto world = surface.point(grid.toFramebuffer({x, y}));
    if (!world) return {-1, -1};
    if (!world->allFinite()) {
      finite = false;
      return {-1, -1};
    }
    const auto px = camera.project(*world);
    // Inside the outermost pixel centres: resampling there reads no pixel off the image.
    if (!px || !(px->x() >= 0 && px->y() >= 0 && px->x() <= camera.width - 1 &&
                 px->y() <= camera.height - 1)) {
      return {-1, -1};
    }
    if (surface.occluder && hidden(*surface.occluder, camera, *world)) return {-1, -1};
    return {static_cast<float>(px->x()), static_cast<float>(px->y())};
  };
  // A plane's map is a collineation, cheap at every pixel. A mesh's costs two ray casts
  // a pixel: it is cast on a lattice and interpolated inside the cells whose corners are
  // all seen and whose centre, cast too, lies within kLatticeTolPx of the interpolation
  // (a smooth surface); other cells are cast at every pixel.
  const int step =
      surface.occluder && size.width > kLattice && size.height > kLattice ? kLattice : 1;
  std::vector<int> xs, ys;
  for (int x = 0; x < size.width; x += step) xs.push_back(x);
  if (xs.back() != size.width - 1) xs.push_back(size.width - 1);
  for (int y = 0; y < size.height; y += step) ys.push_back(y);
  if (ys.back() != size.height - 1) ys.push_back(size.height - 1);
  for (int y : ys) {
    for (int x : xs) map.at<cv::Vec2f>(y, x) = cast(x, y);
  }
  if (step > 1) {
    // Which cells are smooth, then every pixel between the nodes: inside a smooth cell
    // interpolated; on a lattice line between two nodes interpolated only when every cell
    // beside it is smooth (either cell's bilinear is the same line there); else cast.
    const std::size_t nx = xs.size() - 1, ny = ys.size() - 1;
    std::vector<char> smooth(nx * ny, 0);
    const auto at = [&](int x, int y) { return map.at<cv::Vec2f>(y, x); };
    const auto lerp = [&](std::size_t i, std::size_t j, int x, int y) {
      const int x0 = xs[i], x1 = xs[i + 1], y0 = ys[j], y1 = ys[j + 1];
      const float fx = static_cast<float>(x - x0) / static_cast<float>(x1 - x0);
      const float fy = static_cast<float>(y - y0) / static_cast<float>(y1 - y0);
      return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) +
             fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
    };
    for (std::size_t j = 0; j < ny; ++j) {
      for (std::size_t i = 0; i < nx; ++i) {
        const int x0 = xs[i], x1 = xs[i + 1], y0 = ys[j], y1 = ys[j + 1];
        bool ok =
            at(x0, y0)[0] >= 0 && at(x1, y0)[0] >= 0 && at(x0, y1)[0] >= 0 && at(x1, y1)[0] >= 0;
        if (ok) {
          const int xm = (x0 + x1) / 2, ym = (y0 + y1) / 2;
          const cv::Vec2f exact = cast(xm, ym);
          ok = exact[0] >= 0 && cv::norm(exact - lerp(i, j, xm, ym)) <= kLatticeTolPx;
        }
        smooth[j * nx + i] = ok;
      }
    }
    const auto isSmooth = [&](std::size_t i, std::size_t j) { return smooth[j * nx + i] != 0; };
    for (std::size_t j = 0; j < ny; ++j) {
      for (std::size_t i = 0; i < nx; ++i) {
        const int x0 = xs[i], x1 = xs[i + 1], y0 = ys[j], y1 = ys[j + 1];
        for (int y = y0; y <= y1; ++y) {
          auto* row = map.ptr<cv::Vec2f>(y);
          for (int x = x0; x <= x1; ++x) {
            if ((x == x0 || x == x1) && (y == y0 || y == y1)) continue;  // a node
            // A cell fills its top and left edges; its bottom and right ones are the next
            // cell's, but at the grid's border.
            if ((x == x1 && i + 1 < nx) || (y == y1 && j + 1 < ny)) continue;
            bool interpolate = isSmooth(i, j);
            if (y == y0 && j > 0) interpolate = interpolate && isSmooth(i, j - 1);
            if (x == x0 && i > 0) interpolate = interpolate && isSmooth(i - 1, j);
            row[x] = interpolate ? lerp(i, j, x, y) : cast(x, y);
          }
        }
      }
    }
  }
  if (!finite)
    return fail(ErrorCode::kInvalidInput, "drift map: the rig model's mapping is not finite");
  return map;
}

Result<cv::Mat> projectorCameraMap(const geom::PlaneHomography& projector_to_plane,
                                   const geom::CameraModel& camera, const WorkGrid& grid) {
  if (!projector_to_plane.H.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "drift map: the rig model's mapping is not finite");
  }
  return projectorCameraMap(planeLitSurface(projector_to_plane, grid.framebuffer), camera, grid);
}

std::optional<Vec2> mappedCameraPixel(const cv::Mat& map, const Vec2& w) {
  const int x0 = static_cast<int>(std::floor(w.x())), y0 = static_cast<int>(std::floor(w.y()));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= map.cols || y0 + 1 >= map.rows) return std::nullopt;
  const double fx = w.x() - x0, fy = w.y() - y0;
  Vec2 sum = Vec2::Zero();
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const cv::Vec2f c = map.at<cv::Vec2f>(y0 + dy, x0 + dx);
      if (c[0] < 0) return std::nullopt;
      sum += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * Vec2(c[0], c[1]);
    }
  }
  return sum;
}

std::optional<Vec2> workPixelSeenAt(const cv::Mat& map, const Vec2& camera, const Vec2& start) {
  // The map is smooth where the camera sees the surface (a collineation, or a mesh's
  // facets seen from afar), so the steps converge in a few; the Jacobian is taken by
  // differences of a quarter work pixel, one-sided at the edge of the seen part.
  constexpr double kStep = 0.25, kTolPx = 1e-3, kLongestStep = 16;
  Vec2 w = start;
  for (int k = 0; k < 30; ++k) {
    auto f = mappedCameraPixel(map, w);
    if (!f) return std::nullopt;
    const Vec2 r = camera - *f;
    if (r.norm() < kTolPx) return w;
    Eigen::Matrix2d J;
    for (int axis = 0; axis < 2; ++axis) {
      Vec2 h = Vec2::Zero();
      h[axis] = kStep;
      if (auto ahead = mappedCameraPixel(map, w + h)) {
        J.col(axis) = (*ahead - *f) / kStep;
      } else if (auto behind = mappedCameraPixel(map, w - h)) {
        J.col(axis) = (*f - *behind) / kStep;
      } else {
        return std::nullopt;
      }
    }
    const double det = J.determinant();
    if (!std::isfinite(det) || std::abs(det) < 1e-9) return std::nullopt;
    Vec2 step = J.inverse() * r;
    if (step.norm() > kLongestStep) step *= kLongestStep / step.norm();
    w += step;
  }
  return std::nullopt;
}

}  // namespace procam::drift
