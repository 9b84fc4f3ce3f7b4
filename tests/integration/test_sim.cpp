// procamd --sim: the whole daemon on the virtual rig's mock drivers.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

DaemonProcess::Launch sim(const std::vector<std::string>& extra = {}) {
  DaemonProcess::Launch l{{"--sim"}, {}, -1, true};
  l.args.insert(l.args.end(), extra.begin(), extra.end());
  return l;
}

TEST(Sim, DefaultSceneListsTheHandheldRig) {
  TempDir dir;
  DaemonProcess d(dir, sim());
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["sim"], "handheld");
  // tests/scenes/handheld.toml: projector "proj", camera "cam", accelerometer "accel".
  EXPECT_EQ((*status)["devices"],
            json({{"output", 1}, {"camera", 1}, {"tilt", 1}, {"tracker", 0}}));
  auto devices = c.call({{"cmd", "devices"}});
  ASSERT_TRUE(devices);
  std::map<std::string, std::string> driver_of;
  for (const auto& dev : (*devices)["devices"]) {
    EXPECT_EQ(dev["state"], "open") << dev.dump();
    driver_of[dev["name"]] = dev["driver"];
  }
  EXPECT_EQ(driver_of, (std::map<std::string, std::string>{
                           {"proj", "sim-output"}, {"cam", "sim-camera"}, {"accel", "sim-tilt"}}));
}

TEST(Sim, PatternIsShownOnTheMockProjector) {
  TempDir dir;
  DaemonProcess d(dir, sim({"handheld"}));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto p = c.call({{"cmd", "pattern"}, {"name", "grid"}});
  ASSERT_TRUE(p);
  EXPECT_EQ((*p)["shown"], true);
}

TEST(Sim, KeystoneHomographyMapsTheFrameCornersOntoTheSetCorners) {
  TempDir dir;
  DaemonProcess d(dir, sim());
  ASSERT_TRUE(d.started());
  Connection c(d.socketPath());
  const json corners = {{40, 20}, {1250, 5}, {1279, 719}, {0, 690}};
  auto k = c.call({{"cmd", "keystone"}, {"action", "set"}, {"corners", corners}});
  ASSERT_TRUE(k);
  ASSERT_EQ((*k)["output_size"], json({1280, 720}));
  const json& H = (*k)["homography"];
  ASSERT_EQ(H.size(), 3u);
  // dst ~ H * src for the frame's corner pixel centres ([Raskar02] §3.2.5); exact up
  // to rounding of a 4-point solve, so 1e-6 px.
  const double src[4][2] = {{0, 0}, {1279, 0}, {1279, 719}, {0, 719}};
  for (int i = 0; i < 4; ++i) {
    double v[3];
    for (int r = 0; r < 3; ++r) {
      v[r] = H[r][0].get<double>() * src[i][0] + H[r][1].get<double>() * src[i][1] +
             H[r][2].get<double>();
    }
    EXPECT_NEAR(v[0] / v[2], corners[i][0].get<double>(), 1e-6) << i;
    EXPECT_NEAR(v[1] / v[2], corners[i][1].get<double>(), 1e-6) << i;
  }
}

TEST(Sim, UnknownSceneStopsStartupListingTheShippedOnes) {
  TempDir dir;
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "no_such_scene"}, {}, -1, false});
  EXPECT_EQ(d.wait(), 1);
  EXPECT_NE(d.log().find("handheld"), std::string::npos) << d.log();
}

}  // namespace
}  // namespace procam::itest
