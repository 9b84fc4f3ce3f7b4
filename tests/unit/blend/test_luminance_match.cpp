// Per-pixel photometric matching ([Majumder05]) and the brightness maps it reads, on
// synthetic projectors whose light is known exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "blend/blend_tables.hpp"
#include "blend/brightness_map.hpp"
#include "blend/luminance_match.hpp"

namespace procam::blend {
namespace {

// A projector's white: `peak` at the frame's centre falling off as a cos^3-like bowl.
double bowl(double peak, const Vec2& px, cv::Size size) {
  const double dx = (px.x() - 0.5 * (size.width - 1)) / size.width;
  const double dy = (px.y() - 0.5 * (size.height - 1)) / size.width;
  return peak * (1 - 0.4 * (dx * dx + dy * dy));
}

BrightnessMap exactMap(double peak, cv::Size size, int step = 16) {
  BrightnessMap m;
  m.step = step;
  m.width = size.width;
  m.height = size.height;
  m.white =
      cv::Mat(brightnessNodes(size.height, step), brightnessNodes(size.width, step), CV_32FC1);
  for (int j = 0; j < m.white.rows; ++j) {
    for (int i = 0; i < m.white.cols; ++i) {
      const Vec2 px(i * step, j * step);
      m.white.at<float>(j, i) = static_cast<float>(bowl(peak, px, size));
    }
  }
  return m;
}

TEST(BrightnessMap, MeasuredFromACameraThatSeesPartOfTheFrame) {
  // A 640x480 camera seeing the left 70 % of a 320x200 projector at 2 camera pixels per
  // projector pixel, rotated a little; white = black + the projector's bowl.
  const cv::Size fb(320, 200);
  cv::Mat white(480, 640, CV_16UC1), black(480, 640, CV_16UC1, cv::Scalar(120));
  cv::Mat u(480, 640, CV_32FC1), v(480, 640, CV_32FC1), mask(480, 640, CV_8UC1);
  const double c = std::cos(0.05), s = std::sin(0.05);
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      const double pu = 0.5 * (c * x - s * y) - 12, pv = 0.5 * (s * x + c * y) - 30;
      const bool seen = pu >= 0 && pv >= 0 && pu <= 0.7 * (fb.width - 1) && pv <= fb.height - 1;
      u.at<float>(y, x) = static_cast<float>(pu);
      v.at<float>(y, x) = static_cast<float>(pv);
      mask.at<uint8_t>(y, x) = seen ? 255 : 0;
      white.at<uint16_t>(y, x) =
          static_cast<uint16_t>(std::lround(120 + (seen ? bowl(3000, Vec2(pu, pv), fb) : 0)));
    }
  }
  auto map = measureBrightness(white, black, u, v, mask, fb, 16);
  ASSERT_TRUE(map) << map.error().message;
  ASSERT_EQ(map->white.cols, brightnessNodes(320, 16));
  ASSERT_EQ(map->white.rows, brightnessNodes(200, 16));
  // Seen interior nodes: the mean of the bowl over the node's cell, whose curvature
  // moves it by 0.4 (8/320)^2 / 3 of the peak at most, and 0.5 code of rounding: 0.05 %.
  double seen_worst = 0, filled_lo = 1e9, filled_hi = 0;
  for (int j = 1; j + 1 < map->white.rows; ++j) {
    for (int i = 1; i + 1 < map->white.cols; ++i) {
      const Vec2 px(i * 16, j * 16);
      const double truth = bowl(3000, px, fb), got = map->white.at<float>(j, i);
      if (px.x() + 8 < 0.7 * 319 - 1) {
        seen_worst = std::max(seen_worst, std::abs(got / truth - 1));
      } else if (px.x() > 0.7 * 319 + 16) {
        filled_lo = std::min(filled_lo, got);
        filled_hi = std::max(filled_hi, got);
      }
    }
  }
  EXPECT_LT(seen_worst, 5e-4);
  // Unseen nodes take their seen neighbours' light: within the seen range.
  EXPECT_GT(filled_lo, 0.8 * 3000);
  EXPECT_LT(filled_hi, 3000);
  EXPECT_NEAR(brightnessAt(*map, Vec2(40, 40)), bowl(3000, Vec2(40, 40), fb), 3000 * 1e-3);

  // Typed errors.
  EXPECT_EQ(measureBrightness(white, black, u, v, mask, cv::Size(1, 200)).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(measureBrightness(white, black, u, v, mask, fb, 2).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(measureBrightness(white, cv::Mat(480, 640, CV_8UC1), u, v, mask, fb).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(measureBrightness(white, black, u, v, cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)), fb)
                .error()
                .code,
            ErrorCode::kTooFewPoints);
}

TEST(BrightnessMap, JsonRoundTripAndRecordsThatAreNotOne) {
  const BrightnessMap m = exactMap(11.0, cv::Size(1280, 800), 32);
  const nlohmann::json j = brightnessToJson(m);
  auto back = brightnessFromJson(j);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->step, 32);
  EXPECT_EQ(back->width, 1280);
  EXPECT_EQ(back->height, 800);
  EXPECT_EQ(cv::norm(back->white, m.white, cv::NORM_INF), 0.0);
  const auto broken = [&](const char* key, const nlohmann::json& value) {
    nlohmann::json b = j;
    b[key] = value;
    return brightnessFromJson(b);
  };
  for (const auto& [key, value] :
       std::vector<std::pair<const char*, nlohmann::json>>{{"step", 0},
                                                           {"step", 1000},
                                                           {"width", 1},
                                                           {"height", 1e9},
                                                           {"cols", 3},
                                                           {"rows", "26"},
                                                           {"white", nlohmann::json::array()},
                                                           {"white", "none"}}) {
    auto r = broken(key, value);
    ASSERT_FALSE(r) << key << " = " << value.dump();
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  }
  for (const nlohmann::json& bad :
       {nlohmann::json(-1.0), nlohmann::json(0.0), nlohmann::json(nullptr), nlohmann::json("x")}) {
    nlohmann::json b = j;
    b["white"][17] = bad;
    EXPECT_FALSE(brightnessFromJson(b)) << bad.dump();
  }
  EXPECT_FALSE(brightnessFromJson(nlohmann::json::array()));
}

// Two 240x200 projectors side by side on a 400x200 content, overlapping over content
// x in [160, 240), one 40 % brighter than the other, each with its own fall-off.
struct TwoProjectors {
  cv::Size fb{240, 200};
  cv::Size content{400, 200};
  BrightnessMap left = exactMap(10.0, fb), right = exactMap(14.0, fb);
  cv::Mat w_left, w_right;
  std::vector<MatchProjector> match;
  explicit TwoProjectors(bool step_in_weights) {
    w_left = cv::Mat(fb, CV_32FC1);
    w_right = cv::Mat(fb, CV_32FC1);
    for (int y = 0; y < fb.height; ++y) {
      for (int x = 0; x < fb.width; ++x) {
        // Content x of left pixel x is x; of right pixel x is x + 160.
        const double t = std::clamp((x - 160.0) / 80.0, 0.0, 1.0);  // right's share at x
        double a = 1 - t;
        // Weights that jump (still summing to one): the matched light must not.
        if (step_in_weights && x >= 180 && x < 200) a = std::clamp(a + 0.2, 0.0, 1.0);
        w_left.at<float>(y, x) = static_cast<float>(a);
        const double tr = std::clamp((x + 160 - 160.0) / 80.0, 0.0, 1.0);
        double b = tr;
        if (step_in_weights && x + 160 >= 180 && x + 160 < 200)
          b = 1 - std::clamp((1 - tr) + 0.2, 0.0, 1.0);
        w_right.at<float>(y, x) = static_cast<float>(b);
      }
    }
    match.push_back({&w_left, &left, [](const Vec2& p) { return std::optional<Vec2>(p); }});
    match.push_back(
        {&w_right, &right, [](const Vec2& p) { return std::optional<Vec2>(p + Vec2(160, 0)); }});
  }
  // Light at content pixel (x, y) from the matched weights and the true brightness.
  double light(const LuminanceMatch& m, int x, int y) const {
    double sum = 0;
    if (x < fb.width) sum += m.weights[0].at<float>(y, x) * bowl(10.0, Vec2(x, y), fb);
    if (x >= 160) sum += m.weights[1].at<float>(y, x - 160) * bowl(14.0, Vec2(x - 160, y), fb);
    return sum;
  }
};

TEST(LuminanceMatch, ProjectorsOfDifferentBrightnessLightASmoothTarget) {
  for (bool step : {false, true}) {
    SCOPED_TRACE(step ? "weights with a step" : "linear ramps");
    const TwoProjectors rig(step);
    LuminanceMatchOptions options;
    options.cells = 100;  // 4 content px
    options.gradient_per_px = 1e-3;
    auto m = matchLuminance(rig.match, rig.content, options);
    ASSERT_TRUE(m) << m.error().message;
    ASSERT_EQ(m->weights.size(), 2u);
    double worst_step = 0, lo = 1e9, hi = 0;
    for (int y = 2; y < 198; ++y) {
      for (int x = 2; x < 397; ++x) {
        const double l = rig.light(*m, x, y), r = rig.light(*m, x + 1, y);
        ASSERT_GT(l, 0);
        worst_step = std::max(worst_step, std::abs(r / l - 1));
        lo = std::min(lo, l);
        hi = std::max(hi, l);
      }
    }
    for (const cv::Mat& w : m->weights) {
      double wmin = 0, wmax = 0;
      cv::minMaxLoc(w, &wmin, &wmax);
      EXPECT_GE(wmin, 0);
      EXPECT_LE(wmax, 1);
    }
    // The target changes by 0.1 % per content px at most; the light follows it within
    // the bilinear interpolation of the 4 px raster between cell centres.
    std::printf(
        "[ figures  ] %s: largest step %.4f %% per px, uniformity %.3f -> %.3f "
        "(measured %.3f), light kept %.3f\n",
        step ? "stepped weights" : "ramps", 100 * worst_step,
        m->figures.before_min / m->figures.before_max, m->figures.after_min / m->figures.after_max,
        lo / hi, m->figures.kept);
    EXPECT_LT(worst_step, 1.5e-3);
    EXPECT_LE(m->figures.largest_step, 1e-3 * (1 + 1e-9));
    EXPECT_GT(m->figures.after_min / m->figures.after_max,
              m->figures.before_min / m->figures.before_max);
    EXPECT_GT(m->figures.kept, 0.5);
    EXPECT_LE(m->figures.kept, 1.2);
    EXPECT_NEAR(lo / hi, m->figures.after_min / m->figures.after_max, 0.02);
  }
}

// Brightness compares only within one camera's exposure: responses two cameras measured
// keep their gammas but are not matched, and the tables say why.
TEST(LuminanceMatch, ResponsesFromDifferentCamerasAreNotMatched) {
  const TwoProjectors rig(false);
  std::vector<std::optional<ProjectorResponse>> responses(2);
  for (std::size_t t = 0; t < 2; ++t) {
    ProjectorResponse r;
    r.gamma = 2.0 + 0.4 * t;
    r.white = 100.0 + 40.0 * t;
    r.brightness = t == 0 ? rig.left : rig.right;
    r.camera = t == 0 ? "cam_a" : "cam_b";
    responses[t] = r;
  }
  std::vector<ContentOf> to_content;
  for (const auto& p : rig.match) to_content.push_back(p.to_content);
  auto apart =
      blendTables({rig.w_left.clone(), rig.w_right.clone()}, responses, to_content, rig.content);
  ASSERT_TRUE(apart) << apart.error().message;
  EXPECT_TRUE(apart->different_cameras);
  EXPECT_FALSE(apart->matched);
  EXPECT_EQ(apart->gain, std::vector<double>({1.0, 1.0}));
  EXPECT_EQ(apart->gamma, std::vector<double>({2.0, 2.4}));
  EXPECT_EQ(matchingJson(*apart)["matching"], "none");
  // One camera: matched per pixel.
  responses[1]->camera = "cam_a";
  auto together =
      blendTables({rig.w_left.clone(), rig.w_right.clone()}, responses, to_content, rig.content);
  ASSERT_TRUE(together) << together.error().message;
  EXPECT_TRUE(together->matched);
  EXPECT_EQ(matchingJson(*together)["matching"], "per-pixel");
}

TEST(LuminanceMatch, BadInputIsRefused) {
  const TwoProjectors rig(false);
  EXPECT_EQ(matchLuminance({}, rig.content).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(matchLuminance(rig.match, cv::Size(0, 10)).error().code, ErrorCode::kInvalidInput);
  LuminanceMatchOptions bad;
  bad.gradient_per_px = std::nan("");
  EXPECT_EQ(matchLuminance(rig.match, rig.content, bad).error().code, ErrorCode::kInvalidInput);
  bad = {};
  bad.cells = 4;
  EXPECT_EQ(matchLuminance(rig.match, rig.content, bad).error().code, ErrorCode::kInvalidInput);
  std::vector<MatchProjector> wrong = rig.match;
  const BrightnessMap small = exactMap(10.0, cv::Size(100, 100));
  wrong[1].brightness = &small;
  EXPECT_EQ(matchLuminance(wrong, rig.content).error().code, ErrorCode::kInvalidInput);
  wrong = rig.match;
  wrong[0].to_content = nullptr;
  EXPECT_EQ(matchLuminance(wrong, rig.content).error().code, ErrorCode::kInvalidInput);
  wrong = rig.match;
  for (auto& p : wrong) p.to_content = [](const Vec2&) { return std::optional<Vec2>(); };
  EXPECT_EQ(matchLuminance(wrong, rig.content).error().code, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace procam::blend
