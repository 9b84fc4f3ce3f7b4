// The six still holds of the accelerometer calibration, collected one at a time
// (keystone/six_position.hpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/units.hpp"
#include "keystone/six_position.hpp"

namespace procam::keystone {
namespace {

TEST(SixPositionCollector, SixHoldsRecoverOffsetAndGain) {
  AccelCalibration truth;
  truth.offset = Vec3(0.03, -0.02, 0.05);
  truth.scale = Vec3(1.02, 0.97, 1.01);
  SixPositionCollector holds;
  const char* names[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (int i = 0; i < 6; ++i) {
    const Vec3 up = (i % 2 ? -1.0 : 1.0) * Vec3::Unit(i / 2);
    // Held 3 degrees off vertical: still accepted.
    const Vec3 f = Eigen::AngleAxisd(3 * kDeg, Vec3::Unit((i / 2 + 1) % 3)) * up;
    auto pose = holds.add(truth.scale.cwiseProduct(f) + truth.offset);
    ASSERT_TRUE(pose) << pose.error().message;
    EXPECT_EQ(*pose, names[i]);
    if (i == 4) {
      EXPECT_EQ(holds.missing(), std::vector<std::string>({"-z"}));
      EXPECT_EQ(holds.solve().error().code, ErrorCode::kTooFewPoints);
    }
  }
  auto fit = holds.solve();
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_LT((fit->calibration.offset - truth.offset).norm(), 1e-6);
  EXPECT_LT((fit->calibration.scale - truth.scale).norm(), 1e-6);
  // 45 degrees from every axis: not a hold of the procedure.
  EXPECT_FALSE(holds.add(Vec3(1, 1, 0).normalized()));
}

}  // namespace
}  // namespace procam::keystone
