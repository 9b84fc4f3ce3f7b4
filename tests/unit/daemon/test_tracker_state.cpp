// Tracker registrations in the daemon: the `tracker register` request fitted
// ([Raskar02] eq. 4.2, §4.2.5), its typed errors, and tracker.json round trips.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "tracker_state.hpp"

namespace procam::daemon {
namespace {

using nlohmann::json;

struct Motion {
  Mat3 R = Eigen::AngleAxisd(-0.7, Vec3(1, 2, 0.5).normalized()).toRotationMatrix();
  Vec3 t{0.2, 1.5, -0.4};
};

json pointsRequest(const Motion& m, int n) {
  const Vec3 tracker[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {0.5, -0.3, 0.2}};
  json points = json::array();
  for (int i = 0; i < n; ++i) {
    const Vec3 w = m.R * tracker[i] + m.t;
    points.push_back({{"tracker", {tracker[i].x(), tracker[i].y(), tracker[i].z()}},
                      {"world", {w.x(), w.y(), w.z()}}});
  }
  return {{"cmd", "tracker"}, {"action", "register"}, {"points", points}};
}

TEST(TrackerState, PointPairsGiveTheRigidMotion) {
  const Motion m;
  auto r = fitRegistrationRequest(pointsRequest(m, 6));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->source, "points");
  EXPECT_EQ(r->points, 6);
  EXPECT_LT((r->fit.tracker_to_world.R - m.R).norm(), 1e-9);
  EXPECT_LT((r->fit.tracker_to_world.t - m.t).norm(), 1e-9);
  EXPECT_LT(r->fit.rms, 1e-9);
  EXPECT_LT((r->fit.toWorld(Vec3(2, 3, 4)) - (m.R * Vec3(2, 3, 4) + m.t)).norm(), 1e-9);
}

TEST(TrackerState, TooFewDegenerateAndMalformedRequestsAreTyped) {
  const Motion m;
  auto few = fitRegistrationRequest(pointsRequest(m, 3));
  ASSERT_FALSE(few);
  EXPECT_EQ(few.error().code, ErrorCode::kTooFewPoints);
  json line = {{"points", json::array()}};
  for (int i = 0; i < 5; ++i)
    line["points"].push_back({{"tracker", {i, 2 * i, 0}}, {"world", {0, i, 0}}});
  auto degenerate = fitRegistrationRequest(line);
  ASSERT_FALSE(degenerate);
  EXPECT_EQ(degenerate.error().code, ErrorCode::kDegenerate);
  json no_world = pointsRequest(m, 4);
  no_world["points"][2].erase("world");
  auto missing = fitRegistrationRequest(no_world);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(missing.error().message.find("points[2]"), std::string::npos);
  json nan = pointsRequest(m, 4);
  nan["points"][1]["tracker"][0] = "x";
  EXPECT_FALSE(fitRegistrationRequest(nan));
  EXPECT_FALSE(fitRegistrationRequest({{"mode", "sideways"}, {"points", json::array()}}));
}

// §4.2.5: readings of screen points define the world frame (origin, x axis,
// z = the screen's normal towards the viewer).
TEST(TrackerState, ScreenModeMakesTheScreenTheWorldFrame) {
  const Motion m;  // world -> tracker here: the tracker sees the screen from its own frame
  const Vec3 screen[] = {{0, 0, 0}, {1.2, 0, 0}, {1.2, 0.8, 0}, {0, 0.8, 0}, {0.6, 0.4, 0}};
  json points = json::array();
  for (const Vec3& s : screen) {
    const Vec3 p = m.R * s + m.t;
    points.push_back({{"tracker", {p.x(), p.y(), p.z()}}});
  }
  const Vec3 viewer = m.R * Vec3(0.6, 0.4, 2.0) + m.t;
  json req = {{"mode", "screen"},
              {"points", points},
              {"origin", 0},
              {"x_axis", 1},
              {"viewer_side", {viewer.x(), viewer.y(), viewer.z()}}};
  auto r = fitRegistrationRequest(req);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->source, "screen");
  for (const Vec3& s : screen) {
    EXPECT_LT((r->fit.toWorld(m.R * s + m.t) - s).norm(), 1e-9);
  }
  req.erase("x_axis");
  auto missing = fitRegistrationRequest(req);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kInvalidInput);
}

TEST(TrackerState, TrackerFileRoundTripsAndRejectsNonRotations) {
  const Motion m;
  TrackerRegistrations regs;
  regs["head"] = *fitRegistrationRequest(pointsRequest(m, 5));
  auto back = trackerFileFromText(trackerFileText(regs));
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->count("head"), 1u);
  const auto& r = back->at("head");
  EXPECT_LT((r.fit.tracker_to_world.R - m.R).norm(), 1e-12);
  EXPECT_LT((r.fit.tracker_to_world.t - m.t).norm(), 1e-12);
  EXPECT_EQ(r.points, 5);
  EXPECT_EQ(r.source, "points");
  json doc = json::parse(trackerFileText(regs));
  doc["trackers"]["head"]["R"][0] = 2.0;
  auto bad = trackerFileFromText(doc.dump());
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kParse);
  EXPECT_NE(bad.error().message.find("head"), std::string::npos);
  EXPECT_FALSE(trackerFileFromText("{\"cameras\": []}"));
  EXPECT_FALSE(trackerFileFromText("not json"));
}

}  // namespace
}  // namespace procam::daemon

namespace procam::daemon {
namespace {

TEST(ReadingStats, RateOverTheLastTwoSecondsAndRepeatsNotCounted) {
  ReadingStats s;
  const auto t0 = ReadingStats::Clock::now();
  const auto at = [&](double sec) {
    return t0 + std::chrono::duration_cast<ReadingStats::Clock::duration>(
                    std::chrono::duration<double>(sec));
  };
  // 3 s at 50 Hz, then the same sample read again.
  for (int i = 0; i <= 150; ++i) EXPECT_TRUE(s.add(1000 + 20'000'000ull * i, at(i / 50.0)));
  EXPECT_FALSE(s.add(1000 + 20'000'000ull * 150, at(3.001)));
  EXPECT_EQ(s.count(), 151u);
  EXPECT_EQ(s.lastTimestampNs(), 1000 + 20'000'000ull * 150);
  EXPECT_NEAR(s.rateHz(at(3.0)), 50.0, 1e-6);
  // Stopped: once the window holds fewer than two arrivals the rate is 0.
  EXPECT_NEAR(s.rateHz(at(4.0)), 50.0, 1e-6);  // one second of arrivals left
  EXPECT_EQ(s.rateHz(at(5.5)), 0.0);
  const json j = s.toJson("frames");
  EXPECT_EQ(j["frames"], 151);
  EXPECT_DOUBLE_EQ(j["last_timestamp"].get<double>(), (1000 + 20'000'000ull * 150) * 1e-9);
}

}  // namespace
}  // namespace procam::daemon
