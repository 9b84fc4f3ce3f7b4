// Lost devices on the virtual rig: PROCAM_SIM_UNPLUG makes the mock tilt
// sensor return PROCAM_ENODEV for a window; the daemon marks it lost, tells
// the watchers, reopens it with back-off and announces it again.
#include <gtest/gtest.h>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

std::optional<json> deviceNamed(Connection& c, const std::string& name) {
  auto devices = c.call({{"cmd", "devices"}});
  if (!devices) return std::nullopt;
  for (const auto& d : (*devices)["devices"]) {
    if (d["name"] == name) return d;
  }
  return std::nullopt;
}

TEST(SimDevices, UnpluggedTiltSensorIsLostThenBack) {
  TempDir dir;
  // Unplugged 3 to 5 s after the daemon started. It is read once a second
  // (presence check): lost at the first read after 3 s; reopened after 1 s
  // (still unplugged), then 2 s later (back).
  DaemonProcess d(
      dir, DaemonProcess::Launch{{"--sim", "handheld"}, {"PROCAM_SIM_UNPLUG=accel@3-5"}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection watcher(d.socketPath());
  Connection query(d.socketPath());
  ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
  auto before = deviceNamed(query, "accel");
  ASSERT_TRUE(before);
  // A slow start may already be past 3 s: then the loss shows in the list.
  bool saw_lost = (*before)["state"] == "lost";
  std::optional<json> removed, added;
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  while (!added && std::chrono::steady_clock::now() < deadline) {
    auto line = watcher.next(1s);
    if (!line || (*line)["class"] != "EVENT" || (*line)["name"] != "accel") continue;
    if ((*line)["event"] == "device-removed") {
      removed = line;
      auto during = deviceNamed(query, "accel");
      ASSERT_TRUE(during);
      EXPECT_EQ((*during)["state"], "lost") << during->dump();
      EXPECT_NE((*during)["error"].get<std::string>().find("unplugged"), std::string::npos)
          << during->dump();
      saw_lost = true;
    } else if ((*line)["event"] == "device-added") {
      added = line;
    }
  }
  EXPECT_TRUE(saw_lost);
  if (removed) {
    EXPECT_EQ((*removed)["state"], "lost");
    EXPECT_EQ((*removed)["family"], "tilt");
  }
  ASSERT_TRUE(added) << d.log();
  EXPECT_EQ((*added)["state"], "open");
  EXPECT_EQ((*added)["driver"], "sim-tilt");
  auto after = deviceNamed(query, "accel");
  ASSERT_TRUE(after);
  EXPECT_EQ((*after)["state"], "open");
  EXPECT_FALSE(after->contains("error"));
  // The other devices were never touched.
  EXPECT_EQ(deviceNamed(query, "proj")->at("state"), "open");
  EXPECT_EQ(deviceNamed(query, "cam")->at("state"), "open");
  auto status = query.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["devices"]["tilt"], 1);
}

}  // namespace
}  // namespace procam::itest
