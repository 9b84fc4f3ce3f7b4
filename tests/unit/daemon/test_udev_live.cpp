// Discovery through the real libudev on fake devices (umockdev): run under
// `umockdev-wrapper`, which redirects libudev to a test bed in which this
// test adds sysfs devices with the properties procamd's rules would give.
// The test bed's monitor socket never becomes readable, so hotplug is tested
// by calling the handler (test_device_manager.cpp).
#include <gtest/gtest.h>
#include <umockdev.h>

#include <cstdlib>
#include <map>
#include <string>

#include "device_manager.hpp"
#include "fake_drivers.hpp"
#include "udev_monitor.hpp"

namespace procam::daemon {
namespace {

bool underUmockdev() {
  const char* preload = std::getenv("LD_PRELOAD");
  return preload && std::string(preload).find("umockdev") != std::string::npos;
}

class UdevLive : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!underUmockdev()) GTEST_SKIP() << "needs umockdev-wrapper (ctest runs it so)";
    bed_ = umockdev_testbed_new();
    // An IIO accelerometer the rules classify as a tilt sensor, a V4L2 camera
    // no driver of this test claims, and a hidraw device without a role.
    umockdev_testbed_add_device(bed_, "iio", "iio:device0", nullptr, "name", "accel_3d",
                                "in_accel_x_raw", "12", nullptr, "DEVNAME", "/dev/iio:device0",
                                "PROCAM_ROLE", "tilt", "ID_VENDOR_ID", "1234", nullptr);
    umockdev_testbed_add_device(bed_, "video4linux", "video0", nullptr, "name", "Cam", nullptr,
                                "DEVNAME", "/dev/video0", "ID_V4L_CAPABILITIES",
                                ":capture:", "PROCAM_ROLE", "camera", nullptr);
    umockdev_testbed_add_device(bed_, "hidraw", "hidraw0", nullptr, "dev", "240:0", nullptr,
                                "DEVNAME", "/dev/hidraw0", nullptr);
  }
  void TearDown() override {
    if (bed_) g_object_unref(bed_);
  }
  UMockdevTestbed* bed_ = nullptr;
};

TEST_F(UdevLive, EnumerationSeesTheRulesProperties) {
  auto udev = Udev::create();
  ASSERT_TRUE(udev) << udev.error().message;
  auto records = udev->enumerate();
  ASSERT_TRUE(records) << records.error().message;
  std::map<std::string, UdevRecord> by_name;
  for (const auto& r : *records) by_name[r.sysname] = r;
  ASSERT_EQ(by_name.size(), 3u);
  const UdevRecord& iio = by_name["iio:device0"];
  EXPECT_EQ(iio.subsystem, "iio");
  EXPECT_EQ(iio.devnode, "/dev/iio:device0");
  EXPECT_EQ(iio.syspath, "/sys/devices/iio:device0");
  EXPECT_EQ(iio.property("PROCAM_ROLE"), "tilt");
  EXPECT_EQ(iio.property("ID_VENDOR_ID"), "1234");
  auto desc = describeUdevDevice(iio);
  ASSERT_TRUE(desc);
  EXPECT_EQ(desc->family, PROCAM_FAMILY_TILT);
  EXPECT_FALSE(describeUdevDevice(by_name["hidraw0"]));
}

TEST_F(UdevLive, StartOpensClaimedDevicesAndListsTheOthersWithTheReason) {
  auto loop = EventLoop::create();
  ASSERT_TRUE(loop);
  const auto registry = fake::registry();
  DeviceSet devices;
  std::vector<std::string> warnings;
  {
    DeviceManager manager(
        **loop, registry, devices, [](const std::string&, nlohmann::json) {},
        [&](const std::string& m) { warnings.push_back(m); });
    manager.start({});
    EXPECT_TRUE(manager.monitoring());        // created; umockdev never makes it readable
    ASSERT_EQ(devices.entries().size(), 2u);  // hidraw0 has no role
    const DeviceEntry* tilt = devices.find("iio:device0");
    ASSERT_NE(tilt, nullptr);
    EXPECT_TRUE(tilt->usable());
    EXPECT_EQ(tilt->driver, "fake-tilt");
    EXPECT_EQ(tilt->score, 20);
    EXPECT_EQ(tilt->description.syspath, "/sys/devices/iio:device0");
    const DeviceEntry* cam = devices.find("video0");
    ASSERT_NE(cam, nullptr);
    EXPECT_FALSE(cam->usable());
    EXPECT_EQ(cam->error, "no camera driver accepts this device");
    EXPECT_TRUE(warnings.empty()) << warnings.front();
  }
}

}  // namespace
}  // namespace procam::daemon
