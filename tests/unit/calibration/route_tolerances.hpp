#pragma once
// Route (a) accuracy bounds for a calibrated projector against the truth:
// focal 0.5%, principal point 2 px, position 2 mm, rotation 0.05 degrees.
#include <gtest/gtest.h>

#include <cmath>

#include "calibration/projector_calibration.hpp"

namespace procam::testing {

inline double rotationErrorDeg(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / M_PI;
}

inline void expectMatches(const calib::ProjectorCalibration& c, const geom::CameraModel& truth) {
  EXPECT_NEAR(c.K.fx, truth.K.fx, 0.005 * truth.K.fx);
  EXPECT_NEAR(c.K.fy, truth.K.fy, 0.005 * truth.K.fy);
  EXPECT_NEAR(c.K.cx, truth.K.cx, 2.0);
  EXPECT_NEAR(c.K.cy, truth.K.cy, 2.0);
  EXPECT_LT((c.pose.center() - truth.pose.center()).norm(), 0.002);
  EXPECT_LT(rotationErrorDeg(c.pose.R, truth.pose.R), 0.05);
}

}  // namespace procam::testing
