// The virtual rig's mock drivers through the plugin ABI: the tilt sensor
// reports gravity, the camera sees what the mock projector shows.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "loader.hpp"
#include "registry.hpp"
#include "sim_plugin.hpp"

namespace procam::plugins {
namespace {

DeviceDescription simDevice(procam_family family, const char* name) {
  DeviceDescription d;
  d.family = family;
  d.subsystem = "sim";
  d.name = name;
  d.properties = {{"SIM_SCENE", "handheld"}, {"SIM_DEVICE", name}};
  return d;
}

DriverRegistry simRegistry() {
  static const StaticPlugin plugins[] = {{"sim", &procam_sim_plugin_entry}};
  auto drivers = loadStaticPlugins(plugins);
  EXPECT_TRUE(drivers);
  DriverRegistry r;
  for (const auto& d : *drivers) r.add(d);
  return r;
}

Device open(const DriverRegistry& r, DeviceDescription desc) {
  auto match = r.bestMatch(desc);
  EXPECT_TRUE(match);
  EXPECT_EQ(match->score, 100);
  auto dev = createDevice(match->driver, desc, {});
  EXPECT_TRUE(dev) << dev.error().message;
  return std::move(*dev);
}

TEST(SimDrivers, TiltReportsGravityMagnitude) {
  auto r = simRegistry();
  Device tilt = open(r, simDevice(PROCAM_FAMILY_TILT, "accel"));
  procam_tilt_sample s{};
  char err[256] = {};
  ASSERT_EQ(tilt.raw().ops.tilt->read(tilt.raw().self, &s, err, sizeof err), PROCAM_OK) << err;
  const double norm = std::hypot(s.specific_force[0], s.specific_force[1], s.specific_force[2]);
  // handheld.toml: 50 mg bias per axis (<= 0.087 g in norm) and 400 ug/sqrt(Hz)
  // noise; 0.1 g covers both with margin.
  EXPECT_NEAR(norm, 9.80665, 0.1 * 9.80665);
}

TEST(SimDrivers, CameraSeesWhiteBrighterThanBlack) {
  auto r = simRegistry();
  Device out = open(r, simDevice(PROCAM_FAMILY_OUTPUT, "proj"));
  Device cam = open(r, simDevice(PROCAM_FAMILY_CAMERA, "cam"));
  uint32_t w = 0, h = 0;
  double hz = 0;
  ASSERT_EQ(out.raw().ops.output->get_mode(out.raw().self, &w, &h, &hz), PROCAM_OK);
  ASSERT_EQ(w, 1280u);
  ASSERT_EQ(h, 720u);
  auto meanWith = [&](uint8_t level) {
    std::vector<uint8_t> px(static_cast<size_t>(w) * h * 3, level);
    procam_image frame{w, h, w * 3, PROCAM_PIXEL_RGB8, px.data(), 0};
    char err[256] = {};
    EXPECT_EQ(out.raw().ops.output->show(out.raw().self, &frame, err, sizeof err), PROCAM_OK)
        << err;
    procam_image img{};
    EXPECT_EQ(cam.raw().ops.camera->capture(cam.raw().self, 1000, &img, err, sizeof err), PROCAM_OK)
        << err;
    const size_t n = static_cast<size_t>(img.stride) * img.height;
    return std::accumulate(img.data, img.data + n, 0.0) / static_cast<double>(n);
  };
  const double black = meanWith(0), white = meanWith(255);
  EXPECT_GT(white, black + 10.0) << "black " << black << " white " << white;
}

TEST(SimDrivers, UnknownDeviceIsRefusedWithTheSceneName) {
  auto r = simRegistry();
  auto desc = simDevice(PROCAM_FAMILY_TILT, "gyro");
  auto match = r.bestMatch(desc);
  ASSERT_TRUE(match);
  auto dev = createDevice(match->driver, desc, {});
  ASSERT_FALSE(dev);
  EXPECT_NE(dev.error().message.find("has no such device 'gyro'"), std::string::npos)
      << dev.error().message;
}

}  // namespace
}  // namespace procam::plugins
