// The outputs through the driver plugin ABI.
#include <gtest/gtest.h>
#include <procamd/procam_plugin.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

extern "C" const procam_plugin_table* procam_output_plugin_entry(void);

namespace {

const procam_driver_factory* factory(const char* name) {
  const procam_plugin_table* t = procam_output_plugin_entry();
  for (size_t i = 0; i < t->n_factories; ++i) {
    if (std::strcmp(t->factories[i].name, name) == 0) return &t->factories[i];
  }
  return nullptr;
}

TEST(OutputPlugin, HeadlessShowsFramesOfItsModeAndRejectsOthers) {
  const procam_plugin_table* t = procam_output_plugin_entry();
  EXPECT_EQ(t->abi_version, PROCAM_PLUGIN_ABI_VERSION);
  const procam_driver_factory* f = factory("headless");
  ASSERT_NE(f, nullptr);
  procam_device_desc desc{};
  desc.family = PROCAM_FAMILY_OUTPUT;
  desc.subsystem = "headless";
  EXPECT_GT(f->probe(&desc), 0);
  desc.subsystem = "video4linux";
  EXPECT_EQ(f->probe(&desc), 0);
  desc.subsystem = "headless";
  const procam_kv opts[] = {{"width", "64"}, {"height", "48"}};
  const procam_config config{opts, 2};
  procam_device dev{};
  char err[256] = {};
  ASSERT_EQ(f->create(&desc, &config, &dev, err, sizeof(err)), PROCAM_OK) << err;
  uint32_t w = 0, h = 0;
  double hz = 0;
  ASSERT_EQ(dev.ops.output->get_mode(dev.self, &w, &h, &hz), PROCAM_OK);
  EXPECT_EQ(w, 64u);
  EXPECT_EQ(h, 48u);
  EXPECT_EQ(dev.poll_fd(dev.self), -1);
  std::vector<uint8_t> rgb(64 * 48 * 3, 77);
  procam_image frame{64, 48, 64 * 3, PROCAM_PIXEL_RGB8, rgb.data(), 0};
  EXPECT_EQ(dev.ops.output->show(dev.self, &frame, err, sizeof(err)), PROCAM_OK) << err;
  frame.width = 32;
  EXPECT_EQ(dev.ops.output->show(dev.self, &frame, err, sizeof(err)), PROCAM_EINVAL);
  EXPECT_NE(std::string(err).find("mode"), std::string::npos);
  dev.destroy(dev.self);
  const procam_kv bad[] = {{"width", "wide"}};
  const procam_config bad_config{bad, 1};
  EXPECT_EQ(f->create(&desc, &bad_config, &dev, err, sizeof(err)), PROCAM_EINVAL);
}

TEST(OutputPlugin, KmsReportsNoDrmDeviceAsNoDevice) {
  const procam_driver_factory* f = factory("kms");
  if (!f) GTEST_SKIP() << "built without libdrm/gbm";
  std::error_code ec;
  if (std::filesystem::exists("/dev/dri", ec)) GTEST_SKIP() << "this machine has /dev/dri";
  procam_device_desc desc{};
  desc.family = PROCAM_FAMILY_OUTPUT;
  desc.subsystem = "drm";
  EXPECT_GT(f->probe(&desc), 0);
  procam_device dev{};
  char err[256] = {};
  EXPECT_EQ(f->create(&desc, nullptr, &dev, err, sizeof(err)), PROCAM_ENODEV);
  EXPECT_NE(std::string(err).find("no DRM device"), std::string::npos) << err;
}

}  // namespace
