// procamd (not --sim) discovers its devices through libudev: run under
// `umockdev-wrapper`, whose test bed the daemon inherits (LD_PRELOAD and
// UMOCKDEV_DIR), so the fake devices added here are what libudev shows it.
#include <gtest/gtest.h>
#include <umockdev.h>

#include <cstdlib>
#include <map>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

bool underUmockdev() {
  const char* preload = std::getenv("LD_PRELOAD");
  return preload && std::string(preload).find("umockdev") != std::string::npos;
}

TEST(UdevDaemon, DevicesListsWhatTheRulesClassified) {
  if (!underUmockdev()) GTEST_SKIP() << "needs umockdev-wrapper (ctest runs it so)";
  UMockdevTestbed* bed = umockdev_testbed_new();
  umockdev_testbed_add_device(bed, "iio", "iio:device0", nullptr, "name", "accel_3d",
                              "in_accel_x_raw", "12", nullptr, "DEVNAME", "/dev/iio:device0",
                              "PROCAM_ROLE", "tilt", nullptr);
  umockdev_testbed_add_device(bed, "video4linux", "video0", nullptr, "name", "Cam", nullptr,
                              "DEVNAME", "/dev/video0", "PROCAM_ROLE", "camera", nullptr);
  umockdev_testbed_add_device(bed, "hidraw", "hidraw0", nullptr, "dev", "240:0", nullptr, "DEVNAME",
                              "/dev/hidraw0", nullptr);
  {
    TempDir dir;
    // The fixture plugin's constant-tilt driver accepts any PROCAM_ROLE=tilt device.
    DaemonProcess d(dir, DaemonProcess::Launch{{"--plugin-dir", PROCAM_FIXTURE_DIR}, {}, -1, true});
    ASSERT_TRUE(d.started()) << d.log();
    Connection c(d.socketPath());
    auto reply = c.call({{"cmd", "devices"}});
    ASSERT_TRUE(reply);
    std::map<std::string, json> by_name;
    for (const auto& dev : (*reply)["devices"]) by_name[dev["name"]] = dev;
    ASSERT_EQ(by_name.size(), 2u) << reply->dump();  // hidraw0 has no role
    const json& tilt = by_name["iio:device0"];
    EXPECT_EQ(tilt["family"], "tilt");
    EXPECT_EQ(tilt["subsystem"], "iio");
    EXPECT_EQ(tilt["devnode"], "/dev/iio:device0");
    EXPECT_EQ(tilt["syspath"], "/sys/devices/iio:device0");
    // The best-scoring driver: constant-tilt (10) unless an in-tree IIO
    // driver scores higher; either way one was chosen by score.
    EXPECT_FALSE(tilt["driver"].is_null()) << tilt.dump();
    EXPECT_GE(tilt.value("score", 0), 10) << tilt.dump();
    // The v4l2 driver claims the camera by its role and node name, and opening
    // fails cleanly: the test bed has the udev record but no device node.
    const json& cam = by_name["video0"];
    EXPECT_EQ(cam["state"], "error");
    EXPECT_EQ(cam["driver"], "v4l2") << cam.dump();
    EXPECT_NE(cam.value("error", "").find("/dev/video0"), std::string::npos) << cam.dump();
  }
  g_object_unref(bed);
}

}  // namespace
}  // namespace procam::itest
