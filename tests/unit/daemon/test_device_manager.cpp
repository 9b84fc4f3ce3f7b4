// The device manager: udev records -> descriptions, matching, hotplug
// add/remove (the handler called directly: no udev daemon here), device fds
// in the loop, lost devices and their reopening.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>

#include "device_manager.hpp"
#include "fake_drivers.hpp"
#include "udev_device.hpp"

namespace procam::daemon {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

UdevRecord iioTilt(const std::string& sysname = "iio:device0") {
  UdevRecord r;
  r.action = "add";
  r.subsystem = "iio";
  r.sysname = sysname;
  r.devnode = "/dev/" + sysname;
  r.syspath = "/sys/devices/platform/accel/" + sysname;
  r.properties = {{"DEVNAME", r.devnode}, {"PROCAM_ROLE", "tilt"}, {"ID_VENDOR_ID", "abcd"}};
  return r;
}

TEST(UdevDevice, RoleTiltBecomesATiltDescription) {
  const UdevRecord r = iioTilt();
  auto d = describeUdevDevice(r);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->family, PROCAM_FAMILY_TILT);
  EXPECT_EQ(d->subsystem, "iio");
  EXPECT_EQ(d->devnode, "/dev/iio:device0");
  EXPECT_EQ(d->syspath, "/sys/devices/platform/accel/iio:device0");
  EXPECT_EQ(d->name, "iio:device0");
  EXPECT_EQ(d->properties, r.properties);
  EXPECT_EQ(d->property("ID_VENDOR_ID"), "abcd");
}

TEST(UdevDevice, EveryDeviceRoleMapsToItsFamily) {
  EXPECT_EQ(familyOfRole("camera"), PROCAM_FAMILY_CAMERA);
  EXPECT_EQ(familyOfRole("tilt"), PROCAM_FAMILY_TILT);
  EXPECT_EQ(familyOfRole("tracker"), PROCAM_FAMILY_TRACKER);
  EXPECT_EQ(familyOfRole("output"), PROCAM_FAMILY_OUTPUT);
  // Buses are not devices of their own: a configured sensor names its bus.
  EXPECT_FALSE(familyOfRole("i2c-adapter"));
  EXPECT_FALSE(familyOfRole("gpiochip"));
  EXPECT_FALSE(familyOfRole(""));
}

TEST(UdevDevice, DevicesWithoutARoleAreNotProcamds) {
  UdevRecord r = iioTilt();
  r.properties = {{"DEVNAME", r.devnode}};
  EXPECT_FALSE(describeUdevDevice(r));
  r.properties = {{"PROCAM_ROLE", "gpiochip"}};
  EXPECT_FALSE(describeUdevDevice(r));
}

TEST(UdevDevice, NameFallsBackToTheLastSyspathComponent) {
  UdevRecord r = iioTilt();
  r.sysname.clear();
  EXPECT_EQ(describeUdevDevice(r)->name, "iio:device0");
}

// Every subsystem in which the rules give a device role is enumerated and
// monitored: read the installed rules file itself.
TEST(UdevDevice, SubsystemsCoverTheRulesDeviceRoles) {
  const char* src = std::getenv("PROCAM_SOURCE_DIR");
  ASSERT_NE(src, nullptr);
  std::ifstream in(std::string(src) + "/udev/70-procamd.rules");
  ASSERT_TRUE(in);
  const std::regex rule(R"re(SUBSYSTEM=="([^"]+)".*ENV\{PROCAM_ROLE\}="([^"]+)")re");
  std::set<std::string> ours;
  for (const char* s : procamSubsystems()) ours.insert(s);
  int device_rules = 0;
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, rule) || !familyOfRole(m[2].str())) continue;
    ++device_rules;
    EXPECT_TRUE(ours.count(m[1].str())) << m[1] << " (role " << m[2] << ")";
  }
  EXPECT_GE(device_rules, 4);  // camera, tracker, tilt (2), output
}

// A loop, a device set and a manager whose events are recorded.
class ManagerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fake::gone = false;
    loop_ = std::move(*EventLoop::create());
    manager_ = std::make_unique<DeviceManager>(
        *loop_, registry_, devices_,
        [this](const std::string& ev, json body) {
          body["event"] = ev;
          events_.push_back(std::move(body));
        },
        [this](const std::string& m) { warnings_.push_back(m); });
  }
  void TearDown() override {
    manager_.reset();
    fake::gone = false;
  }

  // Runs the loop until `pred` holds (checked every 5 ms); false on timeout.
  template <class F>
  bool runUntil(F pred, std::chrono::milliseconds timeout = 5s) {
    bool met = false;
    auto check = loop_->addTimer(5ms, true, [&] {
      if (pred()) {
        met = true;
        loop_->stop();
      }
    });
    auto limit = loop_->addTimer(timeout, false, [&] { loop_->stop(); });
    loop_->run();
    loop_->removeTimer(*check);
    if (met) loop_->removeTimer(*limit);  // a one-shot timer that fired is gone already
    return met;
  }

  void startWithoutUdev(std::chrono::milliseconds presence = 1000ms) {
    manager_->start({.udev = false, .presence_interval = presence});
  }

  std::vector<json> eventsNamed(const std::string& name) const {
    std::vector<json> out;
    for (const auto& e : events_) {
      if (e["event"] == name) out.push_back(e);
    }
    return out;
  }

  plugins::DriverRegistry registry_ = fake::registry();
  DeviceSet devices_;
  std::unique_ptr<EventLoop> loop_;
  std::unique_ptr<DeviceManager> manager_;
  std::vector<json> events_;
  std::vector<std::string> warnings_;
};

TEST_F(ManagerTest, HotplugAddMatchesTheBestDriverAndRemoveClosesIt) {
  startWithoutUdev();
  std::vector<std::string> added, removed;
  manager_->onDeviceAdded([&](const DeviceEntry& e) { added.push_back(e.name); });
  manager_->onDeviceRemoved([&](const DeviceEntry& e) {
    EXPECT_FALSE(e.usable());
    removed.push_back(e.name);
  });
  manager_->handleUdevEvent(iioTilt());
  ASSERT_TRUE(runUntil([&] { return !added.empty(); }));
  DeviceEntry* e = devices_.find("iio:device0");
  ASSERT_NE(e, nullptr);
  EXPECT_TRUE(e->usable());
  // fake-tilt scores 20 for an IIO tilt sensor, generic-tilt 5.
  EXPECT_EQ(e->driver, "fake-tilt");
  EXPECT_EQ(e->score, 20);
  ASSERT_EQ(eventsNamed("device-added").size(), 1u);
  EXPECT_EQ(eventsNamed("device-added")[0]["state"], "open");
  EXPECT_EQ(eventsNamed("device-added")[0]["syspath"], "/sys/devices/platform/accel/iio:device0");

  UdevRecord gone = iioTilt();
  gone.action = "remove";
  manager_->handleUdevEvent(gone);
  EXPECT_EQ(devices_.find("iio:device0"), nullptr);
  EXPECT_EQ(removed, std::vector<std::string>{"iio:device0"});
  ASSERT_EQ(eventsNamed("device-removed").size(), 1u);
  EXPECT_EQ(eventsNamed("device-removed")[0]["state"], "removed");
  EXPECT_EQ(eventsNamed("device-removed")[0]["name"], "iio:device0");
}

TEST_F(ManagerTest, UnclaimedDeviceIsListedWithTheReason) {
  startWithoutUdev();
  UdevRecord cam = iioTilt("video0");
  cam.subsystem = "video4linux";
  cam.properties = {{"PROCAM_ROLE", "camera"}};
  manager_->handleUdevEvent(cam);
  ASSERT_TRUE(runUntil([&] { return devices_.find("video0") != nullptr; }));
  const DeviceEntry* e = devices_.find("video0");
  EXPECT_FALSE(e->usable());
  EXPECT_EQ(std::string(e->state()), "error");
  EXPECT_EQ(e->error, "no camera driver accepts this device");
  ASSERT_EQ(eventsNamed("device-added").size(), 1u);
  EXPECT_EQ(eventsNamed("device-added")[0]["error"], "no camera driver accepts this device");
}

TEST_F(ManagerTest, NonTiltRoleOnlyLosesAgainstTheRoleSpecificScore) {
  // A tilt sensor on another bus (hidraw) scores 10 with fake-tilt, still above generic-tilt.
  startWithoutUdev();
  UdevRecord hid = iioTilt("hidraw3");
  hid.subsystem = "hidraw";
  manager_->handleUdevEvent(hid);
  ASSERT_TRUE(runUntil([&] { return devices_.find("hidraw3") != nullptr; }));
  EXPECT_EQ(devices_.find("hidraw3")->driver, "fake-tilt");
  EXPECT_EQ(devices_.find("hidraw3")->score, 10);
}

TEST_F(ManagerTest, ConfiguredDeviceKeepsItsNodeAndOtherEventsAreIgnored) {
  plugins::DeviceDescription cfg;
  cfg.family = PROCAM_FAMILY_TILT;
  cfg.name = "imu";
  cfg.subsystem = "config";
  cfg.devnode = "/dev/iio:device0";
  devices_.open(registry_, cfg, "fake-tilt", {});
  startWithoutUdev();
  manager_->handleUdevEvent(iioTilt());
  UdevRecord change = iioTilt("iio:device1");
  change.action = "change";
  manager_->handleUdevEvent(change);
  // Nothing was queued: the loop has no open to finish.
  EXPECT_FALSE(runUntil([&] { return devices_.entries().size() > 1; }, 200ms));
  EXPECT_TRUE(events_.empty());
}

TEST_F(ManagerTest, UnplugWhileOpeningDropsTheOpen) {
  startWithoutUdev();
  manager_->handleUdevEvent(iioTilt());
  UdevRecord gone = iioTilt();
  gone.action = "remove";
  manager_->handleUdevEvent(gone);
  EXPECT_FALSE(runUntil([&] { return !devices_.entries().empty(); }, 300ms));
  EXPECT_TRUE(events_.empty());
}

TEST_F(ManagerTest, ReadableDeviceFdDeliversSamplesToTheHooks) {
  plugins::DeviceDescription d = *describeUdevDevice(iioTilt());
  devices_.open(registry_, d, "", {{"fd", "pipe"}});
  ASSERT_TRUE(devices_.find("iio:device0")->usable());
  startWithoutUdev();
  std::vector<double> got;
  manager_->onReading([&](const DeviceEntry& e, const Reading& r) {
    EXPECT_EQ(e.name, "iio:device0");
    got.push_back(std::get<procam_tilt_sample>(r).specific_force[0]);
  });
  // The pipe's write end lives in the fake driver's state.
  const int wfd =
      static_cast<fake::Tilt*>(devices_.find("iio:device0")->device.raw().self)->pipe[1];
  const char samples[] = {7, 8, 9};
  ASSERT_EQ(::write(wfd, samples, 3), 3);
  ASSERT_TRUE(runUntil([&] { return got.size() == 3; }));
  EXPECT_EQ(got, (std::vector<double>{7, 8, 9}));
}

TEST_F(ManagerTest, PollEveryReadsATimerPolledDevice) {
  devices_.open(registry_, *describeUdevDevice(iioTilt()), "", {});
  startWithoutUdev(60000ms);  // no presence reads during the test
  int readings = 0;
  manager_->onReading([&](const DeviceEntry&, const Reading& r) {
    EXPECT_DOUBLE_EQ(std::get<procam_tilt_sample>(r).specific_force[2], 9.81);
    ++readings;
  });
  auto id = manager_->pollEvery("iio:device0", 10ms);
  ASSERT_TRUE(id);
  ASSERT_TRUE(runUntil([&] { return readings >= 3; }));
  manager_->stopPolling(*id);
  EXPECT_FALSE(manager_->pollEvery("nothing", 10ms));
}

TEST_F(ManagerTest, ClosedReadGateKeepsTheManagerOffADeviceUntilItOpens) {
  devices_.open(registry_, *describeUdevDevice(iioTilt()), "", {{"fd", "pipe"}});
  bool may_read = false;  // as while calibrate captures from the device on a worker
  manager_->setReadGate([&](const std::string&) { return may_read; });
  startWithoutUdev(20ms);
  std::vector<double> got;
  manager_->onReading([&](const DeviceEntry&, const Reading& r) {
    got.push_back(std::get<procam_tilt_sample>(r).specific_force[0]);
  });
  const int wfd =
      static_cast<fake::Tilt*>(devices_.find("iio:device0")->device.raw().self)->pipe[1];
  const char samples[] = {4, 5};
  ASSERT_EQ(::write(wfd, samples, 2), 2);
  // Readable all along, yet nothing is read (the first wake-up takes the fd out).
  EXPECT_FALSE(runUntil([&] { return !got.empty(); }, 200ms));
  EXPECT_FALSE(manager_->read("iio:device0"));
  // Open again: the next presence check puts the fd back and the samples come.
  may_read = true;
  ASSERT_TRUE(runUntil([&] { return got.size() == 2; }));
  EXPECT_EQ(got, (std::vector<double>{4, 5}));
}

TEST_F(ManagerTest, LostDeviceIsClosedAndReopenedAfterBackOff) {
  devices_.open(registry_, *describeUdevDevice(iioTilt()), "", {});
  startWithoutUdev(20ms);
  std::vector<std::string> removed;
  manager_->onDeviceRemoved([&](const DeviceEntry& e) { removed.push_back(e.name); });
  fake::gone = true;
  ASSERT_TRUE(runUntil([&] { return !eventsNamed("device-removed").empty(); }));
  const DeviceEntry* e = devices_.find("iio:device0");
  ASSERT_NE(e, nullptr);  // still listed, as lost
  EXPECT_EQ(std::string(e->state()), "lost");
  EXPECT_FALSE(e->usable());
  EXPECT_EQ(eventsNamed("device-removed")[0]["state"], "lost");
  EXPECT_EQ(removed, std::vector<std::string>{"iio:device0"});
  ASSERT_FALSE(warnings_.empty());
  EXPECT_NE(warnings_.back().find("fake sensor unplugged"), std::string::npos) << warnings_.back();
  // The first reopen (after 1 s) still fails; it comes back on the second (2 s later).
  ASSERT_TRUE(runUntil([&] { return devices_.find("iio:device0")->retries == 1; }, 3s));
  fake::gone = false;
  ASSERT_TRUE(runUntil([&] { return devices_.find("iio:device0")->usable(); }, 4s));
  EXPECT_EQ(std::string(devices_.find("iio:device0")->state()), "open");
  EXPECT_EQ(devices_.find("iio:device0")->driver, "fake-tilt");
  ASSERT_EQ(eventsNamed("device-added").size(), 1u);
  EXPECT_EQ(eventsNamed("device-added")[0]["state"], "open");
}

TEST_F(ManagerTest, ReportedEnodevMarksLostAndOtherErrorsDoNot) {
  devices_.open(registry_, *describeUdevDevice(iioTilt()), "", {});
  startWithoutUdev(60000ms);
  manager_->report("iio:device0", PROCAM_EIO, "glitch");
  manager_->report("iio:device0", PROCAM_EAGAIN, "");
  EXPECT_TRUE(devices_.find("iio:device0")->usable());
  manager_->report("iio:device0", PROCAM_ENODEV, "camera unplugged mid-capture");
  EXPECT_EQ(std::string(devices_.find("iio:device0")->state()), "lost");
  EXPECT_EQ(devices_.find("iio:device0")->error, "lost: camera unplugged mid-capture");
  // A udev remove of a lost device forgets it and its pending reopen.
  UdevRecord gone = iioTilt();
  gone.action = "remove";
  manager_->handleUdevEvent(gone);
  EXPECT_EQ(devices_.find("iio:device0"), nullptr);
  EXPECT_FALSE(runUntil([&] { return !devices_.entries().empty(); }, 1500ms));
}

TEST_F(ManagerTest, LostDeviceAnnouncedAgainByUdevIsReopenedAtOnce) {
  devices_.open(registry_, *describeUdevDevice(iioTilt()), "", {});
  startWithoutUdev(60000ms);
  manager_->report("iio:device0", PROCAM_ENODEV, "gone");
  ASSERT_EQ(std::string(devices_.find("iio:device0")->state()), "lost");
  manager_->handleUdevEvent(iioTilt());
  // Well before the first back-off (1 s) ends.
  ASSERT_TRUE(runUntil([&] { return devices_.find("iio:device0")->usable(); }, 500ms));
  EXPECT_EQ(devices_.entries().size(), 1u);
  EXPECT_EQ(eventsNamed("device-added").size(), 1u);
}

TEST_F(ManagerTest, AWorkersShareOutlivesAnUnplug) {
  devices_.open(registry_, *describeUdevDevice(iioTilt()), "", {});
  startWithoutUdev(60000ms);
  std::shared_ptr<plugins::Device> held = devices_.find("iio:device0")->device.share();
  UdevRecord gone = iioTilt();
  gone.action = "remove";
  manager_->handleUdevEvent(gone);
  EXPECT_EQ(devices_.find("iio:device0"), nullptr);
  ASSERT_TRUE(held->valid());
  procam_tilt_sample s{};
  char err[64] = {};
  EXPECT_EQ(held->raw().ops.tilt->read(held->raw().self, &s, err, sizeof err), PROCAM_OK);
  EXPECT_DOUBLE_EQ(s.specific_force[2], 9.81);
}

TEST(DeviceManagerBackOff, OneTwoFourEightThenEveryTenSeconds) {
  std::vector<int64_t> s;
  for (int i = 0; i < 7; ++i) s.push_back(DeviceManager::retryDelay(i).count());
  EXPECT_EQ(s, (std::vector<int64_t>{1, 2, 4, 8, 10, 10, 10}));
}

}  // namespace
}  // namespace procam::daemon
