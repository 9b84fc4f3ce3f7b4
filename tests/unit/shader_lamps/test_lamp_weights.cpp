// Each projector's view of the object and the weights of several projectors on it
// ([Raskar02] §5.2.5): distances and angles against the analytic plate, weights that sum
// to one where projectors overlap, zero past the grazing cut-off and along depth
// discontinuities, and a projector switched off leaving a reported hole.
#include <gtest/gtest.h>

#include <cmath>

#include "lamp_rig.hpp"
#include "shader_lamps/lamp_view.hpp"
#include "shader_lamps/lamp_weights.hpp"

namespace procam::lamps {
namespace {

TEST(ShaderLampView, DistanceAndIncidenceMatchThePlate) {
  auto plate = ObjectModel::build(test::plate(2.0, 1.0, 4));
  ASSERT_TRUE(plate);
  const geom::CameraModel p = test::projectorAt(Vec3::Zero(), Vec3(0, 2, 0));
  auto view = castLampView(p, *plate);
  ASSERT_TRUE(view) << view.error().message;
  int hits = 0;
  for (int y = 0; y < 300; y += 7) {
    for (int x = 0; x < 400; x += 7) {
      const auto ray = p.backproject(Vec2(x, y));
      ASSERT_TRUE(ray);
      const double t = 2.0 / ray->dir.y();
      const Vec3 X = ray->at(t);
      const bool on = std::abs(X.x()) < 1 && std::abs(X.z()) < 1;
      ASSERT_EQ(view->hit(x, y), on) << x << "," << y;
      if (!on) continue;
      ++hits;
      EXPECT_NEAR(view->distance.at<float>(y, x), t, 1e-5);
      EXPECT_NEAR(view->cosine.at<float>(y, x), ray->dir.y(), 1e-6);
    }
  }
  EXPECT_GT(hits, 1000);
}

struct TwoLamps {
  ObjectModel plate;
  geom::CameraModel a, b;
  LampView va, vb;
};

// Two projectors 1.2 m apart, 2 m from a 3 x 3 m plate: their images overlap in the middle.
TwoLamps twoLamps() {
  auto plate = ObjectModel::build(test::plate(2.0, 1.5, 6));
  EXPECT_TRUE(plate);
  TwoLamps r{std::move(*plate),
             test::projectorAt(Vec3(-0.6, 0, 0), Vec3(-0.6, 2, 0)),
             test::projectorAt(Vec3(0.6, 0, 0), Vec3(0.6, 2, 0)),
             {},
             {}};
  r.va = *castLampView(r.a, r.plate);
  r.vb = *castLampView(r.b, r.plate);
  return r;
}

TEST(ShaderLampWeights, OverlappingProjectorsSumToOne) {
  const TwoLamps r = twoLamps();
  const Lamp lamps[] = {{&r.a, &r.va, true}, {&r.b, &r.vb, true}};
  auto w = lampWeights(lamps);
  ASSERT_TRUE(w) << w.error().message;
  double worst = 0;
  int overlap = 0, alone = 0;
  for (double x = -1.4; x <= 1.4; x += 0.01) {
    for (double z = -0.6; z <= 0.6; z += 0.05) {
      const Vec3 X(x, 2, z), n(0, -1, 0);
      const auto seen = lampsSeeing(lamps, X, n);
      double sum = 0;
      int inside = 0;
      for (std::size_t i = 0; i < 2; ++i) {
        if (!seen[i]) continue;
        sum += sampleBilinear(w->weight[i], *seen[i]);
        inside += sampleBilinear(w->reach[i], *seen[i]) > 8;
      }
      if (seen[0] && seen[1] && inside == 2) {
        ++overlap;
        worst = std::max(worst, std::abs(sum - 1));
      }
      if (seen[0] && !seen[1] && sampleBilinear(w->reach[0], *seen[0]) > 3) {
        ++alone;
        EXPECT_NEAR(sampleBilinear(w->weight[0], *seen[0]), 1.0, 1e-6) << x << "," << z;
      }
    }
  }
  EXPECT_GT(overlap, 100);
  EXPECT_GT(alone, 100);
  // Interpolating each projector's weights between its own pixels: a smooth field, so the
  // sum is one to within the change of its curvature over a pixel.
  EXPECT_LT(worst, 1e-3);
  std::printf("overlap points %d, sum of weights within %.2g of one\n", overlap, worst);
}

TEST(ShaderLampWeights, NothingPastTheGrazingCutOff) {
  // One projector looking at the plate at 50 deg off its normal: its far side is past 60.
  auto plate = ObjectModel::build(test::plate(2.0, 1.5, 6));
  ASSERT_TRUE(plate);
  const geom::CameraModel p = test::projectorAt(Vec3(-1.8, 0.3, 0), Vec3(0, 2, 0));
  auto view = castLampView(p, *plate);
  ASSERT_TRUE(view);
  const Lamp lamps[] = {{&p, &*view, true}};
  auto w = lampWeights(lamps);
  ASSERT_TRUE(w);
  int grazing = 0, facing = 0;
  for (int y = 0; y < 300; ++y) {
    for (int x = 0; x < 400; ++x) {
      if (!view->hit(x, y)) continue;
      const float c = view->cosine.at<float>(y, x), weight = w->weight[0].at<float>(y, x);
      if (c < 0.5f) {
        ++grazing;
        EXPECT_EQ(weight, 0.f);
      } else if (w->reach[0].at<float>(y, x) > 2) {
        ++facing;
        EXPECT_FLOAT_EQ(weight, 1.f);  // alone: all of the light
      }
    }
  }
  EXPECT_GT(grazing, 1000);
  EXPECT_GT(facing, 1000);
}

TEST(ShaderLampWeights, DepthDiscontinuitiesAreEdges) {
  // A small plate 0.5 m in front of the big one, both parts of the object.
  geom::TriangleMesh mesh = test::plate(2.0, 1.5, 6);
  const geom::TriangleMesh front = test::plate(1.5, 0.2, 1);
  const int base = static_cast<int>(mesh.vertices.size());
  for (const Vec3& v : front.vertices) mesh.vertices.push_back(v);
  for (const auto& f : front.faces) mesh.faces.emplace_back(f + Eigen::Vector3i::Constant(base));
  auto object = ObjectModel::build(mesh);
  ASSERT_TRUE(object);
  const geom::CameraModel p = test::projectorAt(Vec3::Zero(), Vec3(0, 2, 0));
  auto view = castLampView(p, *object);
  ASSERT_TRUE(view);
  const Lamp lamps[] = {{&p, &*view, true}};
  auto w = lampWeights(lamps);
  ASSERT_TRUE(w);
  // Along the centre row the small plate spans |x| < 0.2 at 1.5 m: pixels 199.5 +- 53.3,
  // so pixels 146 | 147 and 252 | 253 straddle its outline; with the one-pixel margin on
  // either side, 145-148 and 251-254 light nothing.
  const int y = 150;
  EXPECT_GT(w->reach[0].at<float>(y, 199), 40);  // the small plate's middle
  for (const int first : {145, 251}) {
    for (int x = first; x < first + 4; ++x) EXPECT_EQ(w->reach[0].at<float>(y, x), 0.f) << x;
    EXPECT_GT(w->reach[0].at<float>(y, first - 1), 0.f);
    EXPECT_GT(w->reach[0].at<float>(y, first + 4), 0.f);
  }
}

TEST(ShaderLampWeights, APositionErrorWidensTheDarkMargin) {
  auto plate = ObjectModel::build(test::plate(2.0, 0.5, 2));
  ASSERT_TRUE(plate);
  const geom::CameraModel p = test::projectorAt(Vec3::Zero(), Vec3(0, 2, 0));
  auto view = castLampView(p, *plate);
  ASSERT_TRUE(view);
  const Lamp lamps[] = {{&p, &*view, true}};
  // The plate's edge |x| = 0.5 at 2 m: between pixels 99 and 100 (199.5 - 100).
  LampWeightOptions o;
  auto exact = lampWeights(lamps, o);
  o.position_error_m = 0.01;  // 2 pixels at 2 m with f = 400
  auto loose = lampWeights(lamps, o);
  ASSERT_TRUE(exact && loose);
  const int y = 150;
  EXPECT_EQ(exact->reach[0].at<float>(y, 100), 0.f);  // the one-pixel margin
  EXPECT_GT(exact->reach[0].at<float>(y, 101), 0.f);
  for (int x = 100; x <= 102; ++x) EXPECT_EQ(loose->reach[0].at<float>(y, x), 0.f) << x;
  EXPECT_GT(loose->reach[0].at<float>(y, 103), 0.f);
  o.position_error_m = 1;
  EXPECT_EQ(lampWeights(lamps, o).error().code, ErrorCode::kInvalidInput);
}

TEST(ShaderLampWeights, ASwitchedOffProjectorLeavesAReportedHole) {
  const TwoLamps r = twoLamps();
  const Lamp both[] = {{&r.a, &r.va, true}, {&r.b, &r.vb, true}};
  const Lamp one[] = {{&r.a, &r.va, true}, {&r.b, &r.vb, false}};
  auto w_both = lampWeights(both);
  auto w_one = lampWeights(one);
  ASSERT_TRUE(w_both && w_one);
  // Every pixel of b is dark, and a lights alone whatever it reaches.
  EXPECT_EQ(cv::countNonZero(w_one->weight[1]), 0);
  cv::Mat lit_a = w_one->reach[0] > 0, full = w_one->weight[0] == 1.f;
  EXPECT_EQ(cv::countNonZero(lit_a & ~full), 0);
  const Coverage c_both = lampCoverage(both, *w_both, r.plate);
  const Coverage c_one = lampCoverage(one, *w_one, r.plate);
  EXPECT_EQ(c_both.unlit_m2, 0.0);
  EXPECT_TRUE(c_both.unlit_faces.empty());
  EXPECT_GT(c_one.unlit_m2, 0.5);
  EXPECT_FALSE(c_one.unlit_faces.empty());
  // The plate's area is accounted for either way.
  EXPECT_NEAR(c_both.lit_m2 + c_both.unlit_m2 + c_both.never_lit_m2, 9.0, 1e-9);
  EXPECT_NEAR(c_one.lit_m2 + c_one.unlit_m2 + c_one.never_lit_m2, 9.0, 1e-9);
  // What b alone lit is now the hole: both see it as lit, one as lit plus the hole.
  EXPECT_NEAR(c_one.lit_m2 + c_one.unlit_m2, c_both.lit_m2, 1e-9);
}

TEST(ShaderLampWeights, BadInputIsRefused) {
  const TwoLamps r = twoLamps();
  EXPECT_EQ(lampWeights({}).error().code, ErrorCode::kInvalidInput);
  const Lamp missing[] = {{&r.a, nullptr, true}};
  EXPECT_EQ(lampWeights(missing).error().code, ErrorCode::kInvalidInput);
  const Lamp mismatched[] = {{&r.a, &r.va, true}};
  LampWeightOptions o;
  o.max_incidence_deg = 95;
  EXPECT_EQ(lampWeights(mismatched, o).error().code, ErrorCode::kInvalidInput);
  o = {};
  o.discontinuity_deg = 50;  // below the cut-off
  EXPECT_EQ(lampWeights(mismatched, o).error().code, ErrorCode::kInvalidInput);
  geom::CameraModel small = r.a;
  small.width = 200;
  const Lamp wrong_size[] = {{&small, &r.va, true}};
  EXPECT_EQ(lampWeights(wrong_size).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::lamps
