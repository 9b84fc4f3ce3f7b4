// procamctl's text form of replies: every reply class it knows, from a procamd that sent
// less than this procamctl reads (keys missing) or other types than it expects, gives
// text and never reads past what came.
#include <gtest/gtest.h>

#include "format.hpp"

namespace procam::ctl {
namespace {

using nlohmann::json;

const char* const kClasses[] = {"VERSION", "STATUS",    "DEVICES", "KEYSTONE", "PATTERN",
                                "CONTENT", "OBJECT",    "SAVE",    "RELOAD",   "LOG-LEVEL",
                                "TRACKER", "CALIBRATE", "LATENCY", "SNAPSHOT", "CALIBRATE-CAMERA",
                                "CANCEL",  "WATCH",     "ERROR"};

// Text, not the reply's JSON handed back: every line the formatter could write was written
// with its keys absent.
TEST(CtlFormat, RepliesMissingTheirKeysStillRead) {
  for (const char* cls : kClasses) {
    const json r = {{"class", cls}};
    std::string text;
    ASSERT_NO_THROW(text = formatReply(r)) << cls;
    EXPECT_EQ(text.back(), '\n') << cls;
    EXPECT_NE(text, r.dump() + "\n") << cls << " fell back to the raw reply";
  }
  const std::string status = formatReply({{"class", "STATUS"}});
  EXPECT_NE(status.find("pid:"), std::string::npos) << status;
  EXPECT_NE(status.find("auto keystone: off"), std::string::npos) << status;
}

TEST(CtlFormat, ValuesOfAnotherTypeReadAsAbsent) {
  for (const char* cls : kClasses) {
    // Every key a formatter might read, each the wrong type.
    json r = {{"class", cls}};
    for (const char* key : {"release",      "pid",          "uptime_s",
                            "sim",          "config",       "devices",
                            "capabilities", "warnings",     "outputs",
                            "auto",         "corners",      "pattern",
                            "shown",        "content",      "object",
                            "refined",      "path",         "bytes",
                            "level",        "trackers",     "cameras",
                            "camera",       "cancelled",    "events",
                            "enabled",      "proto_major",  "proto_minor",
                            "message",      "keystone",     "drift",
                            "coarse",       "plane_source", "triangulated_plane"}) {
      r[key] = json::array({json::object({{"x", 1}}), 2});
    }
    std::string text;
    ASSERT_NO_THROW(text = formatReply(r)) << cls;
    EXPECT_FALSE(text.empty()) << cls;
  }
  // A reply or event that is not an object at all: as it came.
  EXPECT_EQ(formatReply(json::array({1, 2})), "[1,2]\n");
  EXPECT_EQ(formatEvent(json::array({1, 2})), "[1,2]\n");
  EXPECT_EQ(formatEvent({{"event", 3}, {"a", 1}}), "event a=1\n");
}

TEST(CtlFormat, AnObjectRefinementIsShown) {
  const json r = {{"class", "OBJECT"},
                  {"object", {{"mesh", "object-model.ply"}, {"t", {0.1, 1.5, 0.875}}}},
                  {"refined",
                   {{"points", 713},
                    {"candidates", 3324},
                    {"moved_m", 0.0021},
                    {"turned_deg", 0.75},
                    {"rms_m", 0.00038},
                    {"free", {{{"kind", "slide"}, {"axis", {1, 0, 0}}}}}}}};
  const std::string text = formatReply(r);
  EXPECT_NE(text.find("from 713 of 3324 measured points: moved 2.10 mm, turned 0.750 deg"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("slide along 1 0 0 (as placed)"), std::string::npos) << text;
}

TEST(CtlFormat, AnAdaptiveCalibrationSaysWhatItsCoarsePassFound) {
  const json planar = {{"class", "CALIBRATE"},
                       {"route", "b'"},
                       {"plane_source", "cameras"},
                       {"triangulated_plane", {{"rms_m", 0.000585}, {"inliers", 128}}},
                       {"coarse",
                        {{"frames", 18},
                         {"planar", true},
                         {"blocks", 175},
                         {"rms_px", 0.375},
                         {"tolerance_px", 1.35}}}};
  std::string text = formatReply(planar);
  EXPECT_NE(text.find("planar, 175 blocks fit one homography to 0.375 px RMS (a plane allows "
                      "1.350)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("plane from:    cameras (128 points, 0.585 mm RMS)"), std::string::npos)
      << text;
  const json full = {{"class", "CALIBRATE"},
                     {"route", "a"},
                     {"coarse",
                      {{"planar", false},
                       {"blocks", 142},
                       {"rms_px", 4.21},
                       {"tolerance_px", 0.74},
                       {"then", "the full scan: not planar"}}}};
  text = formatReply(full);
  EXPECT_NE(text.find("not planar, 142 blocks"), std::string::npos) << text;
  EXPECT_NE(text.find("the full scan: not planar"), std::string::npos) << text;
  EXPECT_EQ(text.find("plane from"), std::string::npos) << text;
}

TEST(CtlFormat, DriftShowsItsFiducialFrames) {
  json drift = {
      {"state", "registered"},     {"misregistration_px", 0.0},
      {"camera", "cam"},           {"corrections", 0},
      {"content_too_plain", true}, {"fiducial", {{"frames", 3}, {"misregistration_px", 0.026}}}};
  const json r = {{"class", "STATUS"},
                  {"drift", {{"policy", "on-drift"}}},
                  {"outputs", {{"shown", {{{"name", "proj"}, {"drift", drift}}}}}}};
  std::string text = formatReply(r);
  EXPECT_NE(text.find("3 fiducial frame(s), the last 0.026 px"), std::string::npos) << text;
  drift["fiducial"] = "three";  // another type: not shown, nothing thrown
  const json odd = {{"class", "STATUS"},
                    {"outputs", {{"shown", {{{"name", "p"}, {"drift", drift}}}}}}};
  text = formatReply(odd);
  EXPECT_EQ(text.find("fiducial"), std::string::npos) << text;
}

}  // namespace
}  // namespace procam::ctl
