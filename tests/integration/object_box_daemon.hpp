#pragma once
// object_box in procamd for the shader-lamps tests: the box, its model's own frame, its
// corners picked in the world, the colour camera's averaged snapshots, and the judgement
// of what that camera sees of the painted box against the texture it should show (with
// the simulator's own geometry).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/units.hpp"
#include "daemon_harness.hpp"
#include "object_meshes.hpp"
#include "shader_lamps/appearance.hpp"
#include "shader_lamps/object_model.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"

namespace procam::itest {

inline const Vec3 kBoxCentre(0.1, 1.5, 0.875), kBoxSize(0.3, 0.2, 0.25);
inline constexpr double kCutoffDeg = 60;
// Snapshots averaged: the painted box is near 25 DN in this camera (its exposure is the
// scene's), 1 DN of read noise and shot noise to about 0.3 DN.
inline constexpr int kShots = 16;

inline double luma(const Vec3& rgb) {
  return 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
}

// world = kModelR · model + kBoxCentre: the model's own frame, as a modelling tool left it.
inline Mat3 modelRotation() {
  return (Eigen::AngleAxisd(degToRad(25.0), Vec3::UnitZ()) *
          Eigen::AngleAxisd(degToRad(10.0), Vec3::UnitX()))
      .toRotationMatrix();
}

// The mean of `n` snapshots of `camera`, linear camera units (BGR, float).
inline cv::Mat meanSnapshot(Connection& c, const std::string& camera, int n) {
  using namespace std::chrono_literals;
  cv::Mat sum;
  for (int i = 0; i < n; ++i) {
    auto shot = c.call({{"cmd", "snapshot"}, {"camera", camera}}, 60s * kSlowdown);
    if (!shot || (*shot)["class"] != "SNAPSHOT") {
      ADD_FAILURE() << (shot ? shot->dump() : "no reply");
      return {};
    }
    cv::Mat img = cv::imread((*shot)["path"].get<std::string>(), cv::IMREAD_UNCHANGED), f;
    img.convertTo(f, CV_32FC3);
    if (sum.empty())
      sum = f;
    else
      sum += f;
  }
  return sum / n;
}

struct Seen {
  double mean_rel = 1;  // mean |ratio / median - 1| where a projector faces the box < 60°
  long judged = 0;
  double median_dn = 0;  // the seen luminance's median over the judged pixels
  double spill_px = 0;   // farthest brightened camera pixel off the box from its outline
  long spilled = 0;      // brightened pixels off the box farther than 2 camera pixels
};

// What the camera sees of the painted box (lit minus dark), against albedo · texture.
inline Seen judge(const sim::Scene& scene, const sim::SceneState& state, const cv::Mat& lit,
                  const cv::Mat& dark, const cv::Mat& texture) {
  Seen out;
  const geom::CameraModel* cam = nullptr;
  for (const auto& c : state.cameras)
    if (c.spec.name == "cam_colour") cam = &c.model;
  auto renderer = sim::Renderer::create(scene, state, {});
  if (!cam || !renderer || lit.empty() || dark.empty()) {
    ADD_FAILURE() << "no camera, renderer or snapshot";
    return out;
  }
  const ObjectMesh box = boxMesh(kBoxCentre, kBoxSize, 0.01);
  auto model = lamps::ObjectModel::build(box.mesh, box.uv);
  EXPECT_TRUE(model);
  Vec3 albedo = Vec3::Ones();
  int box_id = -1;
  for (std::size_t s = 0; s < scene.world().surfaces().size(); ++s) {
    if (scene.world().surfaces()[s].name != "box") continue;
    box_id = static_cast<int>(s);
    const auto& a = scene.world().surfaces()[s].albedo_rgb;
    albedo = Vec3(a[0], a[1], a[2]);
  }
  const int W = cam->width, H = cam->height;
  cv::Mat group(H, W, CV_32SC1, cv::Scalar(-1)), on_box(H, W, CV_8UC1, cv::Scalar(0));
  cv::Mat ratio(H, W, CV_64FC1, cv::Scalar(0));
  const cv::Mat seen = lit - dark;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const sim::PixelTruth t = renderer->truthAt(*cam, Vec2(x, y));
      if (!t.hit || t.surface != box_id) continue;
      on_box.at<std::uint8_t>(y, x) = 255;
      bool facing = false;
      for (const auto& p : t.projectors)
        facing |= p.lit && p.cos_incidence >= std::cos(degToRad(kCutoffDeg));
      const auto ray = cam->backproject(Vec2(x, y));
      const auto s = ray ? model->intersect(*ray) : std::nullopt;
      if (!facing || !s) continue;
      group.at<int>(y, x) = boxSideOf(t.normal);
      const Vec3 want = albedo.cwiseProduct(lamps::textureAt(texture, s->texcoord));
      const cv::Vec3f bgr = seen.at<cv::Vec3f>(y, x);
      ratio.at<double>(y, x) = luma(Vec3(bgr[2], bgr[1], bgr[0])) / luma(want);
    }
  }
  // Judged two pixels in from any face edge, crease or cut-off (a pixel's light and the
  // camera's supersampling spread over about one pixel).
  std::vector<double> ratios;
  std::vector<cv::Point> where;
  for (int y = 2; y + 2 < H; ++y) {
    for (int x = 2; x + 2 < W; ++x) {
      const int g = group.at<int>(y, x);
      if (g < 0) continue;
      bool inner = true;
      for (int dy = -2; dy <= 2 && inner; ++dy)
        for (int dx = -2; dx <= 2; ++dx) inner &= group.at<int>(y + dy, x + dx) == g;
      if (!inner) continue;
      ratios.push_back(ratio.at<double>(y, x));
      where.emplace_back(x, y);
    }
  }
  out.judged = static_cast<long>(ratios.size());
  if (ratios.empty()) return out;

  std::vector<double> sorted = ratios;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                   sorted.end());
  const double median = sorted[sorted.size() / 2];
  double sum = 0;
  for (double r : ratios) sum += std::abs(r / median - 1);
  out.mean_rel = sum / static_cast<double>(ratios.size());
  std::vector<double> dn;
  for (const cv::Point& p : where) {
    const cv::Vec3f bgr = seen.at<cv::Vec3f>(p);
    dn.push_back(luma(Vec3(bgr[2], bgr[1], bgr[0])));
  }
  std::nth_element(dn.begin(), dn.begin() + static_cast<long>(dn.size() / 2), dn.end());
  out.median_dn = dn[dn.size() / 2];
  // Spill: light on the table, the wall or the floor, away from the box.
  cv::Mat off_box, distance;
  cv::bitwise_not(on_box, off_box);
  cv::distanceTransform(off_box, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      if (on_box.at<std::uint8_t>(y, x)) continue;
      const cv::Vec3f bgr = seen.at<cv::Vec3f>(y, x);
      // Well over the noise of the difference of two means of 16 captures (0.4 DN).
      if (luma(Vec3(bgr[2], bgr[1], bgr[0])) < 5.0) continue;
      const double d = distance.at<float>(y, x);
      out.spill_px = std::max(out.spill_px, d);
      out.spilled += d > 2;
    }
  }
  return out;
}

// The eight corners of the box: in the model's frame and in the world, the world ones
// off by `pick_m` per axis (normal, seeded).
inline json cornerPoints(double pick_m) {
  const Mat3 R = modelRotation();
  json points = json::array();
  std::mt19937 rng(7);
  std::normal_distribution<double> pick(0, 1);
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner =
        kBoxCentre + 0.5 * Vec3((k & 1 ? 1 : -1) * kBoxSize.x(), (k & 2 ? 1 : -1) * kBoxSize.y(),
                                (k & 4 ? 1 : -1) * kBoxSize.z());
    const Vec3 m = R.transpose() * (corner - kBoxCentre);
    const Vec3 w = corner + pick_m * Vec3(pick(rng), pick(rng), pick(rng));
    points.push_back({{"model", {m.x(), m.y(), m.z()}}, {"world", {w.x(), w.y(), w.z()}}});
  }
  return points;
}

// The painted box's figures printed under `what`, and the bounds: 3 % mean relative error
// over at least 20,000 judged pixels, nothing brightened more than 2 px off the box.
inline void expectPaintedBox(const Seen& seen, const char* what) {
  std::printf(
      "%s: %ld camera pixels (median %.1f DN), mean relative luminance error %.2f %% (up to the "
      "white level), brightened pixels off the box: farthest %.1f px from its outline, %ld "
      "beyond 2 px\n",
      what, seen.judged, seen.median_dn, 100 * seen.mean_rel, seen.spill_px, seen.spilled);
  EXPECT_GT(seen.judged, 20000) << what;
  EXPECT_LT(seen.mean_rel, 0.03) << what;
  EXPECT_EQ(seen.spilled, 0) << what;
}

// `object place` of box_model.ply (in the content root) from its corners picked `pick_m`
// off per axis.
inline std::optional<json> placeBox(Connection& c, double pick_m) {
  using namespace std::chrono_literals;
  return c.call({{"cmd", "object"},
                 {"action", "place"},
                 {"model", "box_model.ply"},
                 {"points", cornerPoints(pick_m)}},
                30s);
}

}  // namespace procam::itest
