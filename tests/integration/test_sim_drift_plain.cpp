// recalibrate = "on-drift" and "on-drift-silent" end to end under plain (uniform grey)
// content, which cannot show drift (sim_drift_rig.hpp: wall_oblique, the truth at rest as
// the rig model): "on-drift-silent" reports it too plain and changes nothing, "off" does
// not look, and "on-drift" checks with fiducial frames (AprilTags over the whole frame,
// shown for one check) and corrects a bumped projector from their corners.
#include "sim_drift_rig.hpp"

namespace procam::itest {
namespace {

// Uniform grey content and the projector bumped 1 degree: "on-drift-silent", which shows
// no frame of its own, reports it too plain to tell and changes nothing; "off" does not
// look.
TEST(SimDrift, PlainContentIsReportedWhenSilentAndOffDoesNothing) {
  for (const std::string policy : {"on-drift-silent", "off"}) {
    SCOPED_TRACE(policy);
    TempDir dir;
    const std::string scene_file =
        sceneWithEvents(dir, "[[events]]\nt = " + atText(4.0) +
                                 "\ntarget = \"proj\"\nrotate_deg = [1.0, 0.0, 0.0]\n");
    const auto spawned = Clock::now();
    DaemonProcess d(dir, driftDaemon(dir, policy, scene_file));
    ASSERT_TRUE(d.started()) << d.log();
    Connection c(d.socketPath());
    const std::string before = rigText(dir);
    // Uniform grey for on-drift-silent; the textured image for off (which must not look
    // at it).
    std::string png;
    if (policy == "on-drift-silent") {
      png = contentFile(dir, "grey.png");
      cv::imwrite(png, cv::Mat(900, 1600, CV_8UC3, cv::Scalar(128, 128, 128)));
    } else {
      png = texturedContent(dir);
    }
    ASSERT_NO_FATAL_FAILURE(showContent(c, png));
    while (std::chrono::duration<double>(Clock::now() - spawned).count() < at(7.0)) {
      std::this_thread::sleep_for(250ms);
    }
    if (policy != "off") {
      // Two checks that began after the bump (a loaded machine's captures take longer),
      // four in all.
      const json now = outputDrift(c);
      const int n = now.is_object() ? now.value("checks", 0) : 0;
      EXPECT_TRUE(checkedTimes([&] { return outputDrift(c); }, std::max(4, n + 2), 15s));
    }
    const json dr = outputDrift(c);
    auto st = c.call({{"cmd", "status"}});
    ASSERT_TRUE(st);
    if (policy == "off") {
      EXPECT_TRUE(dr.is_null()) << dr.dump();
      EXPECT_EQ((*st)["drift"]["policy"], "off");
    } else {
      ASSERT_TRUE(dr.is_object());
      EXPECT_EQ(dr.value("state", ""), "too plain to tell") << dr.dump();
      EXPECT_TRUE(dr.value("too_plain", false)) << dr.dump();
      EXPECT_GE(dr.value("checks", 0), 4) << dr.dump();
      EXPECT_EQ(dr.value("corrections", -1), 0) << dr.dump();
      EXPECT_TRUE(dr.value("content_too_plain", false)) << dr.dump();
      EXPECT_FALSE(dr.contains("fiducial")) << dr.dump();  // silent: none shown
      EXPECT_EQ((*st)["drift"]["policy"], "on-drift-silent");
    }
    EXPECT_EQ(before, rigText(dir));
  }
}

// Uniform grey content with "on-drift": the content cannot show drift, a fiducial frame
// (AprilTags over the whole frame, shown for one check) can. Still, the frames find the
// output registered and nothing is corrected; the projector bumped 1 degree is found at
// the next fiducial frame and corrected from the tag corners.
TEST(SimDrift, PlainContentIsCheckedWithFiducialFramesAndABumpCorrected) {
  TempDir dir;
  BumpCourse r(dir);
  ASSERT_NO_FATAL_FAILURE(r.start());
  const std::string png = contentFile(dir, "grey.png");
  cv::imwrite(png, cv::Mat(900, 1600, CV_8UC3, cv::Scalar(128, 128, 128)));
  ASSERT_NO_FATAL_FAILURE(showContent(r.c, png));
  const json still = r.still(dir, rigText(dir), "grey content");
  EXPECT_TRUE(still.value("content_too_plain", false)) << still.dump();
  r.corrected(dir, "grey content");
}

// Two fixed cameras and uniform grey content: the projector bumped 1 degree is found in a
// fiducial frame by one camera, and every camera's next check shows one too, so the
// other confirms it and the projector is corrected from the tag corners.
TEST(SimDrift, PlainContentWithTwoCamerasIsCorrectedFromFiducialFrames) {
  TempDir dir;
  DriftRig r(
      dir, "[[events]]\nt = " + atText(6.0) + "\ntarget = \"proj\"\nrotate_deg = [1.0, 0.0, 0.0]\n",
      true, "drift_fiducial_period_s = 2\n");
  const std::string png = contentFile(dir, "grey.png");
  cv::imwrite(png, cv::Mat(900, 1600, CV_8UC3, cv::Scalar(128, 128, 128)));
  ASSERT_NO_FATAL_FAILURE(r.start(dir, png));
  bool registered = false;
  const std::optional<json> corrected =
      awaitCorrection(r.watcher, "corrected-pose", "corrected-surface", registered);
  ASSERT_TRUE(corrected) << outputDrift(r.c).dump() << r.d.log();
  EXPECT_TRUE(registered) << outputDrift(r.c).dump();
  const json dr = outputDrift(r.c);
  const double rig_px = rigAgainstTruth(dir, r.scene->at(at(7.0)).projectors.at(0).model);
  std::printf(
      "[ figures  ] two cameras, grey content, projector bumped 1 deg: corrected from %d tag "
      "corners, the rig against the true projector %.3f px; %d fiducial frames\n",
      (*corrected)["tiles"].get<int>(), rig_px, dr["fiducial"].value("frames", 0));
  EXPECT_LE(rig_px, 0.5);
  // A handful of frames, not one at every check.
  EXPECT_LE(dr["fiducial"].value("frames", 0), 20) << dr.dump();
}

}  // namespace
}  // namespace procam::itest
