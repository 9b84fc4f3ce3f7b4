// The V4L2 camera against a simulated device behind its ioctl seam: negotiation, the
// buffer state machine, controls, a device that vanishes, and enumeration.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "camera/plugin/camera_plugin.hpp"
#include "camera/v4l2/v4l2_camera.hpp"
#include "fake_v4l2.hpp"

namespace procam::camera {
namespace {

using testing::FakeV4l2;
using testing::FakeV4l2State;

std::shared_ptr<FakeV4l2State> uvcLike() {
  auto s = std::make_shared<FakeV4l2State>();
  s->formats = {{V4L2_PIX_FMT_MJPEG, {{1280, 720}, {640, 480}}},
                {V4L2_PIX_FMT_YUYV, {{320, 240}, {640, 480}, {160, 120}}}};
  s->addControl(V4L2_CID_EXPOSURE_AUTO, 0, 3, V4L2_EXPOSURE_APERTURE_PRIORITY);
  s->addControl(V4L2_CID_EXPOSURE_ABSOLUTE, 1, 5000, 156);
  s->addControl(V4L2_CID_POWER_LINE_FREQUENCY, 0, 2, 0);
  return s;
}

std::shared_ptr<FakeV4l2State> monoCamera() {
  auto s = std::make_shared<FakeV4l2State>();
  s->formats = {{V4L2_PIX_FMT_GREY, {{64, 48}}}, {V4L2_PIX_FMT_Y16, {{64, 48}}}};
  s->padding = 16;  // bytesperline 80: the frame must honour the stride
  s->addControl(V4L2_CID_GAIN, 0, 100, 10);
  return s;
}

V4l2Camera camera(std::shared_ptr<FakeV4l2State> s, V4l2Options o = {}) {
  if (o.device.empty()) o.device = "/dev/video0";
  return V4l2Camera(o, std::make_unique<FakeV4l2>(std::move(s)));
}

TEST(V4l2Negotiation, PrefersUncompressedAndTheLargestSize) {
  auto s = uvcLike();
  auto cam = camera(s);
  ASSERT_TRUE(cam.start());
  EXPECT_EQ(cam.fourcc(), uint32_t(V4L2_PIX_FMT_YUYV));  // YUYV before MJPEG
  EXPECT_EQ(cam.format().width, 640u);
  EXPECT_EQ(cam.format().height, 480u);
  EXPECT_EQ(cam.format().pixel, PROCAM_PIXEL_RGB8);
  EXPECT_EQ(cam.info().card, "Fake Camera");
  EXPECT_EQ(cam.info().bus_info, "usb-0000:00:14.0-1");
}

TEST(V4l2Negotiation, AskedFormatAndSize) {
  auto s = uvcLike();
  V4l2Options o;
  o.fourcc = V4L2_PIX_FMT_MJPEG;
  o.width = 1280;
  o.height = 720;
  o.fps = 30;
  auto cam = camera(s, o);
  ASSERT_TRUE(cam.start());
  EXPECT_EQ(s->fmt.pixelformat, uint32_t(V4L2_PIX_FMT_MJPEG));
  EXPECT_EQ(s->fmt.width, 1280u);
  EXPECT_EQ(s->timeperframe_set.numerator * 30, s->timeperframe_set.denominator);
}

TEST(V4l2Negotiation, RefusesWhatTheDeviceDoesNotOffer) {
  {
    V4l2Options o;
    o.width = 800;
    o.height = 600;
    auto cam = camera(uvcLike(), o);
    auto r = cam.start();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kNotSupported);
    EXPECT_NE(r.error().message.find("offers: 320x240, 640x480, 160x120"), std::string::npos)
        << r.error().message;
  }
  {
    V4l2Options o;
    o.fourcc = V4L2_PIX_FMT_GREY;
    auto cam = camera(uvcLike(), o);
    auto r = cam.start();
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("offers: MJPG, YUYV"), std::string::npos) << r.error().message;
  }
  {
    auto s = monoCamera();
    s->timeperframe = false;
    V4l2Options o;
    o.fps = 60;
    auto cam = camera(s, o);
    auto r = cam.start();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kNotSupported);
    EXPECT_FALSE(s->open);  // a failed start closes the node
  }
}

TEST(V4l2Buffers, AtLeastFourAreMappedAndQueued) {
  auto s = monoCamera();
  V4l2Options o;
  o.buffers = 6;
  auto cam = camera(s, o);
  ASSERT_TRUE(cam.start());
  EXPECT_EQ(cam.bufferCount(), 6u);
  EXPECT_EQ(s->maps, 6);
  EXPECT_EQ(s->incoming.size(), 6u);
  EXPECT_TRUE(s->streaming);
  cam.stop();
  EXPECT_EQ(s->unmaps, 6);
  EXPECT_FALSE(s->streaming);
  EXPECT_TRUE(s->buffers.empty());  // REQBUFS 0 released them
  EXPECT_FALSE(s->open);

  auto few = monoCamera();
  few->max_buffers = 2;
  auto cam2 = camera(few);
  auto r = cam2.start();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
  EXPECT_NE(r.error().message.find("granted 2 buffers"), std::string::npos);
  EXPECT_EQ(few->maps, few->unmaps);
}

TEST(V4l2Capture, FramesCycleThroughEveryBufferWithoutACopy) {
  auto s = monoCamera();
  auto cam = camera(s);
  ASSERT_TRUE(cam.start());
  EXPECT_EQ(cam.format().pixel, PROCAM_PIXEL_GRAY8);  // GREY preferred over Y16
  uint64_t last = 0;
  for (uint32_t n = 0; n < 10; ++n) {  // 10 frames through 4 buffers: each is requeued
    ASSERT_TRUE(s->produce());
    auto f = cam.capture(100);
    ASSERT_TRUE(f) << f.error().message;
    const Frame& fr = **f;
    EXPECT_EQ(fr.sequence, n);
    EXPECT_EQ(fr.copies, 0);
    EXPECT_EQ(fr.image.step[0], 80u);
    for (int y : {0, 17, 47})
      for (int x : {0, 5, 63}) EXPECT_EQ(fr.image.at<uint8_t>(y, x), (x + y + n) % 251);
    // The buffer's timestamp (CLOCK_MONOTONIC), 30 fps from 5 s.
    EXPECT_EQ(fr.timestamp_ns, 5'000'000'000ull + n * 33'333'000ull);
    EXPECT_GT(fr.timestamp_ns, last);
    last = fr.timestamp_ns;
    // The frame's buffer stays with the driver until the next capture.
    EXPECT_EQ(s->incoming.size(), 3u);
  }
  EXPECT_EQ(s->qbuf_errors, 0);
}

TEST(V4l2Capture, NothingWaitingTimeoutAndCorruptFrames) {
  auto s = monoCamera();
  auto cam = camera(s);
  ASSERT_TRUE(cam.start());
  EXPECT_EQ(cam.capture(0).error().code, ErrorCode::kAgain);
  EXPECT_EQ(cam.capture(20).error().code, ErrorCode::kTimeout);
  ASSERT_TRUE(s->produce(true));
  auto bad = cam.capture(20);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kIo);
  EXPECT_EQ(s->incoming.size(), 4u);  // the corrupt buffer went straight back
  ASSERT_TRUE(s->produce());
  EXPECT_TRUE(cam.capture(20));
  EXPECT_EQ(s->qbuf_errors, 0);
}

TEST(V4l2Capture, SixteenBitAndYuyvAreConverted) {
  auto s = monoCamera();
  V4l2Options o;
  o.fourcc = V4L2_PIX_FMT_Y16;
  auto cam = camera(s, o);
  ASSERT_TRUE(cam.start());
  EXPECT_EQ(cam.format().pixel, PROCAM_PIXEL_GRAY16);
  ASSERT_TRUE(s->produce());
  ASSERT_TRUE(s->produce());
  ASSERT_TRUE(cam.capture(0));
  auto f = cam.capture(0);
  ASSERT_TRUE(f);
  EXPECT_EQ((*f)->image.at<uint16_t>(3, 4), (4 + 3 + 1) * 256);

  auto y = uvcLike();
  V4l2Options g;
  g.pixel = PROCAM_PIXEL_GRAY8;
  auto cam2 = camera(y, g);
  ASSERT_TRUE(cam2.start());
  ASSERT_TRUE(y->produce());
  auto f2 = cam2.capture(0);
  ASSERT_TRUE(f2);
  EXPECT_EQ((*f2)->copies, 1);
  // Limited-range luma 100 stretched: (100 - 16) * 255 / 219.
  EXPECT_NEAR((*f2)->image.at<uint8_t>(40, 60), (100 - 16) * 255.0 / 219.0, 0.6);
}

TEST(V4l2Controls, ManualExposureGainPowerLineAndWhatIsMissing) {
  auto s = uvcLike();
  auto cam = camera(s);
  ASSERT_TRUE(cam.start());
  ASSERT_TRUE(cam.setControl(Control::kAutoExposure, 0));
  EXPECT_EQ(s->values[V4L2_CID_EXPOSURE_AUTO], V4L2_EXPOSURE_MANUAL);
  ASSERT_TRUE(cam.setControl(Control::kExposure, 0.02));
  EXPECT_EQ(s->values[V4L2_CID_EXPOSURE_ABSOLUTE], 200);  // 100 µs units
  auto far = cam.setControl(Control::kExposure, 1.0);     // 10000 > 5000
  ASSERT_FALSE(far);
  EXPECT_EQ(far.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(far.error().message.find("[1, 5000]"), std::string::npos);
  ASSERT_TRUE(cam.setControl(Control::kPowerLine, 50));
  EXPECT_EQ(s->values[V4L2_CID_POWER_LINE_FREQUENCY], V4L2_CID_POWER_LINE_FREQUENCY_50HZ);
  EXPECT_EQ(cam.setControl(Control::kPowerLine, 55).error().code, ErrorCode::kInvalidInput);
  auto gain = cam.setControl(Control::kGain, 3);
  ASSERT_FALSE(gain);
  EXPECT_EQ(gain.error().code, ErrorCode::kNotSupported);
  EXPECT_NE(gain.error().message.find("gain is not supported by this device"), std::string::npos);
  EXPECT_EQ(cam.setControl(Control::kWhiteBalance, 5000).error().code, ErrorCode::kNotSupported);

  auto m = monoCamera();
  auto mono = camera(m);
  ASSERT_TRUE(mono.start());
  ASSERT_TRUE(mono.setControl(Control::kGain, 42));
  EXPECT_EQ(m->values[V4L2_CID_GAIN], 42);
  EXPECT_EQ(mono.setControl(Control::kExposure, 0.01).error().code, ErrorCode::kNotSupported);
}

// What `snapshot` reports: the values in effect, read from the device (the
// camera's own changes included), nothing for a control it lacks.
TEST(V4l2Controls, ExposureAndGainAreReadBackFromTheDevice) {
  auto s = uvcLike();
  auto cam = camera(s);
  ASSERT_TRUE(cam.start());
  ASSERT_TRUE(cam.exposureSeconds());
  EXPECT_DOUBLE_EQ(*cam.exposureSeconds(), 0.0156);  // 156 x 100 µs
  ASSERT_TRUE(cam.setControl(Control::kExposure, 0.02));
  EXPECT_DOUBLE_EQ(*cam.exposureSeconds(), 0.02);
  s->values[V4L2_CID_EXPOSURE_ABSOLUTE] = 333;  // automatic exposure moved it
  EXPECT_DOUBLE_EQ(*cam.exposureSeconds(), 0.0333);
  EXPECT_FALSE(cam.gain());
  EXPECT_FALSE(cam.gainInDb());

  auto m = monoCamera();
  auto mono = camera(m);
  ASSERT_TRUE(mono.start());
  EXPECT_FALSE(mono.exposureSeconds());
  ASSERT_TRUE(mono.setControl(Control::kGain, 42));
  ASSERT_TRUE(mono.gain());
  EXPECT_DOUBLE_EQ(*mono.gain(), 42.0);
}

TEST(V4l2Vanish, UnplugGivesNoDeviceAndACleanStop) {
  auto s = monoCamera();
  auto cam = camera(s);
  ASSERT_TRUE(cam.start());
  ASSERT_TRUE(s->produce());
  ASSERT_TRUE(cam.capture(0));
  s->vanished = true;
  auto r = cam.capture(100);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kNoDevice);
  cam.stop();
  EXPECT_EQ(s->maps, s->unmaps);
  // Reopening while it is gone fails the same way.
  auto again = cam.start();
  ASSERT_FALSE(again);
  EXPECT_EQ(again.error().code, ErrorCode::kNoDevice);
}

TEST(V4l2Plugin, ProbeOptionsAndEnodevThroughTheAbi) {
  const procam_kv role[] = {{"PROCAM_ROLE", "camera"}};
  procam_device_desc desc{
      PROCAM_FAMILY_CAMERA, "video4linux", "/dev/video0", nullptr, nullptr, role, 1};
  EXPECT_EQ(plugin::kV4l2Factory.probe(&desc), 50);
  procam_device_desc tilt = desc;
  tilt.family = PROCAM_FAMILY_TILT;
  EXPECT_EQ(plugin::kV4l2Factory.probe(&tilt), 0);

  auto s = uvcLike();
  const procam_kv opts[] = {
      {"width", "320"}, {"height", "240"}, {"exposure_s", "0.01"}, {"power_line_hz", "60"}};
  procam_config config{opts, 4};
  procam_device dev{};
  char err[256] = {};
  ASSERT_EQ(
      plugin::createV4l2On(std::make_unique<FakeV4l2>(s), &desc, &config, &dev, err, sizeof err),
      PROCAM_OK)
      << err;
  EXPECT_EQ(s->values[V4L2_CID_EXPOSURE_AUTO], V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(s->values[V4L2_CID_EXPOSURE_ABSOLUTE], 100);
  EXPECT_EQ(s->values[V4L2_CID_POWER_LINE_FREQUENCY], V4L2_CID_POWER_LINE_FREQUENCY_60HZ);
  EXPECT_EQ(dev.poll_fd(dev.self), 42);
  procam_image img{};
  EXPECT_EQ(dev.ops.camera->capture(dev.self, 0, &img, err, sizeof err), PROCAM_EAGAIN);
  ASSERT_TRUE(s->produce());
  ASSERT_EQ(dev.ops.camera->capture(dev.self, 0, &img, err, sizeof err), PROCAM_OK) << err;
  EXPECT_EQ(img.width, 320u);
  EXPECT_EQ(img.format, PROCAM_PIXEL_RGB8);
  s->vanished = true;
  EXPECT_EQ(dev.ops.camera->capture(dev.self, 10, &img, err, sizeof err), PROCAM_ENODEV);
  dev.destroy(dev.self);
  EXPECT_EQ(s->maps, s->unmaps);

  // A control the camera lacks refuses the device; so does an unknown option.
  const procam_kv gain[] = {{"gain", "2"}};
  procam_config gainConfig{gain, 1};
  auto s2 = uvcLike();
  EXPECT_EQ(plugin::createV4l2On(std::make_unique<FakeV4l2>(s2), &desc, &gainConfig, &dev, err,
                                 sizeof err),
            PROCAM_ENOTSUP);
  EXPECT_FALSE(s2->open);
  const procam_kv three[] = {{"buffers", "3"}};
  procam_config threeConfig{three, 1};
  EXPECT_EQ(plugin::createV4l2On(std::make_unique<FakeV4l2>(uvcLike()), &desc, &threeConfig, &dev,
                                 err, sizeof err),
            PROCAM_EINVAL);
  EXPECT_NE(std::string(err).find("v4l2 camera: option buffers: 3 is not in 4..64"),
            std::string::npos)
      << err;
  const procam_kv bad[] = {{"format", "H264"}};
  procam_config badConfig{bad, 1};
  EXPECT_EQ(plugin::createV4l2On(std::make_unique<FakeV4l2>(uvcLike()), &desc, &badConfig, &dev,
                                 err, sizeof err),
            PROCAM_EINVAL);
}

TEST(V4l2Enumerate, NoDevicesIsAnEmptyList) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("procam-v4l2-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto io = systemV4l2Io();
  EXPECT_TRUE(enumerateV4l2(*io, dir.string()).empty());
  // A node that is not a V4L2 device (QUERYCAP fails) is left out.
  std::ofstream(dir / "video0") << "not a device";
  EXPECT_TRUE(enumerateV4l2(*io, dir.string()).empty());
  EXPECT_TRUE(enumerateV4l2(*io, (dir / "missing").string()).empty());
  fs::remove_all(dir);
  // The fake answers QUERYCAP as a capture device.
  auto s = monoCamera();
  FakeV4l2 fake(s);
  const fs::path fakeDir =
      fs::temp_directory_path() / ("procam-v4l2f-" + std::to_string(::getpid()));
  fs::create_directories(fakeDir);
  std::ofstream(fakeDir / "video3") << "";
  std::ofstream(fakeDir / "vbi0") << "";
  auto list = enumerateV4l2(fake, fakeDir.string());
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].devnode, (fakeDir / "video3").string());
  EXPECT_EQ(list[0].driver, "fake");
  fs::remove_all(fakeDir);
}

}  // namespace
}  // namespace procam::camera
