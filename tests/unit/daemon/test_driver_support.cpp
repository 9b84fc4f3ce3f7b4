// The support every in-tree driver uses on its side of the plugin ABI
// (plugins/support/driver_support.hpp): status codes, the reason buffer, properties
// and options.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <utility>

#include "support/driver_support.hpp"

namespace procam::plugins {
namespace {

TEST(DriverSupport, ErrorCodesMapToAbiStatuses) {
  EXPECT_EQ(statusOf(ErrorCode::kNotFound), PROCAM_ENODEV);
  EXPECT_EQ(statusOf(ErrorCode::kInvalidInput), PROCAM_EINVAL);
  EXPECT_EQ(statusOf(ErrorCode::kParse), PROCAM_EINVAL);
  EXPECT_EQ(statusOf(ErrorCode::kIo), PROCAM_EIO);
  EXPECT_EQ(statusOf(ErrorCode::kNoConvergence), PROCAM_EINTERNAL);
}

TEST(DriverSupport, DeviceCodesAndAbiStatusesRoundTrip) {
  // A driver that relays another driver's status (the ir_camera tracker relays its
  // camera's) keeps it: status -> code -> status is the identity on every PROCAM_E*.
  const std::pair<ErrorCode, int> pairs[] = {{ErrorCode::kInvalidInput, PROCAM_EINVAL},
                                             {ErrorCode::kNoDevice, PROCAM_ENODEV},
                                             {ErrorCode::kIo, PROCAM_EIO},
                                             {ErrorCode::kTimeout, PROCAM_ETIMEDOUT},
                                             {ErrorCode::kAgain, PROCAM_EAGAIN},
                                             {ErrorCode::kNotSupported, PROCAM_ENOTSUP},
                                             {ErrorCode::kInternal, PROCAM_EINTERNAL},
                                             {ErrorCode::kEnded, PROCAM_EEND}};
  for (const auto& [code, status] : pairs) {
    EXPECT_EQ(statusOf(code), status) << toString(code);
    EXPECT_EQ(codeOf(status), code) << status;
  }
  EXPECT_EQ(codeOf(-99), ErrorCode::kInternal);  // not a status of this ABI
}

TEST(DriverSupport, ReportTruncatesIntoTheCallersBufferAndReturnsTheStatus) {
  char err[6];
  std::memset(err, 'x', sizeof err);
  EXPECT_EQ(report(err, sizeof err, Error{ErrorCode::kIo, "bus stopped"}), PROCAM_EIO);
  EXPECT_STREQ(err, "bus s");  // 5 characters and the terminator
  EXPECT_EQ(report(nullptr, 0, "no buffer", PROCAM_EAGAIN), PROCAM_EAGAIN);
}

TEST(DriverSupport, PropertyIsEmptyWhenAbsent) {
  const procam_kv props[] = {{"PROCAM_ROLE", "tilt"}, {nullptr, "x"}, {"SIM_SCENE", nullptr}};
  procam_device_desc d{};
  d.properties = props;
  d.n_properties = 3;
  EXPECT_EQ(property(&d, "PROCAM_ROLE"), "tilt");
  EXPECT_EQ(property(&d, "SIM_SCENE"), "");
  EXPECT_EQ(property(&d, "MISSING"), "");
  EXPECT_EQ(property(nullptr, "PROCAM_ROLE"), "");
  EXPECT_TRUE(startsWith("/dev/i2c-1", "/dev/i2c-"));
  EXPECT_FALSE(startsWith(nullptr, "/dev/"));
}

TEST(DriverSupport, OptionsParseValuesAndNameTheBadOne) {
  const procam_kv kv[] = {{"address", "0x53"}, {"rate_hz", "100"}, {"rate_hz", "12.5"},
                          {"buffered", "no"},  {"count", "x18"},   {"gain", "inf"},
                          {"on", "maybe"}};
  const procam_config config{kv, 7};
  const DriverOptions o("i2c tilt", &config);
  EXPECT_EQ(o.integer("address").value(), 0x53);
  EXPECT_EQ(o.number("rate_hz").value(), 12.5);  // the last occurrence wins
  EXPECT_EQ(o.flag("buffered").value(), false);
  EXPECT_FALSE(o.text("device").has_value());
  EXPECT_FALSE(o.integer("device").value().has_value());
  ASSERT_FALSE(o.integer("count"));
  EXPECT_EQ(o.integer("count").error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(o.integer("count").error().message, "i2c tilt: option count: 'x18' is not an integer");
  EXPECT_EQ(o.number("gain").error().message, "i2c tilt: option gain: 'inf' is not a number");
  EXPECT_EQ(o.flag("on").error().message, "i2c tilt: option on: 'maybe' is not true or false");
  auto unknown = o.onlyKnown({"address", "rate_hz", "buffered", "count", "gain"});
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().message,
            "i2c tilt: unknown option 'on' (known: address, rate_hz, buffered, count, gain)");
  EXPECT_TRUE(o.onlyKnown({"address", "rate_hz", "buffered", "count", "gain", "on"}));
  EXPECT_TRUE(DriverOptions("none", nullptr).onlyKnown({}));
}

}  // namespace
}  // namespace procam::plugins
