#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/units.hpp"
#include "keystone/orientation.hpp"
#include "keystone_command.hpp"

namespace procam::keystone_cli {
namespace {

std::vector<std::string> base() {
  return {"--size", "1920x1080", "--intrinsics", "1600,1600,959.5,539.5", "--json"};
}

keystone::KeystoneSolution solve(std::vector<std::string> extra) {
  auto args = base();
  args.insert(args.end(), extra.begin(), extra.end());
  auto parsed = parseSolveArgs(args);
  EXPECT_TRUE(parsed) << parsed.error().message;
  auto s = keystone::solveKeystone(parsed->problem);
  EXPECT_TRUE(s) << s.error().message;
  return *s;
}

TEST(KeystoneCli, AngleAndVectorFormsAgree) {
  const keystone::Angles a{12 * kDeg, -7 * kDeg, 18 * kDeg};
  const Mat3 R = keystone::rotationFromAngles(a);
  const Vec3 down = R * Vec3(0, 0, -1), normal = R * Vec3::UnitY();
  auto str = [](const Vec3& v) {
    return std::to_string(v.x()) + "," + std::to_string(v.y()) + "," + std::to_string(v.z());
  };
  const auto by_angles = solve({"--pitch", "12", "--roll", "-7", "--yaw", "18"});
  const auto by_vectors = solve({"--down", str(down), "--wall-normal", str(-normal)});
  // to_string keeps 6 decimals: directions agree to ~1e-6 rad -> ~2e-3 px at f = 1600.
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR((by_angles.corners[i] - by_vectors.corners[i]).norm(), 0, 5e-3);
}

TEST(KeystoneCli, JsonHasTheDocumentedShape) {
  auto parsed = parseSolveArgs([] {
    auto a = base();
    a.insert(a.end(), {"--pitch", "15", "--roll", "0", "--aspect", "4:3"});
    return a;
  }());
  ASSERT_TRUE(parsed);
  EXPECT_EQ(parsed->problem.content_width, 1440);
  EXPECT_EQ(parsed->problem.content_height, 1080);
  auto s = keystone::solveKeystone(parsed->problem);
  ASSERT_TRUE(s);
  const auto j = nlohmann::json::parse(formatSolution(*s, true));
  ASSERT_EQ(j.at("homography").size(), 9u);
  ASSERT_EQ(j.at("corners").size(), 4u);
  EXPECT_DOUBLE_EQ(j.at("scale").get<double>(), s->scale);
  // Row-major content -> framebuffer: applying it to the content's top-left edge corner
  // gives the first corner.
  Mat3 H;
  for (int k = 0; k < 9; ++k) H(k / 3, k % 3) = j["homography"][k].get<double>();
  const Vec2 tl = (H * Vec3(-0.5, -0.5, 1)).hnormalized();
  EXPECT_NEAR(tl.x(), j["corners"][0][0].get<double>(), 1e-9);
  EXPECT_NEAR(tl.y(), j["corners"][0][1].get<double>(), 1e-9);
}

TEST(KeystoneCli, SingleSensorModes) {
  // Tilt only: yaw taken as 0. Camera only: roll taken as 0.
  const Mat3 Rt = keystone::rotationFromAngles({10 * kDeg, 5 * kDeg, 0});
  const Vec3 d = Rt * Vec3(0, 0, -1);
  const auto tilt_only = solve({"--down", std::to_string(d.x()) + "," + std::to_string(d.y()) +
                                              "," + std::to_string(d.z())});
  const auto angles = solve({"--pitch", "10", "--roll", "5"});
  EXPECT_NEAR((tilt_only.corners[2] - angles.corners[2]).norm(), 0, 5e-3);
  const auto camera_only = solve({"--wall-normal", "0,0,1"});
  EXPECT_NEAR(camera_only.scale, 1, 1e-12);
}

TEST(KeystoneCli, UsageErrors) {
  auto with = [](std::vector<std::string> extra) {
    auto a = base();
    a.insert(a.end(), extra.begin(), extra.end());
    return parseSolveArgs(a);
  };
  EXPECT_EQ(with({}).error().code, ErrorCode::kParse);  // no orientation
  EXPECT_EQ(with({"--pitch", "1"}).error().code, ErrorCode::kParse);
  EXPECT_EQ(with({"--pitch", "x", "--roll", "0"}).error().code, ErrorCode::kParse);
  EXPECT_EQ(with({"--pitch", "1", "--roll", "0", "--down", "0,1,0"}).error().code,
            ErrorCode::kParse);
  EXPECT_EQ(with({"--pitch", "1", "--roll", "0", "--anchor", "left"}).error().code,
            ErrorCode::kParse);
  EXPECT_EQ(with({"--down", "0,0"}).error().code, ErrorCode::kParse);
  EXPECT_EQ(with({"--down", "0,0,0"}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(
      parseSolveArgs({"--size", "0x5", "--intrinsics", "1,1,0,0", "--pitch", "0", "--roll", "0"})
          .error()
          .code,
      ErrorCode::kParse);
}

}  // namespace
}  // namespace procam::keystone_cli
