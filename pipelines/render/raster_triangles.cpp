#include "render/raster_triangles.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include "render/raster.hpp"

namespace procam::render {
namespace {

struct ClipVertex {
  Vec4 clip;   // (x w, y w, z w, w) in pixels
  Vec4 color;  // RGBA in [0, 1]
};

// A triangle clipped by 6 planes has at most 9 vertices.
constexpr int kMaxPolygon = 9;
using Polygon = std::array<ClipVertex, kMaxPolygon + 1>;

// One Sutherland-Hodgman pass against the half-space dist(v) >= 0. Clip coordinates and
// colours are interpolated linearly along the edge: linear in homogeneous space is
// perspective-correct once divided by w.
template <class Dist>
int clipAgainst(const Polygon& in, int n, Polygon& out, Dist dist) {
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % n];
    const double da = dist(a.clip), db = dist(b.clip);
    if (da >= 0) out[m++] = a;
    if ((da >= 0) != (db >= 0)) {
      const double t = da / (da - db);
      out[m++] = {a.clip + t * (b.clip - a.clip), a.color + t * (b.color - a.color)};
    }
  }
  return m;
}

// Screen-space triangle ready for scan conversion.
struct ScreenTriangle {
  std::array<Vec2, 3> p;
  std::array<float, 3> z;             // NDC depth, affine in screen space
  std::array<float, 3> inv_w;         // 1 / w
  std::array<cv::Vec4f, 3> color_iw;  // colour / w
  int row_min = 0, row_max = -1;
};

// Clips one triangle and appends the fan of the clipped polygon.
void clipTriangle(const std::array<ClipVertex, 3>& tri, cv::Size size,
                  std::vector<ScreenTriangle>& out) {
  Polygon a, b;
  int n = 3;
  std::copy(tri.begin(), tri.end(), a.begin());
  const double W = size.width, H = size.height;
  // Depth first (near -w <= z, far z <= w), then the image band [-1, W] x [-1, H]: no
  // pixel centre lies outside it, so this clipping changes no coverage.
  n = clipAgainst(a, n, b, [](const Vec4& c) { return c.z() + c.w(); });
  n = clipAgainst(b, n, a, [](const Vec4& c) { return c.w() - c.z(); });
  n = clipAgainst(a, n, b, [](const Vec4& c) { return c.x() + c.w(); });
  n = clipAgainst(b, n, a, [W](const Vec4& c) { return W * c.w() - c.x(); });
  n = clipAgainst(a, n, b, [](const Vec4& c) { return c.y() + c.w(); });
  n = clipAgainst(b, n, a, [H](const Vec4& c) { return H * c.w() - c.y(); });
  if (n < 3) return;
  ScreenTriangle s;
  std::array<Vec2, kMaxPolygon> p;
  std::array<double, kMaxPolygon> iw;
  for (int i = 0; i < n; ++i) {
    // w > 0 on what is left: -w <= z <= w gives w >= 0, and w = 0 only at the
    // projector's centre, where the polygon is degenerate.
    if (!(a[i].clip.w() > 0)) return;
    iw[i] = 1.0 / a[i].clip.w();
    p[i] = a[i].clip.head<2>() * iw[i];
  }
  for (int i = 1; i + 1 < n; ++i) {
    const int idx[3] = {0, i, i + 1};
    double y_min = H, y_max = -1;
    for (int k = 0; k < 3; ++k) {
      const ClipVertex& v = a[idx[k]];
      s.p[k] = p[idx[k]];
      s.z[k] = static_cast<float>(v.clip.z() * iw[idx[k]]);
      s.inv_w[k] = static_cast<float>(iw[idx[k]]);
      for (int c = 0; c < 4; ++c) s.color_iw[k][c] = static_cast<float>(v.color[c] * iw[idx[k]]);
      y_min = std::min(y_min, s.p[k].y());
      y_max = std::max(y_max, s.p[k].y());
    }
    s.row_min = std::max(0, static_cast<int>(std::ceil(y_min)));
    s.row_max = std::min(size.height - 1, static_cast<int>(std::floor(y_max)));
    if (s.row_min <= s.row_max) out.push_back(s);
  }
}

// Round to nearest, as GL's conversion of a normalised float to 8 bits.
uint8_t toUnorm8(float v) {
  return static_cast<uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
}

}  // namespace

Result<void> rasterizeColoredMesh(const ColoredMesh& mesh, const Mat4& pixel3d, cv::Size size,
                                  cv::Mat& color, cv::Mat& depth,
                                  const std::function<bool()>& stop) {
  if (mesh.colors.size() != mesh.vertices.size()) {
    return fail(ErrorCode::kInvalidInput, "raster: one colour per vertex required");
  }
  if (size.width < 1 || size.height < 1) {
    return fail(ErrorCode::kInvalidInput, "raster: empty output size");
  }
  const int nv = static_cast<int>(mesh.vertices.size());
  std::vector<ClipVertex> verts(mesh.vertices.size());
  for (int i = 0; i < nv; ++i) {
    const cv::Vec4b& c = mesh.colors[i];
    verts[i] = {pixel3d * mesh.vertices[i].homogeneous(), Vec4(c[0], c[1], c[2], c[3]) / 255.0};
  }
  std::vector<ScreenTriangle> tris;
  tris.reserve(mesh.triangles.size());
  size_t until_check = kStopCheckTriangles;
  for (const auto& t : mesh.triangles) {
    if (stop && --until_check == 0) {
      if (stop()) return fail(ErrorCode::kCancelled, "raster: stopped");
      until_check = kStopCheckTriangles;
    }
    for (int i : t) {
      if (i < 0 || i >= nv)
        return fail(ErrorCode::kInvalidInput, "raster: vertex index out of range");
    }
    const std::array<ClipVertex, 3> tri = {verts[t[0]], verts[t[1]], verts[t[2]]};
    if (!tri[0].clip.allFinite() || !tri[1].clip.allFinite() || !tri[2].clip.allFinite()) continue;
    clipTriangle(tri, size, tris);
  }
  color.create(size, CV_8UC4);
  color.setTo(cv::Scalar::all(0));
  depth.create(size, CV_32F);
  depth.setTo(cv::Scalar::all(1.0));
  // Stripes of rows on all cores; each stripe draws every triangle in submission order,
  // so equal depths resolve as in GL (the first fragment stays under GL_LESS).
  std::atomic<bool> stopped{false};
  cv::parallel_for_(
      cv::Range(0, size.height),
      [&](const cv::Range& rows) {
        size_t stripe_check = kStopCheckTriangles;
        for (const ScreenTriangle& s : tris) {
          if (stop && --stripe_check == 0) {
            if (stopped.load(std::memory_order_relaxed) || stop()) {
              stopped.store(true, std::memory_order_relaxed);
              return;
            }
            stripe_check = kStopCheckTriangles;
          }
          if (s.row_max < rows.start || s.row_min >= rows.end) continue;
          rasterizeTriangleRows(
              s.p[0], s.p[1], s.p[2], size.width, rows.start, rows.end,
              [&](int x, int y, double b0, double b1, double b2) {
                const float w0 = static_cast<float>(b0), w1 = static_cast<float>(b1),
                            w2 = static_cast<float>(b2);
                const float z = w0 * s.z[0] + w1 * s.z[1] + w2 * s.z[2];
                float& d = depth.at<float>(y, x);
                if (!(z < d)) return;
                d = z;
                const float iw = w0 * s.inv_w[0] + w1 * s.inv_w[1] + w2 * s.inv_w[2];
                const cv::Vec4f c =
                    (w0 * s.color_iw[0] + w1 * s.color_iw[1] + w2 * s.color_iw[2]) * (1.0f / iw);
                cv::Vec4b& o = color.at<cv::Vec4b>(y, x);
                for (int k = 0; k < 4; ++k) o[k] = toUnorm8(c[k]);
              });
        }
      },
      16);
  if (stopped.load()) return fail(ErrorCode::kCancelled, "raster: stopped");
  return {};
}

}  // namespace procam::render
