// Plugin ABI: loading real shared objects, refusing ABI mismatches before any
// plugin code runs, validating tables, matching devices to drivers.
#include <gtest/gtest.h>

#include <cstring>

#include "loader.hpp"
#include "registry.hpp"

namespace procam::plugins {
namespace {

std::string fixture(const char* name) {
  return std::string(PROCAM_FIXTURE_DIR) + "/" + name;
}

DeviceDescription tiltDescription(const char* role) {
  DeviceDescription d;
  d.family = PROCAM_FAMILY_TILT;
  d.subsystem = "iio";
  d.properties = {{"PROCAM_ROLE", role}};
  return d;
}

TEST(PluginLoader, LoadsSharedObjectAndCreatesDevice) {
  auto drivers = loadSharedPlugin(fixture("libconstant_tilt_plugin.so"));
  ASSERT_TRUE(drivers) << drivers.error().message;
  ASSERT_EQ(drivers->size(), 1u);
  EXPECT_EQ((*drivers)[0].name(), "constant-tilt");
  EXPECT_EQ((*drivers)[0].family(), PROCAM_FAMILY_TILT);

  auto desc = tiltDescription("tilt");
  auto device = createDevice((*drivers)[0], desc, {{"z", "-9.5"}});
  ASSERT_TRUE(device) << device.error().message;
  EXPECT_EQ(device->pollFd(), -1);
  procam_tilt_sample sample{};
  char err[64] = {};
  ASSERT_EQ(device->raw().ops.tilt->read(device->raw().self, &sample, err, sizeof err), PROCAM_OK);
  EXPECT_EQ(sample.specific_force[2], -9.5);  // the configured value, exactly
  // Its tilt table is version 1: no counts, and nothing read past the table's end.
  EXPECT_EQ(device->raw().ops.tilt->version, 1u);
  EXPECT_FALSE(tiltCounts(device->raw()));
}

TEST(PluginLoader, DeviceOutlivesDriverListAndKeepsLibraryLoaded) {
  Result<Device> device = fail(ErrorCode::kIo, "unset");
  {
    auto drivers = loadSharedPlugin(fixture("libconstant_tilt_plugin.so"));
    ASSERT_TRUE(drivers);
    auto desc = tiltDescription("tilt");
    device = createDevice((*drivers)[0], desc, {});
  }
  ASSERT_TRUE(device);
  procam_tilt_sample sample{};
  char err[64] = {};
  // Would crash if the library had been unloaded with the driver list.
  ASSERT_EQ(device->raw().ops.tilt->read(device->raw().self, &sample, err, sizeof err), PROCAM_OK);
  EXPECT_EQ(sample.specific_force[2], 9.81);
}

TEST(PluginLoader, CreateErrorCarriesPluginMessage) {
  auto drivers = loadSharedPlugin(fixture("libconstant_tilt_plugin.so"));
  ASSERT_TRUE(drivers);
  auto desc = tiltDescription("tilt");
  auto device = createDevice((*drivers)[0], desc, {{"z", "down"}});
  ASSERT_FALSE(device);
  EXPECT_NE(device.error().message.find("option z: 'down' is not a number"), std::string::npos)
      << device.error().message;
}

TEST(PluginLoader, RefusesAbiMismatchWithoutCallingEntry) {
  // The fixture's entry aborts: reaching the assertions proves it was not called.
  auto drivers = loadSharedPlugin(fixture("libwrong_abi_plugin.so"));
  ASSERT_FALSE(drivers);
  const std::string& msg = drivers.error().message;
  EXPECT_NE(msg.find("ABI version " + std::to_string(PROCAM_PLUGIN_ABI_VERSION + 1)),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("implements ABI version " + std::to_string(PROCAM_PLUGIN_ABI_VERSION)),
            std::string::npos)
      << msg;
}

TEST(PluginLoader, RefusesObjectWithoutPluginSymbols) {
  auto drivers = loadSharedPlugin(fixture("libnot_a_plugin.so"));
  ASSERT_FALSE(drivers);
  EXPECT_NE(drivers.error().message.find("not a procamd plugin"), std::string::npos);
}

TEST(PluginLoader, ReportsMissingFile) {
  auto drivers = loadSharedPlugin(fixture("libdoes_not_exist.so"));
  ASSERT_FALSE(drivers);
  EXPECT_EQ(drivers.error().code, ErrorCode::kIo);
}

TEST(PluginLoader, DirectoryLoadsGoodPluginsAndReportsBadOnes) {
  std::vector<Error> errors;
  auto drivers = loadPluginDirectory(PROCAM_FIXTURE_DIR, errors);
  ASSERT_EQ(drivers.size(), 1u);
  EXPECT_EQ(drivers[0].name(), "constant-tilt");
  EXPECT_EQ(errors.size(), 2u);  // wrong ABI, not a plugin
}

int neverProbe(const procam_device_desc*) {
  return 0;
}
int scoreFive(const procam_device_desc*) {
  return 5;
}
int scoreFifty(const procam_device_desc*) {
  return 50;
}
int noCreate(const procam_device_desc*, const procam_config*, procam_device*, char* err,
             size_t len) {
  std::strncpy(err, "unused", len);
  return PROCAM_ENOTSUP;
}

TEST(PluginTable, ValidationNamesTheProblem) {
  procam_driver_factory bad_family{PROCAM_FAMILY_TILT, "x", "", scoreFive, noCreate, nullptr};
  const uint32_t nine = 9;  // what a broken plugin might store; not a valid enumerator
  std::memcpy(&bad_family.family, &nine, sizeof nine);
  procam_plugin_table table{PROCAM_PLUGIN_ABI_VERSION, "t", "1", 1, &bad_family};
  auto r = validateTable(&table, "test");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("unknown family 9"), std::string::npos);

  procam_driver_factory no_probe{PROCAM_FAMILY_CAMERA, "cam", "", nullptr, noCreate, nullptr};
  table.factories = &no_probe;
  r = validateTable(&table, "test");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("('cam') lacks probe() or create()"), std::string::npos);

  table.n_factories = 0;
  EXPECT_FALSE(validateTable(&table, "test"));
  table.n_factories = 1;
  table.abi_version = PROCAM_PLUGIN_ABI_VERSION + 3;
  EXPECT_FALSE(validateTable(&table, "test"));
  EXPECT_FALSE(validateTable(nullptr, "test"));
}

TEST(DriverRegistry, HighestScoreOfTheRightFamilyWins) {
  static const procam_driver_factory factories[] = {
      {PROCAM_FAMILY_TILT, "low", "", scoreFive, noCreate, nullptr},
      {PROCAM_FAMILY_TILT, "high", "", scoreFifty, noCreate, nullptr},
      {PROCAM_FAMILY_CAMERA, "camera-highest", "", scoreFifty, noCreate, nullptr},
      {PROCAM_FAMILY_TILT, "never", "", neverProbe, noCreate, nullptr},
  };
  DriverRegistry registry;
  for (const auto& f : factories) ASSERT_TRUE(registry.add(Driver{&f, "test", nullptr}));
  EXPECT_FALSE(registry.add(Driver{&factories[0], "again", nullptr}));  // duplicate name

  auto desc = tiltDescription("tilt");
  auto match = registry.bestMatch(desc);
  ASSERT_TRUE(match);
  EXPECT_EQ(match->driver.name(), "high");
  EXPECT_EQ(match->score, 50);

  DeviceDescription tracker;
  tracker.family = PROCAM_FAMILY_TRACKER;
  EXPECT_FALSE(registry.bestMatch(tracker));
}

TEST(DriverRegistry, SharedPluginProbeSeesProperties) {
  auto drivers = loadSharedPlugin(fixture("libconstant_tilt_plugin.so"));
  ASSERT_TRUE(drivers);
  DriverRegistry registry;
  std::vector<std::string> refused;
  registry.addAll(*drivers, refused);
  EXPECT_TRUE(refused.empty());
  auto tilt = tiltDescription("tilt");
  ASSERT_TRUE(registry.bestMatch(tilt));
  auto other = tiltDescription("camera");
  EXPECT_FALSE(registry.bestMatch(other));
}

TEST(Family, NamesRoundTrip) {
  for (procam_family f :
       {PROCAM_FAMILY_CAMERA, PROCAM_FAMILY_TILT, PROCAM_FAMILY_TRACKER, PROCAM_FAMILY_OUTPUT}) {
    auto parsed = parseFamily(familyName(f));
    ASSERT_TRUE(parsed);
    EXPECT_EQ(*parsed, f);
  }
  EXPECT_FALSE(parseFamily("projector"));
}

}  // namespace
}  // namespace procam::plugins
