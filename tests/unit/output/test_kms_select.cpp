// KMS connector/mode choice, modeset API choice and frame statistics on stored KMS
// property tables (tests/unit/output/data), and the driver's error on this machine.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "kms/kms_select.hpp"

namespace procam::output::kms {
namespace {

constexpr uint32_t kInterlace = 16;  // DRM_MODE_FLAG_INTERLACE

struct Table {
  bool atomic_cap = false;
  std::vector<Connector> connectors;
  PropertyTable properties;
};

Table load(const std::string& name) {
  const char* root = std::getenv("PROCAM_SOURCE_DIR");
  std::ifstream in(std::string(root ? root : ".") + "/tests/unit/output/data/" + name);
  EXPECT_TRUE(in.good()) << name;
  const nlohmann::json j = nlohmann::json::parse(in);
  Table t;
  t.atomic_cap = j["atomic_cap"];
  for (const auto& c : j["connectors"]) {
    Connector k;
    k.id = c["id"];
    k.name = connectorTypeName(c["type"]) + "-" + std::to_string(int(c["type_id"]));
    k.connected = c["connected"];
    for (uint32_t crtc : c["crtcs"]) k.crtcs.push_back(crtc);
    for (const auto& m : c["modes"]) {
      const std::string mname = m["name"];
      Mode mode;
      mode.name = mname;
      std::sscanf(mname.c_str(), "%dx%d", &mode.width, &mode.height);
      mode.refresh_hz = refreshHz(m["clock"], m["htotal"], m["vtotal"],
                                  (int(m["flags"]) & kInterlace) != 0, false);
      mode.preferred = m["preferred"];
      k.modes.push_back(mode);
    }
    t.connectors.push_back(k);
  }
  for (const auto& p : j["properties"]["connector"]) t.properties.connector.push_back(p);
  for (const auto& p : j["properties"]["crtc"]) t.properties.crtc.push_back(p);
  for (const auto& p : j["properties"]["plane"]) t.properties.plane.push_back(p);
  return t;
}

TEST(KmsSelect, ModeSpecsParseAndRejectGarbage) {
  EXPECT_TRUE(parseModeSpec("")->preferred);
  EXPECT_TRUE(parseModeSpec("preferred")->preferred);
  const auto m = parseModeSpec("1280x720");
  ASSERT_TRUE(m);
  EXPECT_FALSE(m->preferred);
  EXPECT_EQ(m->width, 1280);
  EXPECT_FALSE(m->refresh_hz.has_value());
  EXPECT_DOUBLE_EQ(*parseModeSpec("1920x1080@59.94")->refresh_hz, 59.94);
  for (const char* bad : {"1920", "x1080", "1920x1080@", "0x0", "1920 x 1080", "big"}) {
    EXPECT_EQ(parseModeSpec(bad).error().code, ErrorCode::kParse) << bad;
  }
}

TEST(KmsSelect, ConnectorNamesAndRefreshRatesFollowTheKernel) {
  EXPECT_EQ(connectorTypeName(11), "HDMI-A");
  EXPECT_EQ(connectorTypeName(14), "eDP");
  EXPECT_EQ(connectorTypeName(10), "DP");
  EXPECT_EQ(connectorTypeName(999), "Unknown");
  EXPECT_NEAR(refreshHz(148500, 2200, 1125, false, false), 60.0, 1e-12);
  EXPECT_NEAR(refreshHz(148352, 2200, 1125, false, false), 59.94, 0.001);
  EXPECT_NEAR(refreshHz(74250, 2200, 1125, true, false), 60.0, 1e-12);
  EXPECT_EQ(refreshHz(1, 0, 0, false, false), 0.0);
}

TEST(KmsSelect, ChoosesConnectorAndModeFromConfiguration) {
  const Table t = load("kms_laptop_with_projector.json");
  ASSERT_EQ(t.connectors[1].name, "HDMI-A-1");
  auto pick = [&](const std::string& c, const std::string& m) {
    return chooseOutput(t.connectors, {c, m});
  };
  // Nothing configured: first connected connector, its preferred mode, its first CRTC.
  auto def = pick("", "");
  ASSERT_TRUE(def);
  EXPECT_EQ(def->connector, 0u);
  EXPECT_EQ(def->mode, 0u);
  EXPECT_EQ(def->crtc, 51u);
  auto hdmi = pick("HDMI-A-1", "preferred");
  ASSERT_TRUE(hdmi);
  EXPECT_EQ(hdmi->connector, 1u);
  EXPECT_EQ(hdmi->mode, 0u);
  EXPECT_EQ(hdmi->crtc, 72u);
  // Size only: the highest refresh of that size (60 over 59.94, 50 and interlaced 60
  // fields... the interlaced mode is named 1920x1080i and parsed as its size too).
  auto size = pick("HDMI-A-1", "1920x1080");
  ASSERT_TRUE(size);
  EXPECT_NEAR(t.connectors[1].modes[size->mode].refresh_hz, 60.0, 1e-9);
  EXPECT_EQ(pick("HDMI-A-1", "1920x1080@50")->mode, 2u);
  EXPECT_EQ(pick("HDMI-A-1", "1920x1080@59.94")->mode, 1u);
  EXPECT_EQ(pick("HDMI-A-1", "1280x720")->mode, 4u);
}

TEST(KmsSelect, ErrorsNameTheCauseAndTheAlternatives) {
  const Table t = load("kms_laptop_with_projector.json");
  auto unknown = chooseOutput(t.connectors, {"HDMI-A-2", ""});
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, ErrorCode::kNotFound);
  EXPECT_NE(unknown.error().message.find("HDMI-A-1"), std::string::npos);
  EXPECT_NE(unknown.error().message.find("DP-1 (disconnected)"), std::string::npos);
  auto unplugged = chooseOutput(t.connectors, {"DP-1", ""});
  ASSERT_FALSE(unplugged);
  EXPECT_NE(unplugged.error().message.find("no display connected"), std::string::npos);
  auto mode = chooseOutput(t.connectors, {"HDMI-A-1", "800x600"});
  ASSERT_FALSE(mode);
  EXPECT_NE(mode.error().message.find("1024x768@60.00"), std::string::npos);
  EXPECT_EQ(chooseOutput(t.connectors, {"HDMI-A-1", "1920x1080@75"}).error().code,
            ErrorCode::kNotFound);
  std::vector<Connector> none = {t.connectors[2]};
  EXPECT_NE(chooseOutput(none, {"", ""}).error().message.find("no connected display"),
            std::string::npos);
}

TEST(KmsSelect, LegacyDriverTableFallsBackAndPicksTheLargestMode) {
  const Table t = load("kms_legacy_driver.json");
  const ApiChoice api = chooseModesetApi(t.atomic_cap, t.properties);
  EXPECT_FALSE(api.atomic);
  EXPECT_NE(api.reason.find("plane property SRC_X missing"), std::string::npos) << api.reason;
  auto c = chooseOutput(t.connectors, {"VGA-1", ""});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->mode, 1u);  // no preferred flag: 1280x1024 is the largest
  const Table full = load("kms_laptop_with_projector.json");
  EXPECT_TRUE(chooseModesetApi(full.atomic_cap, full.properties).atomic);
  EXPECT_FALSE(chooseModesetApi(false, full.properties).atomic);
}

TEST(KmsSelect, FrameStatsCountMissedVblanksAcrossCounterWrap) {
  FrameStats s;
  const double period = 1.0 / 60;
  uint32_t seq = 0xFFFFFFFDu;
  double t = 100;
  s.flip(seq, t);
  for (int i = 0; i < 5; ++i) s.flip(++seq, t += period);  // wraps through 0
  seq += 3;                                                // two vblanks missed
  s.flip(seq, t += 3 * period);
  EXPECT_EQ(s.frames(), 7u);
  EXPECT_EQ(s.missedVblanks(), 2u);
  EXPECT_NEAR(s.maxFrameSeconds(), 3 * period, 1e-9);
  EXPECT_NEAR(s.meanFrameSeconds(), 8 * period / 6, 1e-9);
}

}  // namespace
}  // namespace procam::output::kms
