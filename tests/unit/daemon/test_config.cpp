// procamd.toml parsing: values land in the right fields, and every unknown key
// or bad value is an error that names the file, the line and the key.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "config.hpp"

namespace procam::daemon {
namespace {

Error parseError(const std::string& text) {
  auto cfg = parseConfig(text, "rig.toml");
  EXPECT_FALSE(cfg) << "accepted:\n" << text;
  return cfg ? Error{} : cfg.error();
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST(Config, EmptyTextGivesDefaults) {
  auto cfg = parseConfig("", "rig.toml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->log_level, LogLevel::kInfo);
  EXPECT_EQ(cfg->max_clients, 128);
  EXPECT_FALSE(cfg->auto_keystone);
  EXPECT_TRUE(cfg->devices.empty());
}

TEST(Config, FullRigIsRead) {
  const char* text = R"(
[daemon]
log_level = "debug"
max_clients = 12
client_queue_kib = 256
client_stall_timeout_s = 2.5

[policy]
auto_keystone = true
recalibrate = "on-drift"

[sim]
scene = "handheld.toml"

[[projector]]
name = "main"
driver = "kms"
devnode = "/dev/dri/card0"

[[camera]]
name = "cam0"
[camera.options]
exposure_ms = 8
gain = 1.5
mono = true
serial = "A1"

[[tilt]]
name = "imu"
)";
  auto cfg = parseConfig(text, "rig.toml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->log_level, LogLevel::kDebug);
  EXPECT_EQ(cfg->max_clients, 12);
  EXPECT_EQ(cfg->client_queue_kib, 256);
  EXPECT_DOUBLE_EQ(cfg->client_stall_timeout_s, 2.5);
  EXPECT_TRUE(cfg->auto_keystone);
  EXPECT_EQ(cfg->recalibrate, RecalibratePolicy::kOnDrift);
  EXPECT_EQ(cfg->sim_scene, "handheld.toml");
  ASSERT_EQ(cfg->devices.size(), 3u);
  EXPECT_EQ(cfg->devices[0].family, PROCAM_FAMILY_OUTPUT);
  EXPECT_EQ(cfg->devices[0].driver, "kms");
  EXPECT_EQ(cfg->devices[0].devnode, "/dev/dri/card0");
  EXPECT_EQ(cfg->devices[0].line, 15);
  EXPECT_EQ(cfg->devices[1].family, PROCAM_FAMILY_CAMERA);
  using Opt = std::pair<std::string, std::string>;
  EXPECT_EQ(cfg->devices[1].options,
            (std::vector<Opt>{
                {"exposure_ms", "8"}, {"gain", "1.5"}, {"mono", "true"}, {"serial", "A1"}}));
  EXPECT_EQ(cfg->devices[2].family, PROCAM_FAMILY_TILT);
}

TEST(Config, UnknownKeyNamesKeyAndLine) {
  auto e = parseError("[daemon]\nlog_level = \"info\"\nlog_levle = \"debug\"\n");
  EXPECT_TRUE(contains(e.message, "rig.toml:3: daemon.log_levle: unknown key")) << e.message;
}

TEST(Config, UnknownSectionNamesIt) {
  auto e = parseError("\n[deamon]\n");
  EXPECT_TRUE(contains(e.message, "rig.toml:2: deamon: unknown key")) << e.message;
}

TEST(Config, BadValuesNameKeyAndLine) {
  struct Case {
    const char* text;
    const char* expected;
  } cases[] = {
      {"[daemon]\nlog_level = \"loud\"", "rig.toml:2: daemon.log_level: unknown log level 'loud'"},
      {"[daemon]\nlog_level = 3", "rig.toml:2: daemon.log_level: expected a string"},
      {"[daemon]\n\nmax_clients = 0",
       "rig.toml:3: daemon.max_clients: 0 is out of range [1, 4096]"},
      {"[daemon]\nmax_clients = 1.5", "rig.toml:2: daemon.max_clients: expected an integer"},
      {"[daemon]\nclient_stall_timeout_s = nan",
       "rig.toml:2: daemon.client_stall_timeout_s: nan is out of range"},
      {"[policy]\nauto_keystone = \"yes\"",
       "rig.toml:2: policy.auto_keystone: expected true or false"},
      {"[policy]\nrecalibrate = \"always\"",
       "rig.toml:2: policy.recalibrate: 'always' is not one of"},
      {"[policy]\ndrift_threshold_px = 0",
       "rig.toml:2: policy.drift_threshold_px: 0 is out of range"},
      {"[policy]\ndrift_frames = 17",
       "rig.toml:2: policy.drift_frames: 17 is out of range [1, 16]"},
      {"[policy]\ndrift_period_s = \"fast\"",
       "rig.toml:2: policy.drift_period_s: expected a number"},
      {"[[camera]]\ndriver = \"v4l2\"", "rig.toml:1: camera[0].name: missing"},
      {"[[camera]]\nname = \"a\"\n[[tilt]]\nname = \"a\"",
       "rig.toml:4: tilt[0].name: duplicate device name 'a'"},
      {"[[camera]]\nname = \"a\"\nexposure = 3", "rig.toml:3: camera[0].exposure: unknown key"},
      {"[[camera]]\nname = \"a\"\noptions = { list = [1, 2] }",
       "rig.toml:3: camera[0].options.list: expected a string, number or boolean"},
      {"camera = 3", "rig.toml:1: camera: expected an array of tables"},
      {"daemon = 3", "rig.toml:1: daemon: expected a table"},
  };
  for (const auto& c : cases) {
    auto e = parseError(c.text);
    EXPECT_TRUE(contains(e.message, c.expected))
        << "got: " << e.message << "\nwanted: " << c.expected;
  }
}

TEST(Config, CalibrationSettleIsANumberOrAuto) {
  auto cfg = parseConfig("", "rig.toml");
  ASSERT_TRUE(cfg);
  EXPECT_EQ(cfg->calibration.settle_frames, 2);
  EXPECT_FALSE(cfg->calibration.auto_settle);
  cfg = parseConfig(
      "[calibration]\nsettle_frames = \"auto\"\nmargin_frames = 3\nlatency_repeats = 5\n"
      "latency_timeout_s = 0.5\n",
      "rig.toml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_TRUE(cfg->calibration.auto_settle);
  EXPECT_EQ(cfg->calibration.margin_frames, 3);
  EXPECT_EQ(cfg->calibration.latency_repeats, 5);
  EXPECT_EQ(cfg->calibration.latency_timeout_s, 0.5);
  cfg = parseConfig("[calibration]\nsettle_frames = 12\n", "rig.toml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->calibration.settle_frames, 12);
  EXPECT_FALSE(cfg->calibration.auto_settle);
  struct Case {
    const char* text;
    const char* expected;
  } cases[] = {
      {"[calibration]\nsettle_frames = \"soon\"",
       "rig.toml:2: calibration.settle_frames: expected an integer or \"auto\""},
      {"[calibration]\nsettle_frames = 601",
       "rig.toml:2: calibration.settle_frames: 601 is out of range [0, 600]"},
      {"[calibration]\nlatency_repeats = 0",
       "rig.toml:2: calibration.latency_repeats: 0 is out of range [1, 20]"},
      {"[calibration]\nlatency_timeout_s = 0.01",
       "rig.toml:2: calibration.latency_timeout_s: 0.01 is out of range"},
      {"[calibration]\nsettle = 2", "rig.toml:2: calibration.settle: unknown key"},
  };
  for (const auto& c : cases) {
    auto e = parseError(c.text);
    EXPECT_TRUE(contains(e.message, c.expected))
        << "got: " << e.message << "\nwanted: " << c.expected;
  }
}

TEST(Config, ContentViewerIsThreeNumbers) {
  auto cfg = parseConfig("", "rig.toml");
  ASSERT_TRUE(cfg);
  EXPECT_FALSE(cfg->content_viewer);
  cfg = parseConfig("[content]\nviewer = [0.5, -1, 1.75]\n", "rig.toml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  ASSERT_TRUE(cfg->content_viewer);
  EXPECT_EQ(*cfg->content_viewer, (std::array<double, 3>{0.5, -1, 1.75}));
  EXPECT_TRUE(contains(parseError("[content]\nviewer = [1, 2]").message,
                       "rig.toml:2: content.viewer: expected an array of 3 numbers"));
  EXPECT_TRUE(contains(parseError("[content]\neye = [1, 2, 3]").message,
                       "rig.toml:2: content.eye: unknown key"));
}

TEST(Config, ContentProjectionIsPerspectiveOrADomeMaster) {
  auto cfg = parseConfig("", "rig.toml");
  ASSERT_TRUE(cfg);
  EXPECT_FALSE(cfg->content_dome);
  EXPECT_EQ(cfg->content_dome_front, (std::array<double, 3>{0, 1, 0}));
  EXPECT_EQ(cfg->content_dome_fov_deg, 180.0);
  cfg = parseConfig(
      "[content]\nprojection = \"dome\"\ndome_front = [1, 0, 0.5]\ndome_fov_deg = 220\n",
      "rig.toml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_TRUE(cfg->content_dome);
  EXPECT_EQ(cfg->content_dome_front, (std::array<double, 3>{1, 0, 0.5}));
  EXPECT_EQ(cfg->content_dome_fov_deg, 220.0);
  auto e = parseError(
      "[content]\nprojection = \"fisheye\"\ndome_front = [0, 0, 1]\ndome_fov_deg = 400\n");
  EXPECT_TRUE(contains(
      e.message, "rig.toml:2: content.projection: 'fisheye' is not one of: perspective, dome"))
      << e.message;
  EXPECT_TRUE(
      contains(e.message, "rig.toml:3: content.dome_front: must point away from the vertical"))
      << e.message;
  EXPECT_TRUE(contains(e.message, "rig.toml:4: content.dome_fov_deg")) << e.message;
}

TEST(Config, AllProblemsAreReportedAtOnce) {
  auto e = parseError("[daemon]\nfoo = 1\nmax_clients = -1\n[policy]\nbar = 2\n");
  EXPECT_TRUE(contains(e.message, "rig.toml:2: daemon.foo")) << e.message;
  EXPECT_TRUE(contains(e.message, "rig.toml:3: daemon.max_clients")) << e.message;
  EXPECT_TRUE(contains(e.message, "rig.toml:5: policy.bar")) << e.message;
}

TEST(Config, SyntaxErrorNamesLineAndColumn) {
  auto e = parseError("[daemon]\nlog_level = \"info\n");
  EXPECT_EQ(e.code, ErrorCode::kParse);
  EXPECT_TRUE(contains(e.message, "rig.toml:2:")) << e.message;
}

TEST(Config, MissingFileIsAnIoError) {
  auto cfg = loadConfig("/nonexistent/procamd.toml");
  ASSERT_FALSE(cfg);
  EXPECT_EQ(cfg.error().code, ErrorCode::kIo);
}

TEST(Config, ContentRootsAndLimits) {
  auto cfg = parseConfig(
      "[content]\nroots = [\"/srv/a\", \"/srv/b\"]\nallow_pipeline = true\n"
      "[limits]\nfile_mib = 8\nimage_pixels = 1000000\nframe_pixels = 2000000\n"
      "mesh_vertices = 10\nmesh_faces = 20\nface_indices = 5\nclient_jobs = 3\n",
      "rig.toml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->content_roots, (std::vector<std::string>{"/srv/a", "/srv/b"}));
  EXPECT_TRUE(cfg->content_allow_pipeline);
  EXPECT_EQ(cfg->limits.file_bytes, 8u << 20);
  EXPECT_EQ(cfg->limits.image_pixels, 1000000u);
  EXPECT_EQ(cfg->limits.frame_pixels, 2000000u);
  EXPECT_EQ(cfg->limits.mesh_vertices, 10u);
  EXPECT_EQ(cfg->limits.mesh_faces, 20u);
  EXPECT_EQ(cfg->limits.face_indices, 5u);
  EXPECT_EQ(cfg->limits.client_jobs, 3u);
  auto e = parseError("[content]\nroots = [\"relative/dir\"]\n[limits]\nimage_pixels = 0\n");
  EXPECT_TRUE(
      contains(e.message, "rig.toml:2: content.roots[0]: 'relative/dir' is not an absolute"))
      << e.message;
  EXPECT_TRUE(contains(e.message, "rig.toml:4: limits.image_pixels: 0 is out of range"))
      << e.message;
  e = parseError("[content]\nroots = []\n");
  EXPECT_TRUE(contains(e.message, "content.roots: expected an array of 1 to 64")) << e.message;
}

TEST(Config, DisplayRectangle) {
  auto cfg = parseConfig("[keystone]\ndisplay_centre = [0.1, 3, 1.45]\ndisplay_size = [1.6, 0.9]\n",
                         "rig.toml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  ASSERT_TRUE(cfg->keystone.display_centre && cfg->keystone.display_size);
  EXPECT_EQ((*cfg->keystone.display_centre)[2], 1.45);
  EXPECT_EQ((*cfg->keystone.display_size)[0], 1.6);
  auto e = parseError("[keystone]\ndisplay_centre = [0, 3, 1.5]\n");
  EXPECT_TRUE(contains(e.message,
                       "rig.toml:2: keystone.display_centre: display_centre and display_size go "
                       "together"))
      << e.message;
  e = parseError("[keystone]\ndisplay_size = [1.6, 0]\ndisplay_centre = [0, 3, 1.5]\n");
  EXPECT_TRUE(contains(e.message, "rig.toml:2: keystone.display_size[1]")) << e.message;
}

// Only a regular file of bounded size is read: a directory, a FIFO (which would
// block until a writer came) and a device (endless) are refused at once.
TEST(Config, OnlyARegularFileOfBoundedSizeIsRead) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("procam-config-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string fifo = (dir / "fifo.toml").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& path : {dir.string(), fifo, std::string("/dev/zero")}) {
    auto cfg = loadConfig(path);
    ASSERT_FALSE(cfg) << path;
    EXPECT_EQ(cfg.error().code, ErrorCode::kIo) << path;
    EXPECT_TRUE(contains(cfg.error().message, "not a regular file")) << cfg.error().message;
  }
  const std::string big = (dir / "big.toml").string();
  std::ofstream(big) << std::string(kMaxConfigBytes + 1, '#');
  auto cfg = loadConfig(big);
  ASSERT_FALSE(cfg);
  EXPECT_EQ(cfg.error().code, ErrorCode::kTooLarge);
  const std::string group = (dir / "group.toml").string();
  std::ofstream(group) << "[daemon]\n\ngroup = \"no-such-group-procam\"\n";
  cfg = loadConfig(group);
  ASSERT_FALSE(cfg);
  EXPECT_TRUE(
      contains(cfg.error().message, group + ":3: daemon.group: no group 'no-such-group-procam'"))
      << cfg.error().message;
  std::filesystem::remove_all(dir);
}

TEST(Config, DriftPolicyHasDefaultsAndBounds) {
  auto defaults = parseConfig("[policy]\nrecalibrate = \"on-drift\"\n", "rig.toml");
  ASSERT_TRUE(defaults) << defaults.error().message;
  EXPECT_DOUBLE_EQ(defaults->drift.period_s, 0.25);
  EXPECT_DOUBLE_EQ(defaults->drift.threshold_px, 0.5);
  EXPECT_DOUBLE_EQ(defaults->drift.settle_s, 0.5);
  EXPECT_EQ(defaults->drift.frames, 2);
  EXPECT_DOUBLE_EQ(defaults->drift.fiducial_period_s, 10.0);
  EXPECT_DOUBLE_EQ(defaults->drift.stream_period_s, 5.0);
  EXPECT_EQ(defaults->recalibrate, RecalibratePolicy::kOnDrift);
  auto set = parseConfig(
      "[policy]\nrecalibrate = \"on-drift-silent\"\ndrift_period_s = 1\n"
      "drift_threshold_px = 0.3\ndrift_settle_s = 0\ndrift_frames = 4\n"
      "drift_fiducial_period_s = 0\ndrift_stream_period_s = 30\n",
      "rig.toml");
  ASSERT_TRUE(set) << set.error().message;
  EXPECT_EQ(set->recalibrate, RecalibratePolicy::kOnDriftSilent);
  EXPECT_STREQ(recalibratePolicyName(set->recalibrate), "on-drift-silent");
  EXPECT_TRUE(watchesDrift(set->recalibrate));
  EXPECT_FALSE(watchesDrift(RecalibratePolicy::kOff));
  EXPECT_DOUBLE_EQ(set->drift.period_s, 1.0);
  EXPECT_DOUBLE_EQ(set->drift.threshold_px, 0.3);
  EXPECT_DOUBLE_EQ(set->drift.settle_s, 0.0);
  EXPECT_EQ(set->drift.frames, 4);
  EXPECT_DOUBLE_EQ(set->drift.fiducial_period_s, 0.0);
  EXPECT_DOUBLE_EQ(set->drift.stream_period_s, 30.0);
  auto bad = parseConfig("[policy]\ndrift_fiducial_period_s = -1\n", "rig.toml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("policy.drift_fiducial_period_s"), std::string::npos);
  bad = parseConfig("[policy]\ndrift_stream_period_s = 4000\n", "rig.toml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("policy.drift_stream_period_s"), std::string::npos);
}

TEST(Config, ExampleConfigParses) {
  auto cfg =
      loadConfig(std::string(std::getenv("PROCAM_SOURCE_DIR")) + "/daemon/procamd.toml.example");
  ASSERT_TRUE(cfg) << cfg.error().message;
}

}  // namespace
}  // namespace procam::daemon
