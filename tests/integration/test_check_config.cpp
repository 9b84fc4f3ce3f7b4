// procamd --check-config: what an installer and the service's ExecStartPre= run to
// validate a configuration without starting the daemon.
#include <gtest/gtest.h>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

RunResult check(const std::string& path) {
  return runProgram({PROCAMD_BIN, "--check-config", path, "--plugin-dir", PROCAM_FIXTURE_DIR});
}

TEST(CheckConfig, ValidFileExitsZeroAndCountsItsDevices) {
  TempDir dir;
  dir.write("ok.toml",
            "[daemon]\nlog_level = \"debug\"\n[[camera]]\nname = \"cam0\"\ndriver = \"v4l2\"\n"
            "[[projector]]\nname = \"main\"\ndriver = \"headless\"\n[[tilt]]\nname = \"imu\"\n");
  const RunResult r = check(dir.file("ok.toml"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("ok.toml: valid (3 devices configured)"), std::string::npos) << r.out;
  // Nothing was started: no socket, no state directory.
  EXPECT_FALSE(std::filesystem::exists(dir.file("run")));
}

TEST(CheckConfig, ProblemsNameFileLineAndKey) {
  TempDir dir;
  dir.write("values.toml", "[daemon]\nmax_clients = \"many\"\n[policy]\nfrobnicate = 1\n");
  RunResult r = check(dir.file("values.toml"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("values.toml:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("daemon.max_clients"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("values.toml:4:"), std::string::npos) << r.err;

  // A driver that is neither built in nor in the plugin directory.
  dir.write("driver.toml",
            "[[camera]]\nname = \"a\"\n\n[[camera]]\nname = \"b\"\ndriver = \"v4l3\"\n");
  r = check(dir.file("driver.toml"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("driver.toml:6: camera[1].driver: no camera driver named 'v4l3'"),
            std::string::npos)
      << r.err;

  dir.write("syntax.toml", "[daemon\n");
  r = check(dir.file("syntax.toml"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("syntax.toml:1:"), std::string::npos) << r.err;

  r = check(dir.file("absent.toml"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("cannot open config file"), std::string::npos) << r.err;
  r = check(dir.path());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace procam::itest
