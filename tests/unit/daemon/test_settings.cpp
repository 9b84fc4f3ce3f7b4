// Persisted settings: JSON round trip, schema checks, keystone quad rules.
#include <gtest/gtest.h>

#include "settings.hpp"

namespace procam::daemon {
namespace {

TEST(Settings, RoundTrip) {
  Settings s;
  s.auto_keystone = true;
  s.rig_keystone = true;
  s.keystone = Quad{{{10.5, 20}, {1900, 15}, {1910, 1070}, {5, 1075.25}}};
  s.pattern = "crosshair";
  s.content = "/srv/slide.png";
  auto back = settingsFromJson(settingsToJson(s));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->auto_keystone);
  EXPECT_TRUE(back->rig_keystone);
  ASSERT_TRUE(back->keystone);
  EXPECT_EQ(*back->keystone, *s.keystone);  // doubles survive JSON exactly
  EXPECT_EQ(back->pattern, "crosshair");
  EXPECT_EQ(back->content, "/srv/slide.png");
  auto defaults = settingsFromJson(settingsToJson(Settings{}));
  ASSERT_TRUE(defaults);
  EXPECT_FALSE(defaults->keystone);
  EXPECT_FALSE(defaults->rig_keystone);
  EXPECT_TRUE(defaults->content.empty());
}

// A settings file written before keystone from the rig model existed is still read.
TEST(Settings, FileWithoutRigKeystoneIsRead) {
  auto old = settingsFromJson(
      R"({"schema":1,"auto_keystone":true,"keystone":null,"pattern":"off","content":null})");
  ASSERT_TRUE(old) << old.error().message;
  EXPECT_TRUE(old->auto_keystone);
  EXPECT_FALSE(old->rig_keystone);
}

TEST(Settings, RejectsCorruptOrForeignFiles) {
  for (
      const char* text : {
          "",
          "{",
          "[]",
          R"({"schema":2,"auto_keystone":false,"keystone":null,"pattern":"off","content":null})",
          R"({"schema":1,"auto_keystone":0,"keystone":null,"pattern":"off","content":null})",
          R"({"schema":1,"auto_keystone":false,"rig_keystone":1,"keystone":null,"pattern":"off","content":null})",
          R"({"schema":1,"auto_keystone":false,"keystone":{"corners":[[0,0]]},"pattern":"off","content":null})",
          R"({"schema":1,"auto_keystone":false,"keystone":null,"pattern":"plaid","content":null})",
          R"({"schema":1,"auto_keystone":false,"keystone":null,"pattern":"off","content":5})",
          R"({"schema":1,"auto_keystone":false,"keystone":{"corners":[[0,0],[0,0],[1,1],[0,1]]},"pattern":"off","content":null})",
      }) {
    EXPECT_FALSE(settingsFromJson(text)) << text;
  }
}

TEST(Quad, AcceptsConvexClockwiseOnScreen) {
  EXPECT_TRUE(validateQuad({{{0, 0}, {1919, 0}, {1919, 1079}, {0, 1079}}}));
  EXPECT_TRUE(validateQuad({{{100, 50}, {1800, 0}, {1919, 1079}, {0, 1000}}}));
}

TEST(Quad, RejectsDegenerateReversedNonConvexOrNonFinite) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Quad bad[] = {
      {{{0, 0}, {0, 1079}, {1919, 1079}, {1919, 0}}},  // counter-clockwise on screen
      {{{0, 0}, {1919, 0}, {0, 1079}, {1919, 1079}}},  // self-intersecting (bow tie)
      {{{0, 0}, {1000, 0}, {1919, 0}, {0, 1079}}},     // three collinear corners
      {{{0, 0}, {1919, 0}, {300, 300}, {0, 1079}}},    // reflex corner
      {{{0, 0}, {0, 0}, {1919, 1079}, {0, 1079}}},     // repeated corner
      {{{nan, 0}, {1919, 0}, {1919, 1079}, {0, 1079}}},
  };
  for (const auto& q : bad) EXPECT_FALSE(validateQuad(q));
}

TEST(Pattern, Names) {
  for (const char* n : {"off", "grid", "crosshair", "white", "black"})
    EXPECT_TRUE(isPatternName(n));
  EXPECT_FALSE(isPatternName("Grid"));
  EXPECT_FALSE(isPatternName(""));
}

}  // namespace
}  // namespace procam::daemon
