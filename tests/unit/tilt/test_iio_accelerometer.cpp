#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "fake_iio.hpp"
#include "tilt/iio/iio_accelerometer.hpp"

namespace procam::tilt {
namespace {

namespace fs = std::filesystem;
using testing::FakeIioTree;

TEST(IioScanType, ParsesAndDecodesKernelFormats) {
  auto t = parseIioScanType("le:s12/16>>4");
  ASSERT_TRUE(t);
  const std::uint8_t neg[2] = {0x00, 0x80};  // 0x8000 >> 4 = -2048 in 12 bits
  EXPECT_EQ(t->decode(neg), -2048);
  auto b = parseIioScanType("be:s14/16>>2");
  ASSERT_TRUE(b);
  const std::uint8_t v[2] = {0xFF, 0xFC};  // -1 << 2
  EXPECT_EQ(b->decode(v), -1);
  auto u = parseIioScanType("le:u16/16X2>>0");
  ASSERT_TRUE(u);
  EXPECT_EQ(u->repeat, 2);
  EXPECT_FALSE(parseIioScanType("le:s20/16>>0"));
  EXPECT_FALSE(parseIioScanType("xx:s16/16>>0"));
  std::vector<IioScanChannel> ch = {{"timestamp", 3, *parseIioScanType("le:s64/64>>0"), 0},
                                    {"accel_x", 0, *t, 0},
                                    {"accel_y", 1, *t, 0},
                                    {"accel_z", 2, *t, 0}};
  EXPECT_EQ(layoutIioRecord(ch), 16u);  // 3 x 2 bytes, timestamp aligned to 8
  EXPECT_EQ(ch[3].offset, 8u);
}

TEST(IioAccelerometer, PolledSysfsAppliesOffsetAndScale) {
  FakeIioTree tree;
  tree.set("in_accel_x_raw", "100");
  tree.set("in_accel_y_raw", "-200");
  tree.set("in_accel_z_raw", "1000");
  tree.set("in_accel_scale", "0.009806650");    // 1 mg per count
  tree.set("in_accel_x_scale", "0.019613300");  // per-axis wins
  tree.set("in_accel_z_offset", "-10");
  tree.set("sampling_frequency", "50");
  IioAccelerometer sensor({tree.dir().string(), "", false, 100.0, 64, 10});
  ASSERT_TRUE(sensor.open());
  EXPECT_EQ(tree.get("sampling_frequency"), "100.000000");  // requested rate written
  auto s = sensor.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR(s->specific_force.x(), 100 * 0.0196133, 1e-12);
  EXPECT_NEAR(s->specific_force.y(), -200 * 0.00980665, 1e-12);
  EXPECT_NEAR(s->specific_force.z(), 990 * 0.00980665, 1e-12);
  tree.set("in_accel_y_raw", "garbage");
  EXPECT_EQ(sensor.read().error().code, ErrorCode::kParse);
}

TEST(IioAccelerometer, BufferedRecordsThroughTheCharacterDevice) {
  FakeIioTree tree;
  for (const char* a : {"x", "y", "z"}) tree.set(std::string("in_accel_") + a + "_raw", "0");
  tree.set("in_accel_scale", "0.00980665");
  int index = 0;
  for (const char* ch : {"accel_x", "accel_y", "accel_z"}) {
    tree.set(std::string("scan_elements/in_") + ch + "_en", "0");
    tree.set(std::string("scan_elements/in_") + ch + "_index", std::to_string(index++));
    tree.set(std::string("scan_elements/in_") + ch + "_type", "le:s12/16>>4");
  }
  tree.set("scan_elements/in_timestamp_en", "0");
  tree.set("scan_elements/in_timestamp_index", "3");
  tree.set("scan_elements/in_timestamp_type", "le:s64/64>>0");
  tree.set("buffer/length", "0");
  tree.set("buffer/enable", "0");
  // Two records: (100, -200, 1000) counts at t = 5 s, then (1, 2, 3) at 6 s.
  const fs::path node = tree.dir().parent_path() / "dev-iio-device0";
  {
    std::ofstream out(node, std::ios::binary);
    auto record = [&](int x, int y, int z, std::int64_t t) {
      std::uint8_t r[16] = {};
      const int v[3] = {x, y, z};
      for (int a = 0; a < 3; ++a) {
        const auto u = std::uint16_t(std::int16_t(v[a] * 16));
        r[2 * a] = std::uint8_t(u & 0xFF);
        r[2 * a + 1] = std::uint8_t(u >> 8);
      }
      std::memcpy(r + 8, &t, 8);  // little-endian host
      out.write(reinterpret_cast<const char*>(r), 16);
    };
    record(100, -200, 1000, 5'000'000'000);
    record(1, 2, 3, 6'000'000'000);
  }
  IioAccelerometer sensor({tree.dir().string(), node.string(), true, {}, 32, 10});
  ASSERT_TRUE(sensor.open());
  EXPECT_TRUE(sensor.buffered());
  EXPECT_EQ(tree.get("buffer/enable"), "1");
  EXPECT_EQ(tree.get("buffer/length"), "32");
  EXPECT_EQ(tree.get("scan_elements/in_accel_y_en"), "1");
  auto s = sensor.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR((s->specific_force - Vec3(100, -200, 1000) * 0.00980665).norm(), 0, 1e-12);
  EXPECT_EQ(s->timestamp_ns, 5'000'000'000u);
  s = sensor.read();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->timestamp_ns, 6'000'000'000u);
  EXPECT_EQ(sensor.read().error().code, ErrorCode::kNotFound);  // end of data
  sensor.close();
  EXPECT_EQ(tree.get("buffer/enable"), "0");
}

TEST(IioAccelerometer, CombinedImuGivesItsGyroscopeWithEverySample) {
  // Polled: an MPU-6050 under the kernel's inv_mpu6050 driver has anglvel channels
  // beside the accel ones (rad/s per count).
  FakeIioTree tree;
  for (const char* a : {"x", "y", "z"}) tree.set(std::string("in_accel_") + a + "_raw", "0");
  tree.set("in_accel_z_raw", "1000");
  tree.set("in_accel_scale", "0.00980665");
  tree.set("in_anglvel_x_raw", "655");
  tree.set("in_anglvel_y_raw", "-131");
  tree.set("in_anglvel_z_raw", "0");
  tree.set("in_anglvel_scale", "0.000133090");  // 1 / 131 deg/s per count
  tree.set("in_anglvel_z_offset", "10");
  IioAccelerometer polled({tree.dir().string(), "", false, {}, 64, 10});
  ASSERT_TRUE(polled.open());
  EXPECT_TRUE(polled.hasGyroscope());
  auto s = polled.read();
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_TRUE(s->angular_velocity);
  EXPECT_NEAR((*s->angular_velocity - Vec3(655, -131, 10) * 0.000133090).norm(), 0, 1e-12);
  tree.set("in_anglvel_x_raw", "nan?");  // the sample stays, without its rate
  s = polled.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_FALSE(s->angular_velocity);
  polled.close();

  // Buffered: the anglvel scan elements are enabled with the accel ones.
  int index = 0;
  for (const char* ch : {"accel_x", "accel_y", "accel_z", "anglvel_x", "anglvel_y", "anglvel_z"}) {
    tree.set(std::string("scan_elements/in_") + ch + "_en", "0");
    tree.set(std::string("scan_elements/in_") + ch + "_index", std::to_string(index++));
    tree.set(std::string("scan_elements/in_") + ch + "_type", "le:s16/16>>0");
  }
  tree.set("in_anglvel_x_raw", "0");
  tree.set("buffer/length", "0");
  tree.set("buffer/enable", "0");
  const fs::path node = tree.dir().parent_path() / "dev-iio-device0";
  {
    std::ofstream out(node, std::ios::binary);
    const std::int16_t v[6] = {0, 0, 1000, 131, -262, 0};
    out.write(reinterpret_cast<const char*>(v), sizeof v);  // little-endian host
  }
  IioAccelerometer buffered({tree.dir().string(), node.string(), true, {}, 32, 10});
  ASSERT_TRUE(buffered.open());
  EXPECT_TRUE(buffered.buffered());
  EXPECT_EQ(tree.get("scan_elements/in_anglvel_y_en"), "1");
  s = buffered.read();
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_TRUE(s->angular_velocity);
  EXPECT_NEAR((*s->angular_velocity - Vec3(131, -262, 10) * 0.000133090).norm(), 0, 1e-12);
  EXPECT_NEAR(s->specific_force.z(), 1000 * 0.00980665, 1e-12);
}

TEST(IioAccelerometer, MissingChannelsAndScale) {
  FakeIioTree tree;
  tree.set("in_accel_x_raw", "1");
  IioAccelerometer missing_axes({tree.dir().string(), "", false, {}, 64, 10});
  EXPECT_EQ(missing_axes.open().error().code, ErrorCode::kNotFound);
  tree.set("in_accel_y_raw", "1");
  tree.set("in_accel_z_raw", "1");
  IioAccelerometer no_scale({tree.dir().string(), "", false, {}, 64, 10});
  EXPECT_EQ(no_scale.open().error().code, ErrorCode::kIo);
}

}  // namespace
}  // namespace procam::tilt
