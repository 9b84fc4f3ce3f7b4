// The device manager: udev records -> descriptions, matching, hotplug
// add/remove (the handler called directly: no udev daemon here), device fds
// in the loop, lost devices and their reopening, tracker reads on the reader
// worker, liveness captures of cameras and the fence that hands a device to
// calibrate.
#include <gtest/gtest.h>
#include <sys/epoll.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <thread>
#include <variant>

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

UdevRecord hidTracker(const std::string& sysname = "hidraw7") {
  UdevRecord r = iioTilt(sysname);
  r.subsystem = "hidraw";
  r.syspath = "/sys/devices/usb/" + sysname;
  r.properties = {{"DEVNAME", r.devnode}, {"PROCAM_ROLE", "tracker"}};
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
    fake::hold = false;
    fake::reads_running = 0;
    fake::most_reads_running = 0;
    fake::destroyed_mid_read = 0;
    fake::trackers_destroyed = 0;
    fake::camera_gone = false;
    fake::captures = 0;
    fake::checks = 0;
    fake::cameras_destroyed = 0;
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
    fake::hold = false;  // a read still blocked would hold up the reader's join
    manager_.reset();
    fake::gone = false;
    fake::camera_gone = false;
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
    got.push_back(std::get<TiltReading>(r).sample.specific_force[0]);
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
    EXPECT_DOUBLE_EQ(std::get<TiltReading>(r).sample.specific_force[2], 9.81);
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
    got.push_back(std::get<TiltReading>(r).sample.specific_force[0]);
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

TEST_F(ManagerTest, ReportedEndMarksEndedAndIsNotReopened) {
  devices_.open(registry_, *describeUdevDevice(iioTilt()), "", {});
  startWithoutUdev(60000ms);
  std::vector<std::string> removed;
  manager_->onDeviceRemoved([&](const DeviceEntry& e) { removed.push_back(e.name); });
  manager_->report("iio:device0", PROCAM_EEND, "end of the recording (3 frames)");
  const DeviceEntry* e = devices_.find("iio:device0");
  ASSERT_NE(e, nullptr);  // still listed, as ended
  EXPECT_EQ(std::string(e->state()), "ended");
  EXPECT_FALSE(e->usable());
  EXPECT_EQ(e->error, "ended: end of the recording (3 frames)");
  ASSERT_EQ(eventsNamed("device-removed").size(), 1u);
  EXPECT_EQ(eventsNamed("device-removed")[0]["state"], "ended");
  EXPECT_FALSE(eventsNamed("device-removed")[0].contains("retries"));
  EXPECT_EQ(removed, std::vector<std::string>{"iio:device0"});
  EXPECT_TRUE(warnings_.empty());  // the normal end of a recording, not a fault
  // No reopen past the first back-off (1 s).
  EXPECT_FALSE(runUntil([&] { return devices_.find("iio:device0")->usable(); }, 1500ms));
  EXPECT_EQ(devices_.find("iio:device0")->retries, 0);
  EXPECT_TRUE(eventsNamed("device-added").empty());
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

fake::Tracker* trackerState(DeviceSet& devices, const std::string& name) {
  return static_cast<fake::Tracker*>(devices.find(name)->device.raw().self);
}

TEST_F(ManagerTest, SlowTrackerReadRunsOffTheLoopOneAtATime) {
  devices_.open(registry_, *describeUdevDevice(iioTilt()), "", {{"fd", "pipe"}});
  devices_.open(registry_, *describeUdevDevice(hidTracker()), "", {{"fd", "readable"}});
  ASSERT_TRUE(devices_.find("hidraw7")->usable());
  fake::Tracker* tracker = trackerState(devices_, "hidraw7");
  const int tracker_fd = tracker->pipe[0];
  fake::hold = true;  // the tracker's first read blocks until released
  startWithoutUdev(60000ms);
  std::vector<double> tilts, poses;
  manager_->onReading([&](const DeviceEntry& e, const Reading& r) {
    if (const auto* t = std::get_if<TiltReading>(&r)) tilts.push_back(t->sample.specific_force[0]);
    if (const auto* p = std::get_if<procam_pose_sample>(&r)) {
      EXPECT_EQ(e.name, "hidraw7");
      poses.push_back(p->position[0]);
    }
  });
  int ticks = 0;
  auto ticker = loop_->addTimer(5ms, true, [&] { ++ticks; });
  ASSERT_TRUE(ticker);
  const char samples[] = {1, 2, 3};
  const int tilt_wfd =
      static_cast<fake::Tilt*>(devices_.find("iio:device0")->device.raw().self)->pipe[1];
  ASSERT_EQ(::write(tilt_wfd, samples, 3), 3);
  // The loop serves the tilt sensor and a timer while the tracker read is blocked.
  ASSERT_TRUE(
      runUntil([&] { return tilts.size() == 3 && ticks >= 3 && fake::reads_running == 1; }));
  EXPECT_EQ(tilts, (std::vector<double>{1, 2, 3}));
  EXPECT_TRUE(poses.empty());
  // Readable all along, the tracker's fd is out of the loop during its read
  // and no second read starts.
  EXPECT_FALSE(loop_->modify(tracker_fd, EPOLLIN));
  EXPECT_FALSE(manager_->read("hidraw7"));
  EXPECT_EQ(tracker->reads, 1);
  fake::hold = false;
  // Released: each result re-arms the fd, so reads follow one after another.
  ASSERT_TRUE(runUntil([&] { return poses.size() >= 5; }));
  EXPECT_EQ(std::vector<double>(poses.begin(), poses.begin() + 5),
            (std::vector<double>{1, 2, 3, 4, 5}));
  EXPECT_EQ(fake::most_reads_running, 1);
  loop_->removeTimer(*ticker);
}

TEST_F(ManagerTest, UnplugDuringATrackerReadLeavesTheDeviceToTheReader) {
  devices_.open(registry_, *describeUdevDevice(hidTracker()), "", {{"fd", "readable"}});
  fake::hold = true;
  startWithoutUdev(60000ms);
  int readings = 0;
  manager_->onReading([&](const DeviceEntry&, const Reading&) { ++readings; });
  ASSERT_TRUE(runUntil([&] { return fake::reads_running == 1; }));
  UdevRecord gone = hidTracker();
  gone.action = "remove";
  manager_->handleUdevEvent(gone);
  EXPECT_EQ(devices_.find("hidraw7"), nullptr);
  ASSERT_EQ(eventsNamed("device-removed").size(), 1u);
  EXPECT_EQ(fake::trackers_destroyed, 0);  // the reader's share keeps it open
  fake::hold = false;
  ASSERT_TRUE(runUntil([&] { return fake::trackers_destroyed == 1; }));
  EXPECT_EQ(fake::destroyed_mid_read, 0);
  EXPECT_EQ(readings, 0);  // the result of a device closed meanwhile is dropped
  EXPECT_TRUE(warnings_.empty());
}

TEST_F(ManagerTest, DeviceReopenedDuringAReadIsWatchedWhenTheReadEnds) {
  const plugins::DeviceDescription desc = *describeUdevDevice(hidTracker());
  devices_.open(registry_, desc, "", {{"fd", "readable"}});
  fake::hold = true;
  startWithoutUdev(60000ms);
  std::vector<double> poses;
  manager_->onReading([&](const DeviceEntry&, const Reading& r) {
    poses.push_back(std::get<procam_pose_sample>(r).position[0]);
  });
  ASSERT_TRUE(runUntil([&] { return fake::reads_running == 1; }));
  // As a configuration reload does: closed and opened again behind the manager.
  devices_.close("hidraw7");
  devices_.open(registry_, desc, "", {{"fd", "readable"}});
  manager_->sync();
  fake::Tracker* fresh = trackerState(devices_, "hidraw7");
  EXPECT_EQ(fresh->reads, 0);  // not read while the old device's read runs
  fake::hold = false;
  ASSERT_TRUE(runUntil([&] { return fresh->reads >= 3 && poses.size() >= 2; }));
  // Only the new device's readings (numbered from 1 again) reach the hooks.
  EXPECT_EQ(poses[0], 1);
  EXPECT_EQ(poses[1], 2);
  // The old device, released by its read's end, is closed on the closer thread.
  ASSERT_TRUE(runUntil([&] { return fake::trackers_destroyed >= 1; }));
  EXPECT_EQ(fake::trackers_destroyed, 1);
}

TEST_F(ManagerTest, EnodevFromTheReaderMarksTheTrackerLost) {
  devices_.open(registry_, *describeUdevDevice(hidTracker()), "", {});  // no fd: presence reads
  startWithoutUdev(20ms);
  fake::gone = true;
  ASSERT_TRUE(runUntil([&] { return !eventsNamed("device-removed").empty(); }));
  const DeviceEntry* e = devices_.find("hidraw7");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(std::string(e->state()), "lost");
  EXPECT_EQ(e->error, "lost: fake tracker unplugged");
  EXPECT_EQ(eventsNamed("device-removed")[0]["state"], "lost");
  ASSERT_FALSE(warnings_.empty());
  EXPECT_NE(warnings_.back().find("fake tracker unplugged"), std::string::npos) << warnings_.back();
}

TEST_F(ManagerTest, ReadFenceWaitsForTheRunningReadAndDropsTheQueuedOne) {
  devices_.open(registry_, *describeUdevDevice(hidTracker("hidraw7")), "", {{"fd", "readable"}});
  devices_.open(registry_, *describeUdevDevice(hidTracker("hidraw8")), "", {{"fd", "readable"}});
  bool may_read = true;
  manager_->setReadGate([&](const std::string&) { return may_read; });
  fake::hold = true;
  startWithoutUdev(20ms);
  int poses = 0;
  manager_->onReading([&](const DeviceEntry&, const Reading&) { ++poses; });
  fake::Tracker* a = trackerState(devices_, "hidraw7");
  fake::Tracker* b = trackerState(devices_, "hidraw8");
  // Both reads handed to the one reader thread (both fds out of the loop):
  // one runs, blocked, the other waits in the queue behind it.
  ASSERT_TRUE(runUntil([&] {
    return fake::reads_running == 1 && !loop_->modify(a->pipe[0], EPOLLIN) &&
           !loop_->modify(b->pipe[0], EPOLLIN);
  }));
  fake::Tracker* running = a->reads == 1 ? a : b;
  fake::Tracker* queued = running == a ? b : a;
  ASSERT_EQ(queued->reads, 0);

  // As calibrate does: close the gate, take the fence, wait on it off the loop.
  may_read = false;
  const ReadFence fence = manager_->readFence({"hidraw7", "hidraw8", "no-such-device"});
  EXPECT_EQ(fence.size(), 2u);
  std::atomic<bool> passed{false};
  std::thread operation([&] {
    fence.wait();
    // Nothing of the manager's runs on either device from here on.
    EXPECT_EQ(fake::reads_running, 0);
    passed = true;
  });
  EXPECT_FALSE(runUntil([&] { return passed.load(); }, 200ms));  // the running read holds it
  fake::hold = false;
  ASSERT_TRUE(runUntil([&] { return passed.load(); }));
  operation.join();
  // The read that ran reports its pose; the withdrawn one never started and,
  // with the gate closed, no read follows.
  EXPECT_FALSE(runUntil([&] { return queued->reads > 0 || running->reads > 1; }, 200ms));
  EXPECT_EQ(poses, 1);
  // The gate opens: the presence check puts both fds back.
  may_read = true;
  ASSERT_TRUE(runUntil([&] { return queued->reads > 0 && running->reads > 1; }));
}

plugins::DeviceDescription silentCamera(const std::string& name) {
  plugins::DeviceDescription d;
  d.family = PROCAM_FAMILY_CAMERA;
  d.name = name;
  d.subsystem = "config";
  return d;
}

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// A camera without a poll fd whose only sign of death is a failing capture
// (a GigE camera that was switched off): the once-a-second liveness capture
// finds it, it is lost, released off the loop, and reopened when it answers.
TEST_F(ManagerTest, SilentCameraThatDiesIsLostAndReopenedWhenItAnswersAgain) {
  devices_.open(registry_, silentCamera("gige"), "silent-camera", {});
  ASSERT_TRUE(devices_.find("gige")->usable());
  startWithoutUdev();  // procamd's interval: 1 s
  int frames = 0;
  manager_->onReading([&](const DeviceEntry& e, const Reading& r) {
    if (e.name == "gige" && std::holds_alternative<CameraFrame>(r)) ++frames;
  });
  // Alive and idle: captured about once a second, nothing more.
  ASSERT_TRUE(runUntil([&] { return frames >= 2; }, 3s));
  EXPECT_LE(fake::captures, 3);
  EXPECT_EQ(std::string(devices_.find("gige")->state()), "open");

  fake::camera_gone = true;
  const auto died = std::chrono::steady_clock::now();
  ASSERT_TRUE(runUntil([&] { return std::string(devices_.find("gige")->state()) == "lost"; }, 3s));
  const double to_lost = secondsSince(died);
  RecordProperty("seconds_to_lost", std::to_string(to_lost));
  std::printf("silent camera: lost %.2f s after it stopped answering\n", to_lost);
  EXPECT_EQ(devices_.find("gige")->error, "lost: fake camera stopped answering");
  ASSERT_EQ(eventsNamed("device-removed").size(), 1u);
  EXPECT_EQ(eventsNamed("device-removed")[0]["state"], "lost");
  ASSERT_FALSE(warnings_.empty());
  EXPECT_NE(warnings_.back().find("fake camera stopped answering"), std::string::npos);
  // Released by a worker, never by the loop thread (this one).
  ASSERT_TRUE(runUntil([&] { return fake::cameras_destroyed == 1; }, 1s));
  EXPECT_NE(fake::camera_destroyed_on.load(), std::this_thread::get_id());

  // The first reopen (1 s later) finds it still gone; it answers again after that.
  ASSERT_TRUE(runUntil([&] { return devices_.find("gige")->retries == 1; }, 3s));
  fake::camera_gone = false;
  const auto healthy = std::chrono::steady_clock::now();
  ASSERT_TRUE(runUntil([&] { return devices_.find("gige")->usable(); }, 4s));
  const double to_open = secondsSince(healthy);
  RecordProperty("seconds_to_reopen", std::to_string(to_open));
  std::printf("silent camera: open again %.2f s after it answered again\n", to_open);
  EXPECT_EQ(std::string(devices_.find("gige")->state()), "open");
  ASSERT_EQ(eventsNamed("device-added").size(), 1u);
  EXPECT_EQ(eventsNamed("device-added")[0]["state"], "open");
  // And watched again.
  const int before = frames;
  ASSERT_TRUE(runUntil([&] { return frames > before; }, 3s));
}

// A camera whose driver has a liveness check is checked, not captured: an idle
// virtual camera renders nothing for it.
TEST_F(ManagerTest, CameraWithALivenessCheckIsCheckedNotCaptured) {
  devices_.open(registry_, silentCamera("virtual"), "checked-camera", {});
  ASSERT_TRUE(devices_.find("virtual")->usable());
  startWithoutUdev();
  int frames = 0;
  manager_->onReading([&](const DeviceEntry& e, const Reading&) { frames += e.name == "virtual"; });
  ASSERT_TRUE(runUntil([&] { return fake::checks >= 2; }, 3s));
  EXPECT_EQ(fake::captures, 0);
  EXPECT_EQ(frames, 0);
  fake::camera_gone = true;
  const auto died = std::chrono::steady_clock::now();
  ASSERT_TRUE(
      runUntil([&] { return std::string(devices_.find("virtual")->state()) == "lost"; }, 3s));
  std::printf("checked camera: lost %.2f s after its check failed\n", secondsSince(died));
  EXPECT_EQ(devices_.find("virtual")->error, "lost: fake camera stopped answering its checks");
  EXPECT_EQ(fake::captures, 0);
}

// While calibrate owns a camera (read gate closed) the liveness capture keeps
// off it: a capture of the manager would take a frame calibrate waits for.
TEST_F(ManagerTest, LivenessCaptureKeepsOffACameraBehindTheReadGate) {
  devices_.open(registry_, silentCamera("gige"), "silent-camera", {});
  bool may_read = false;
  manager_->setReadGate([&](const std::string&) { return may_read; });
  startWithoutUdev(50ms);
  fake::camera_gone = true;  // would be found lost at the first capture
  EXPECT_FALSE(runUntil([&] { return fake::captures > 0; }, 400ms));
  EXPECT_EQ(std::string(devices_.find("gige")->state()), "open");
  may_read = true;
  ASSERT_TRUE(runUntil([&] { return std::string(devices_.find("gige")->state()) == "lost"; }, 1s));
}

TEST(DeviceManagerBackOff, OneTwoFourEightThenEveryTenSeconds) {
  std::vector<int64_t> s;
  for (int i = 0; i < 7; ++i) s.push_back(DeviceManager::retryDelay(i).count());
  EXPECT_EQ(s, (std::vector<int64_t>{1, 2, 4, 8, 10, 10, 10}));
}

}  // namespace
}  // namespace procam::daemon
