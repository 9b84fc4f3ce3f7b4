// procam-calibrate solve-wall on wall_views: cam_l sees most of proj_l and nothing of
// proj_r, cam_r sees proj_r whole and a fifth of proj_l.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "calibrate_cli_harness.hpp"
#include "rig/rig_model.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "unit/calibration/plane_corners.hpp"

using namespace procam;
using namespace procam::testing;

namespace {

// `solve-wall` registers the second camera through the projectors both see (its pose in
// cameras.json is deliberately wrong: only its intrinsics may be used) and maps both
// projectors onto the wall given by its plane; procam-render draws them as one display.
TEST(CalibrateCli, SolveWallFromCamerasAtSeveralPositions) {
  TempDir dir;
  auto r = calibrate({"patterns", "--projector", "1280x800", "--mode", "gray+phase",
                      "--phase-steps", "3", "--out", dir.file("patterns")});
  ASSERT_EQ(r.status, 0) << r.err;
  // The captures, rendered in this process from each camera's light paths (one
  // procam-sim run per frame would take minutes): every camera films every projector's
  // sequence.
  auto scene = sim::resolveScene("wall_views");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  const nlohmann::json seq = readJsonFile(dir.file("patterns/sequence.json"));
  ASSERT_FALSE(seq.is_discarded());
  std::vector<sim::StillCamera> filming;
  for (const auto& c : state.cameras) {
    auto still = sim::StillCamera::create(*scene, state, c.spec.name);
    ASSERT_TRUE(still) << still.error().message;
    filming.push_back(std::move(*still));
  }
  int seed = 40;
  for (const auto& p : state.projectors) {
    for (const auto& f : seq.at("frames")) {
      const std::string file = f.at("file").get<std::string>();
      const cv::Mat frame = cv::imread(dir.file("patterns/" + file), cv::IMREAD_GRAYSCALE);
      ASSERT_FALSE(frame.empty()) << file;
      for (const sim::StillCamera& c : filming) {
        auto image =
            c.capture({{p.spec.name, frame}}, {.noise = true, .seed = std::uint64_t(++seed)});
        ASSERT_TRUE(image) << image.error().message;
        const fs::path out = dir.file(p.spec.name + "_" + c.name());
        fs::create_directories(out);
        ASSERT_TRUE(cv::imwrite((out / file).string(), *image));
      }
    }
  }
  const nlohmann::json truth = sceneTruth("wall_views");
  ASSERT_FALSE(truth.is_null());
  nlohmann::json cameras = nlohmann::json::parse(camerasJson(truth, {"cam_l", "cam_r"}));
  cameras["cameras"][1]["R"] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  cameras["cameras"][1]["t"] = {0, 0, 0};
  dir.write("cameras.json", cameras.dump(2));
  const std::vector<std::string> solve = {"solve-wall",
                                          "--cameras",
                                          dir.file("cameras.json"),
                                          "--plane",
                                          "0,1,0,-3",
                                          "--out",
                                          dir.file("rig.json"),
                                          "--projector",
                                          "proj_l",
                                          "--patterns",
                                          dir.file("patterns"),
                                          "--captures",
                                          dir.file("proj_l_cam_l"),
                                          dir.file("proj_l_cam_r"),
                                          "--projector",
                                          "proj_r",
                                          "--patterns",
                                          dir.file("patterns"),
                                          "--captures",
                                          dir.file("proj_r_cam_l"),
                                          dir.file("proj_r_cam_r")};
  r = calibrate(solve);
  ASSERT_EQ(r.status, 0) << r.err;
  std::printf("%s", r.err.c_str());
  auto rig = rig::rigFromJson(readJsonFile(dir.file("rig.json")), "rig.json");
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->projectors.size(), 2u);
  ASSERT_TRUE(rig->surface.plane);
  // Every corner of both images within the keystone bound (0.5 px) of where the TRUE
  // projector puts it, also proj_r's, which the posed camera sees a fifth of.
  for (const auto& p : state.projectors) {
    const rig::RigProjector* est = rig->projector(p.spec.name);
    ASSERT_TRUE(est && est->plane_homography) << p.spec.name;
    EXPECT_NE(est->calibrated.method.find("several positions"), std::string::npos);
    const double worst = planeCornerErrorPx(*est->plane_homography, p.model);
    std::printf("[ figures  ] %s: corners within %.3f px of the truth, %ld nodes, %.4f px RMS\n",
                p.spec.name.c_str(), worst, est->points, est->rms_px);
    EXPECT_LE(worst, 0.5) << p.spec.name;
  }
  // procam-render draws the pair as one planar display.
  cv::imwrite(dir.file("white.png"), cv::Mat(450, 1600, CV_8UC3, cv::Scalar::all(255)));
  const procam::itest::RunResult drawn =
      procam::itest::runProgram({PROCAM_RENDER_BIN, "--rig", dir.file("rig.json"), "--content",
                                 dir.file("white.png"), "--out", dir.file("frames")});
  ASSERT_EQ(drawn.status, 0) << drawn.err;
  const nlohmann::json display = readJsonFile(dir.file("frames/display.json"));
  EXPECT_EQ(display["projectors"].size(), 2u) << display.dump();
  EXPECT_FALSE(cv::imread(dir.file("frames/proj_r.png")).empty());

  // A projector no camera filmed names itself; a malformed plane is a command-line error.
  std::vector<std::string> unseen = solve;
  unseen[unseen.size() - 2] = "-";
  unseen[unseen.size() - 1] = "-";
  r = calibrate(unseen);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("projector proj_r"), std::string::npos) << r.err;
  std::vector<std::string> flat = solve;
  flat[4] = "0,0,0,1";
  r = calibrate(flat);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--plane"), std::string::npos) << r.err;
}

}  // namespace
