#include <gtest/gtest.h>

#include <set>

#include "structured_light/gray_code.hpp"
#include "structured_light/pattern_set.hpp"

using namespace procam;
using namespace procam::sl;

TEST(GrayCode, RoundTripAndOneBitPerStep) {
  for (std::uint32_t i = 0; i < 5000; ++i) {
    EXPECT_EQ(fromGray(toGray(i)), i);
    EXPECT_EQ(std::popcount(toGray(i) ^ toGray(i + 1)), 1);
  }
  EXPECT_EQ(bitsFor(1), 0);
  EXPECT_EQ(bitsFor(2), 1);
  EXPECT_EQ(bitsFor(1024), 10);
  EXPECT_EQ(bitsFor(1025), 11);
}

TEST(PatternSet, GrayFrameCountsAndNames) {
  auto set = makePatternSet({.width = 1024, .height = 768});
  ASSERT_TRUE(set);
  EXPECT_EQ(set->columns.bits, 10);
  EXPECT_EQ(set->rows.bits, 10);  // 768 cells need 10 bits
  EXPECT_EQ(set->frames.size(), 2u + 2 * 10 + 2 * 10);
  std::set<std::string> names;
  for (const auto& f : set->frames) names.insert(f.name);
  EXPECT_EQ(names.size(), set->frames.size());
  EXPECT_EQ(set->frames[0].name, "00_white");
  EXPECT_EQ(set->frames[3].name, "03_col_gray_00_inv");
}

TEST(PatternSet, StepDropsLowBits) {
  for (int step : {1, 2, 4, 8, 16}) {
    auto set = makePatternSet({.width = 1024, .height = 768, .step = step});
    ASSERT_TRUE(set);
    EXPECT_EQ(set->columns.cells, 1024 / step);
    EXPECT_EQ(set->columns.bits, bitsFor(static_cast<std::uint32_t>(1024 / step)));
  }
}

TEST(PatternSet, ColumnCodesAreGrayAndInverseIsComplement) {
  auto set = makePatternSet({.width = 300, .height = 20, .step = 3});
  ASSERT_TRUE(set);
  std::vector<std::uint32_t> code(300, 0);
  for (int b = 0; b < set->columns.bits; ++b) {
    const cv::Mat p = renderFrame(*set, findFrame(*set, FrameKind::kGray, Axis::kColumns, b));
    const cv::Mat q =
        renderFrame(*set, findFrame(*set, FrameKind::kGrayInverse, Axis::kColumns, b));
    ASSERT_EQ(p.size(), cv::Size(300, 20));
    for (int x = 0; x < 300; ++x) {
      EXPECT_EQ(p.at<std::uint8_t>(7, x) + q.at<std::uint8_t>(7, x), 255);
      EXPECT_EQ(p.at<std::uint8_t>(0, x), p.at<std::uint8_t>(19, x));
      code[x] = (code[x] << 1) | (p.at<std::uint8_t>(0, x) > 0);
    }
  }
  for (int x = 0; x < 300; ++x) EXPECT_EQ(fromGray(code[x]), static_cast<std::uint32_t>(x / 3));
}

TEST(PatternSet, PhaseFramesFollowTheSinusoid) {
  auto set = makePatternSet({.width = 256,
                             .height = 64,
                             .mode = Mode::kGrayPhase,
                             .phase_steps = 4,
                             .phase_period = 32,
                             .projector_gamma = 1.0});
  ASSERT_TRUE(set);
  EXPECT_EQ(set->columns.cell, 8);
  EXPECT_EQ(set->columns.bits, 5);  // 32 cells
  EXPECT_EQ(set->rows.bits, 3);     // 8 cells
  EXPECT_EQ(set->frames.size(), 2u + (2 * 5 + 4) + (2 * 3 + 4));
  const cv::Mat f = renderFrame(*set, findFrame(*set, FrameKind::kPhase, Axis::kRows, 1));
  for (int y = 0; y < 64; ++y) {
    const double expected = 255 * (0.5 + 0.5 * std::cos(2 * M_PI * (y / 32.0 - 0.25)));
    EXPECT_NEAR(f.at<std::uint8_t>(y, 10), expected, 0.5 + 1e-9);
  }
  // A large step raises the period so unwrapping stays unambiguous.
  auto coarse = makePatternSet({.width = 256, .height = 64, .mode = Mode::kGrayPhase, .step = 16});
  ASSERT_TRUE(coarse);
  EXPECT_EQ(coarse->columns.period, 64);
  EXPECT_EQ(coarse->columns.cell, 16);
}

TEST(PatternSet, RejectsInvalidOptions) {
  EXPECT_FALSE(makePatternSet({.width = 0, .height = 10}));
  EXPECT_FALSE(makePatternSet({.width = 10, .height = 10, .step = 0}));
  EXPECT_FALSE(
      makePatternSet({.width = 10, .height = 10, .mode = Mode::kGrayPhase, .phase_steps = 2}));
  EXPECT_FALSE(makePatternSet({.width = 10, .height = 10, .projector_gamma = 0}));
  EXPECT_EQ(makePatternSet({.width = 10, .height = 10, .step = -1}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_TRUE(parseMode("gray+phase"));
  EXPECT_FALSE(parseMode("phase"));
}
