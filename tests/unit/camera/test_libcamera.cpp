// libcamera on a system without cameras (libcamera 0.0.3 has no virtual pipeline): the
// CameraManager starts, lists nothing, and opening is a clean "no camera".
#include <gtest/gtest.h>

#include "camera/libcamera/libcamera_camera.hpp"
#include "camera/plugin/camera_plugin.hpp"

namespace procam::camera {
namespace {

TEST(Libcamera, EmptySystemIsACleanNoCamera) {
  auto ids = libcameraCameraIds();
  ASSERT_TRUE(ids) << ids.error().message;
  if (!ids->empty()) GTEST_SKIP() << "this machine has cameras; the test needs none";
  LibcameraCamera cam({});
  auto r = cam.start();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kNoDevice);
  EXPECT_NE(r.error().message.find("no camera"), std::string::npos) << r.error().message;
  EXPECT_EQ(cam.pollFd(), -1);
  EXPECT_EQ(cam.capture(0).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(cam.setControl(Control::kExposure, 0.01).error().code, ErrorCode::kInvalidInput);
  cam.stop();  // stopping what never started is harmless

  // Through the plugin ABI: ENODEV with the reason, so the daemon retries later.
  procam_device_desc desc{PROCAM_FAMILY_CAMERA, "libcamera", nullptr, nullptr, "cam", nullptr, 0};
  EXPECT_EQ(plugin::kLibcameraFactory.probe(&desc), 60);
  procam_device dev{};
  char err[256] = {};
  EXPECT_EQ(plugin::kLibcameraFactory.create(&desc, nullptr, &dev, err, sizeof err), PROCAM_ENODEV);
  EXPECT_NE(std::string(err).find("no camera"), std::string::npos) << err;
}

}  // namespace
}  // namespace procam::camera
