#include <gtest/gtest.h>

#include <cmath>

#include "fake_i2c.hpp"
#include "tilt/i2c/i2c_accelerometer.hpp"

namespace procam::tilt {
namespace {

using namespace testing;

struct Rig {
  std::shared_ptr<FakeI2cBus> bus = std::make_shared<FakeI2cBus>();
  FakeChip chip;
  std::unique_ptr<I2cAccelerometer> sensor;
  Rig(I2cChip which, FakeChip c, I2cAccelConfig cfg) : chip(c) {
    cfg.poll_interval = std::chrono::microseconds(0);
    bus->chips.push_back(&chip);
    sensor = makeI2cAccelerometer(which, bus, defaultAddress(which), cfg);
  }
};

TEST(I2cAccelerometers, Adxl345SetupAndLittleEndianFullResolution) {
  Rig rig(I2cChip::kAdxl345, adxl345(), {4, 100, 5, {}});
  ASSERT_TRUE(rig.sensor->open());
  EXPECT_EQ(rig.chip.lastWrite(0x31), 0x09);  // FULL_RES | ±4 g
  EXPECT_EQ(rig.chip.lastWrite(0x2C), 0x0A);  // 100 Hz
  EXPECT_EQ(rig.chip.lastWrite(0x2D), 0x08);  // measure
  EXPECT_EQ(rig.sensor->rateHz(), 100);
  rig.chip.produce(littleEndian({128, -64, -256}));  // 0.5, -0.25, -1 g at 256 LSB/g
  auto s = rig.sensor->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_FALSE(s->angular_velocity);  // no gyroscope in the package
  EXPECT_NEAR((s->specific_force - Vec3(0.5, -0.25, -1) * kStandardGravity).norm(), 0, 1e-12);
  // Data-ready was cleared by the burst read: no second sample.
  EXPECT_EQ(rig.sensor->read().error().code, ErrorCode::kNotFound);
  rig.sensor->close();
  EXPECT_EQ(rig.chip.lastWrite(0x2D), 0x00);  // standby
}

TEST(I2cAccelerometers, Mpu6050SetupAndBigEndian) {
  Rig rig(I2cChip::kMpu6050, mpu6050(), {4, 100, 5, {}});
  ASSERT_TRUE(rig.sensor->open());
  EXPECT_EQ(rig.chip.lastWrite(0x6B), 0x01);  // awake, PLL
  EXPECT_EQ(rig.chip.lastWrite(0x1C), 0x08);  // AFS_SEL = 1: ±4 g
  EXPECT_EQ(rig.chip.lastWrite(0x19), 9);     // 1 kHz / (1 + 9)
  EXPECT_EQ(rig.chip.lastWrite(0x38), 0x01);  // DATA_RDY_EN
  EXPECT_EQ(rig.chip.lastWrite(0x1B), 0x08);  // FS_SEL = 1: +-500 deg/s
  // The gyroscope after the temperature, read in the same burst: 65.5 LSB/(deg/s).
  const auto gyro = bigEndian({655, -6550, 32767});
  for (int i = 0; i < 6; ++i) rig.chip.regs[std::size_t(0x43 + i)] = gyro[std::size_t(i)];
  rig.chip.produce(bigEndian({8192, -4096, -32768}));  // 8192 LSB/g
  auto s = rig.sensor->read();
  ASSERT_TRUE(s);
  EXPECT_NEAR((s->specific_force - Vec3(1, -0.5, -4) * kStandardGravity).norm(), 0, 1e-12);
  ASSERT_TRUE(s->angular_velocity);
  EXPECT_NEAR((*s->angular_velocity - Vec3(10, -100, 32767 / 65.5) * (M_PI / 180)).norm(), 0,
              1e-12);
  rig.sensor->close();
  EXPECT_EQ(rig.chip.lastWrite(0x6B), 0x40);  // sleep
}

TEST(I2cAccelerometers, Lis3dhLeftJustifiedTwelveBitWithAutoIncrementBit) {
  Rig rig(I2cChip::kLis3dh, lis3dh(), {2, 100, 5, {}});
  ASSERT_TRUE(rig.sensor->open());
  EXPECT_EQ(rig.chip.lastWrite(0x20), 0x57);  // 100 Hz, XYZ on
  EXPECT_EQ(rig.chip.lastWrite(0x23), 0x88);  // BDU, ±2 g, high resolution
  // 1 mg/digit, 12 bits left-justified in 16.
  rig.chip.produce(littleEndian({250 * 16, -1000 * 16, -2048 * 16}));
  auto s = rig.sensor->read();
  ASSERT_TRUE(s);
  EXPECT_NEAR((s->specific_force - Vec3(0.25, -1.0, -2.048) * kStandardGravity).norm(), 0, 1e-12);
}

TEST(I2cAccelerometers, WrongIdentityNackAndStuckBus) {
  FakeChip wrong = mpu6050();
  wrong.regs[0x75] = 0x71;  // an MPU-9250 answers
  Rig a(I2cChip::kMpu6050, wrong, {});
  auto r = a.sensor->open();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
  EXPECT_NE(r.error().message.find("0x71"), std::string::npos);

  Rig b(I2cChip::kAdxl345, adxl345(), {});
  b.chip.address = 0x1D;  // strapped to the other address: nobody answers at 0x53
  EXPECT_EQ(b.sensor->open().error().code, ErrorCode::kNotFound);

  Rig c(I2cChip::kLis3dh, lis3dh(), {});
  c.bus->stuck = true;
  EXPECT_EQ(c.sensor->open().error().code, ErrorCode::kIo);
  c.bus->stuck = false;
  ASSERT_TRUE(c.sensor->open());
  c.bus->stuck = true;  // bus hangs after setup
  EXPECT_EQ(c.sensor->read().error().code, ErrorCode::kIo);
}

TEST(I2cAccelerometers, NoDataReadyTimesOutAfterThePollBudget) {
  Rig rig(I2cChip::kAdxl345, adxl345(), {2, 100, 7, {}});
  ASSERT_TRUE(rig.sensor->open());
  const int before = rig.bus->transfers;
  EXPECT_EQ(rig.sensor->read().error().code, ErrorCode::kNotFound);
  EXPECT_EQ(rig.bus->transfers - before, 7);
  EXPECT_EQ(parseI2cChip("bmi160").error().code, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace procam::tilt
