// PROCAM_SIM_UNPLUG: the virtual rig's devices can be unplugged for a window.
#include <gtest/gtest.h>

#include <cstdlib>

#include "loader.hpp"
#include "registry.hpp"
#include "sim_plugin.hpp"
#include "sim_unplug.hpp"

namespace procam::sim::mock {
namespace {

TEST(SimUnplug, ParsesWindows) {
  auto w = parseUnplugWindows("accel@2-4.5,cam@0-1");
  ASSERT_TRUE(w) << w.error().message;
  ASSERT_EQ(w->size(), 2u);
  EXPECT_EQ((*w)[0].device, "accel");
  EXPECT_DOUBLE_EQ((*w)[0].from_s, 2.0);
  EXPECT_DOUBLE_EQ((*w)[0].to_s, 4.5);
  EXPECT_EQ((*w)[1].device, "cam");
  EXPECT_TRUE(parseUnplugWindows("")->empty());
}

TEST(SimUnplug, RefusesMalformedWindows) {
  for (const char* bad : {"accel", "accel@", "accel@2", "accel@4-2", "@1-2", "accel@x-3",
                          "accel@1-2,", "accel@-1-2"}) {
    auto w = parseUnplugWindows(bad);
    ASSERT_FALSE(w) << bad;
    EXPECT_NE(w.error().message.find("PROCAM_SIM_UNPLUG"), std::string::npos);
  }
}

TEST(SimUnplug, WindowIsHalfOpenAndPerDevice) {
  const auto w = *parseUnplugWindows("accel@2-4");
  EXPECT_FALSE(unpluggedAt(w, "accel", 1.999));
  EXPECT_TRUE(unpluggedAt(w, "accel", 2.0));
  EXPECT_TRUE(unpluggedAt(w, "accel", 3.9));
  EXPECT_FALSE(unpluggedAt(w, "accel", 4.0));
  EXPECT_FALSE(unpluggedAt(w, "cam", 3.0));
}

TEST(SimUnplug, UnpluggedDeviceCannotBeCreatedOthersCan) {
  ::setenv(kUnplugVariable, "accel@0-100000", 1);
  static const plugins::StaticPlugin table[] = {{"sim", &procam_sim_plugin_entry}};
  auto drivers = plugins::loadStaticPlugins(table);
  ASSERT_TRUE(drivers);
  plugins::DriverRegistry r;
  for (const auto& d : *drivers) r.add(d);
  auto open = [&](procam_family family, const char* name) {
    plugins::DeviceDescription d;
    d.family = family;
    d.subsystem = "sim";
    d.name = name;
    d.properties = {{"SIM_SCENE", "handheld"}, {"SIM_DEVICE", name}};
    auto match = r.bestMatch(d);
    EXPECT_TRUE(match);
    return plugins::createDevice(match->driver, d, {});
  };
  auto tilt = open(PROCAM_FAMILY_TILT, "accel");
  ASSERT_FALSE(tilt);
  EXPECT_NE(tilt.error().message.find("unplugged"), std::string::npos) << tilt.error().message;
  EXPECT_NE(tilt.error().message.find("code -2"), std::string::npos);  // PROCAM_ENODEV
  EXPECT_TRUE(open(PROCAM_FAMILY_OUTPUT, "proj"));
  ::setenv(kUnplugVariable, "accel@0-1-", 1);
  auto bad = open(PROCAM_FAMILY_TILT, "accel");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("name@T1-T2"), std::string::npos);
  ::unsetenv(kUnplugVariable);
  EXPECT_TRUE(open(PROCAM_FAMILY_TILT, "accel"));
}

}  // namespace
}  // namespace procam::sim::mock
