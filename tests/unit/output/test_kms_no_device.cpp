// The KMS output on a machine without a DRM device: a typed error naming the cause.
#include <gtest/gtest.h>

#include <filesystem>

#include "kms/kms_output.hpp"

namespace procam::output::kms {
namespace {

bool hasDrmCard() {
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/dev/dri", ec)) {
    if (e.path().filename().string().rfind("card", 0) == 0) return true;
  }
  return false;
}

TEST(KmsOutput, ReportsNoDrmDeviceCleanly) {
  if (hasDrmCard()) GTEST_SKIP() << "this machine has a DRM card";
  auto out = KmsOutput::create(KmsConfig{});
  ASSERT_FALSE(out);
  EXPECT_EQ(out.error().code, ErrorCode::kNotFound);
  EXPECT_NE(out.error().message.find("no DRM device"), std::string::npos) << out.error().message;
}

TEST(KmsOutput, NamedMissingNodeIsNotFound) {
  auto out = KmsOutput::create(KmsConfig{"/dev/dri/card97", {}, 1000});
  ASSERT_FALSE(out);
  EXPECT_EQ(out.error().code, ErrorCode::kNotFound);
  EXPECT_NE(out.error().message.find("/dev/dri/card97"), std::string::npos);
}

}  // namespace
}  // namespace procam::output::kms
