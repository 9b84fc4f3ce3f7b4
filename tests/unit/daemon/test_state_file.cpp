// Atomic state files: replace, backup of the previous valid version, recovery
// from a corrupt file, never a corrupt backup.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "state_file.hpp"

namespace procam::daemon {
namespace {

namespace fs = std::filesystem;

// Valid: text starting with "ok:".
Result<void> startsWithOk(std::string_view text) {
  if (text.substr(0, 3) == "ok:") return {};
  return fail(ErrorCode::kParse, "does not start with ok:");
}

class StateFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("procam-state-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void put(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  StateFile file() const { return StateFile(dir_.string(), "s.json", startsWithOk); }
  fs::path dir_;
};

TEST_F(StateFileTest, MissingIsNotFound) {
  auto f = file();
  ASSERT_TRUE(f.ensureDirectory());
  auto r = f.read();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
}

TEST_F(StateFileTest, WriteThenReadAndBackupHoldsPrevious) {
  auto f = file();
  ASSERT_TRUE(f.ensureDirectory());
  ASSERT_TRUE(f.write("ok:1"));
  ASSERT_TRUE(f.write("ok:2"));
  auto r = f.read();
  ASSERT_TRUE(r);
  EXPECT_EQ(r->contents, "ok:2");
  EXPECT_FALSE(r->from_backup);
  EXPECT_EQ(*readWholeFile(f.backupPath()), "ok:1");
  EXPECT_FALSE(fs::exists(f.path() + ".tmp"));
  struct stat st {};
  ASSERT_EQ(::stat(f.path().c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
}

TEST_F(StateFileTest, CorruptFileIsReportedAndBackupUsed) {
  auto f = file();
  ASSERT_TRUE(f.ensureDirectory());
  ASSERT_TRUE(f.write("ok:old"));
  ASSERT_TRUE(f.write("ok:new"));
  put("s.json", "garbage");
  auto r = f.read();
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(r->from_backup);
  EXPECT_EQ(r->contents, "ok:old");
  EXPECT_NE(r->warning.find("is corrupt: does not start with ok:"), std::string::npos)
      << r->warning;
}

TEST_F(StateFileTest, CorruptFileNeverReplacesGoodBackup) {
  auto f = file();
  ASSERT_TRUE(f.ensureDirectory());
  ASSERT_TRUE(f.write("ok:a"));
  ASSERT_TRUE(f.write("ok:b"));
  put("s.json", "garbage");
  ASSERT_TRUE(f.write("ok:c"));
  EXPECT_EQ(*readWholeFile(f.backupPath()), "ok:a");
  EXPECT_EQ(f.read()->contents, "ok:c");
}

TEST_F(StateFileTest, BothCorruptIsAParseErrorNamingBoth) {
  auto f = file();
  ASSERT_TRUE(f.ensureDirectory());
  put("s.json", "bad1");
  put("s.json.bak", "bad2");
  auto r = f.read();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kParse);
  EXPECT_NE(r.error().message.find("corrupt too"), std::string::npos) << r.error().message;
}

TEST_F(StateFileTest, LeftoverTemporaryFromACrashIsIgnoredAndReplaced) {
  auto f = file();
  ASSERT_TRUE(f.ensureDirectory());
  ASSERT_TRUE(f.write("ok:saved"));
  put("s.json.tmp", "ok:half-writ");  // a crash between write and rename
  EXPECT_EQ(f.read()->contents, "ok:saved");
  ASSERT_TRUE(f.write("ok:next"));
  EXPECT_EQ(f.read()->contents, "ok:next");
  EXPECT_FALSE(fs::exists(f.path() + ".tmp"));
}

TEST_F(StateFileTest, UnwritableDirectoryIsAnIoError) {
  StateFile f("/proc/procam-no-such-dir", "s.json", startsWithOk);
  auto r = f.write("ok:x");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
}

}  // namespace
}  // namespace procam::daemon
