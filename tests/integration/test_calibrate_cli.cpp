// procam-calibrate end to end: the built programs on files in a temporary directory,
// captures rendered on the virtual rig (calibrate_cli_harness.hpp), the
// results checked against the rig's ground truth with procamd's calibration accuracy
// bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>

#include "calibrate_cli_harness.hpp"
#include "sim/renderer.hpp"
#include "unit/calibration/issue_scenes.hpp"

using namespace procam;
using namespace procam::testing;

namespace {

struct Pfm {
  int width = 0, height = 0;
  cv::Mat u, v, confidence;  // CV_32F, top row first
};

// A 3-channel little-endian PFM, rows stored bottom to top.
std::optional<Pfm> readPfm(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string magic;
  double scale = 0;
  Pfm p;
  in >> magic >> p.width >> p.height >> scale;
  in.get();  // the single whitespace before the data
  if (!in || magic != "PF" || scale >= 0 || p.width <= 0 || p.height <= 0) return std::nullopt;
  std::vector<float> data(static_cast<std::size_t>(p.width) * p.height * 3);
  in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size() * 4));
  if (in.gcount() != static_cast<std::streamsize>(data.size() * 4) || in.peek() != EOF)
    return std::nullopt;
  p.u.create(p.height, p.width, CV_32F);
  p.v.create(p.height, p.width, CV_32F);
  p.confidence.create(p.height, p.width, CV_32F);
  for (int row = 0; row < p.height; ++row)
    for (int x = 0; x < p.width; ++x) {
      const float* px = &data[(static_cast<std::size_t>(row) * p.width + x) * 3];
      const int y = p.height - 1 - row;
      p.u.at<float>(y, x) = px[0];
      p.v.at<float>(y, x) = px[1];
      p.confidence.at<float>(y, x) = px[2];
    }
  return p;
}

Mat3 matrix9(const nlohmann::json& a) {
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = a.at(i).get<double>();
  return m;
}
Mat3 matrix3x3(const nlohmann::json& rows) {
  Mat3 m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = rows.at(r).at(c).get<double>();
  return m;
}
Vec3 vector3(const nlohmann::json& a) {
  return Vec3(a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>());
}

// Projector `index` of rig.json (which holds `count`) against procam-sim's truth: the
// intrinsics accuracy bounds (focal 0.5%, principal point 2 px), and pose ones when `pose`.
void expectProjector(const nlohmann::json& rig, const nlohmann::json& truth, bool pose,
                     std::size_t count = 1, std::size_t index = 0) {
  ASSERT_EQ(rig.at("projectors").size(), count);
  const auto& p = rig["projectors"][index];
  const Mat3 K = matrix9(p.at("K")), Kt = matrix3x3(truth.at("K_matrix"));
  EXPECT_NEAR(K(0, 0), Kt(0, 0), 0.005 * Kt(0, 0));
  EXPECT_NEAR(K(1, 1), Kt(1, 1), 0.005 * Kt(1, 1));
  EXPECT_NEAR(K(0, 2), Kt(0, 2), 2.0);
  EXPECT_NEAR(K(1, 2), Kt(1, 2), 2.0);
  const Mat3 R = matrix9(p.at("R")), Rt = matrix3x3(truth.at("R"));
  const Vec3 centre = -R.transpose() * vector3(p.at("t"));
  const Vec3 true_centre = vector3(truth.at("center"));
  const double rot_deg = Eigen::AngleAxisd(R.transpose() * Rt).angle() * 180 / M_PI;
  if (pose) {
    EXPECT_LT((centre - true_centre).norm(), 0.002);
    EXPECT_LT(rot_deg, 0.05);
  }
  std::printf(
      "[ figures  ] fx %.2f (%.2f) fy %.2f (%.2f) cx %.2f (%.2f) cy %.2f (%.2f), centre error "
      "%.2f mm, rotation error %.4f deg, reprojection RMS %.3f px\n",
      K(0, 0), Kt(0, 0), K(1, 1), Kt(1, 1), K(0, 2), Kt(0, 2), K(1, 2), Kt(1, 2),
      1000 * (centre - true_centre).norm(), rot_deg, p.at("reprojection_rms_px").get<double>());
}

const nlohmann::json& device(const nlohmann::json& truth, const char* kind,
                             const std::string& name) {
  for (const auto& d : truth.at(kind))
    if (d.at("name") == name) return d;
  static const nlohmann::json none;
  return none;
}

// Writes the scene text to DIR/NAME.toml and returns the path.
std::string writeScene(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.file(name + ".toml");
  dir.write(name + ".toml", text);
  return path;
}

}  // namespace

TEST(CalibrateCli, PatternsWritesOnePngPerFrameAndTheSequence) {
  TempDir dir;
  // 64x40, gray+phase, period 32: the Gray cell is 8 px, so 8 column cells (3 bits)
  // and 5 row cells (3 bits); frames: white, black, 2 x 3 + 2 x 3 Gray with inverses,
  // 3 + 3 phase.
  auto r = calibrate({"patterns", "--projector", "64x40", "--mode", "gray+phase", "--phase-steps",
                      "3", "--out", dir.file("p")});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json seq = readJsonFile(dir.file("p/sequence.json"));
  ASSERT_FALSE(seq.is_discarded());
  EXPECT_EQ(seq.at("projector").at("width"), 64);
  EXPECT_EQ(seq.at("projector").at("height"), 40);
  EXPECT_EQ(seq.at("mode"), "gray+phase");
  EXPECT_EQ(seq.at("phase_steps"), 3);
  ASSERT_EQ(seq.at("frames").size(), 20u);
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(dir.file("p")))
    pngs += e.path().extension() == ".png";
  EXPECT_EQ(pngs, 20);
  std::map<std::string, int> kinds;
  for (const auto& f : seq["frames"]) {
    ++kinds[f.at("kind").get<std::string>()];
    const cv::Mat m =
        cv::imread(dir.file("p/" + f.at("file").get<std::string>()), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(m.empty()) << f.dump();
    EXPECT_EQ(m.cols, 64);
    EXPECT_EQ(m.rows, 40);
    EXPECT_EQ(m.type(), CV_8UC1);
    double lo = 0, hi = 0;
    cv::minMaxLoc(m, &lo, &hi);
    if (f["kind"] == "white") {
      EXPECT_EQ(lo, 255);
    }
    if (f["kind"] == "black") {
      EXPECT_EQ(hi, 0);
    }
  }
  EXPECT_EQ(seq["frames"][0].at("file"), "00_white.png");
  EXPECT_EQ(seq["frames"][1].at("file"), "01_black.png");
  EXPECT_EQ(kinds["gray"], 6);
  EXPECT_EQ(kinds["gray_inverse"], 6);
  EXPECT_EQ(kinds["phase"], 6);
  EXPECT_NE(r.err.find("20 frames"), std::string::npos) << r.err;  // progress on stderr

  // Gray only, one code per 4 px: 16 column cells (4 bits), 10 row cells (4 bits).
  r = calibrate({"patterns", "--projector", "64x40", "--step", "4", "--out", dir.file("g")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readJsonFile(dir.file("g/sequence.json")).at("frames").size(), 18u);

  // A malformed command line exits with 2 and names the option.
  r = calibrate({"patterns", "--projector", "64by40", "--out", dir.file("x")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--projector"), std::string::npos) << r.err;
}

// corner_stereo (half resolution, under the reference capture conditions): decode the
// left camera into a PFM, then route (a) with both cameras; route (a)'s accuracy bounds.
TEST(CalibrateCli, DecodeAndSolveRouteAOnCornerStereo) {
  TempDir dir;
  const std::string text = issueCornerStereo();
  ASSERT_FALSE(text.empty());
  const std::string scene = writeScene(dir, "corner", text);
  auto r = calibrate({"patterns", "--projector", "640x400", "--mode", "gray+phase", "--out",
                      dir.file("patterns")});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* cam : {"cam_left", "cam_right"}) {
    const std::string failed =
        renderCaptures(scene, dir.file("patterns"), "proj", cam, dir.file(cam), 5);
    ASSERT_TRUE(failed.empty()) << failed;
  }

  // decode: PFM against the true projector pixel of every lit camera pixel.
  r = calibrate({"decode", "--patterns", dir.file("patterns"), "--captures", dir.file("cam_left"),
                 "--out", dir.file("left.pfm")});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto pfm = readPfm(dir.file("left.pfm"));
  ASSERT_TRUE(pfm);
  ASSERT_EQ(pfm->width, 512);
  ASSERT_EQ(pfm->height, 384);
  auto parsed = sim::Scene::parse(text, "corner", {});
  ASSERT_TRUE(parsed);
  auto renderer = sim::Renderer::create(*parsed, parsed->at(0), {});
  auto truth_maps = renderer->cameraTruth("cam_left");
  ASSERT_TRUE(truth_maps);
  double sum = 0;
  int decoded = 0, lit = 0, bad_undecoded = 0;
  for (int y = 0; y < pfm->height; ++y)
    for (int x = 0; x < pfm->width; ++x) {
      const float u = pfm->u.at<float>(y, x), v = pfm->v.at<float>(y, x);
      const float c = pfm->confidence.at<float>(y, x);
      const bool ok = !(u == -1.0f && v == -1.0f);
      if (!ok) bad_undecoded += c != 0.0f;
      if (ok) {
        EXPECT_TRUE(c > 0 && c <= 1) << x << "," << y;
      }
      if (!truth_maps->lit[0].at<std::uint8_t>(y, x)) continue;
      ++lit;
      if (!ok) continue;
      const cv::Vec2f p = truth_maps->projector_pixel[0].at<cv::Vec2f>(y, x);
      sum += (u - p[0]) * (u - p[0]) + (v - p[1]) * (v - p[1]);
      ++decoded;
    }
  EXPECT_EQ(bad_undecoded, 0);
  const double rms = std::sqrt(sum / (2.0 * std::max(decoded, 1)));
  EXPECT_GT(decoded, 0.9 * lit);
  EXPECT_LE(rms, 0.1);  // Gray + phase decoding bound: <= 0.1 projector px RMS
  std::printf("[ figures  ] decode: %.4f projector px RMS over %d of %d lit pixels\n", rms, decoded,
              lit);

  // solve, route (a), with the true cameras.
  const nlohmann::json truth = sceneTruth(scene);
  ASSERT_FALSE(truth.is_null());
  dir.write("cameras.json", camerasJson(truth, {"cam_left", "cam_right"}));
  r = calibrate({"solve", "--patterns", dir.file("patterns"), "--captures", dir.file("cam_left"),
                 dir.file("cam_right"), "--cameras", dir.file("cameras.json"), "--step", "4",
                 "--out", dir.file("rig.json"), "--surface-out", dir.file("surface.ply")});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json rig = readJsonFile(dir.file("rig.json"));
  ASSERT_FALSE(rig.is_discarded());
  ASSERT_EQ(rig.at("cameras").size(), 2u);
  expectProjector(rig, device(truth, "projectors", "proj"), true);
  EXPECT_LE(rig["projectors"][0].at("reprojection_rms_px").get<double>(), 0.15);
  EXPECT_GT(rig["projectors"][0].at("points").get<int>(), 3000);

  // The surface: a mesh whose vertices lie on the walls y = 3 (x <= 0) and x = 0.
  ASSERT_TRUE(rig.at("surface").contains("mesh")) << rig["surface"].dump();
  EXPECT_EQ(rig["surface"]["mesh"], dir.file("surface.ply"));
  std::ifstream ply(dir.file("surface.ply"));
  std::string line;
  int vertices = -1;
  while (std::getline(ply, line) && line != "end_header")
    if (line.rfind("element vertex ", 0) == 0) vertices = std::stoi(line.substr(15));
  ASSERT_GT(vertices, 100);
  double wall = 0;
  for (int i = 0; i < vertices; ++i) {
    double x = 0, y = 0, z = 0;
    ASSERT_TRUE(std::getline(ply, line));
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf %lf %lf", &x, &y, &z), 3) << line;
    const double d = std::min(std::abs(y - 3.0), std::abs(x));
    wall += d * d;
  }
  const double surface_rms = std::sqrt(wall / vertices);
  EXPECT_LE(surface_rms, 0.001);
  std::printf("[ figures  ] surface: %d vertices, %.3f mm RMS from the walls\n", vertices,
              1000 * surface_rms);
}

// Two projectors side by side on a curved wall (a cylinder of radius 3 m, as cylinder3 at
// half resolution), each scanned by both cameras: one `solve` with a --projector group
// each writes one rig.json with both projectors in the cameras' frame and a mesh beside it
// for each, which procam-render then draws as one display for a viewer.
TEST(CalibrateCli, SolveSeveralProjectorsIntoOneRigThatProcamRenderDraws) {
  TempDir dir;
  const std::string scene = writeScene(dir, "curve", R"(
[scene]
name = "curve"
ambient = 0.02
[[projectors]]
name = "left"
resolution = [640, 400]
intrinsics = { hfov_deg = 50.0 }
pose = { position = [-0.35, -0.2, 1.3], look_at = [-1.35, 2.68, 1.75] }
blur_sigma_px = 0.5
brightness = 10.0
[[projectors]]
name = "right"
resolution = [640, 400]
intrinsics = { hfov_deg = 50.0 }
pose = { position = [0.35, -0.2, 1.3], look_at = [1.35, 2.68, 1.75] }
blur_sigma_px = 0.5
brightness = 10.0
[[cameras]]
name = "cam_a"
resolution = [512, 384]
intrinsics = { hfov_deg = 90.0 }
distortion = { k1 = -0.04, k2 = 0.01 }
pose = { position = [-1.2, -1.5, 1.6], look_at = [0.0, 3.0, 1.6] }
bit_depth = 10
read_noise_dn = 1.0
full_well_e = 10000.0
exposure = 0.7
psf_sigma_px = 0.7
supersamples = 4
[[cameras]]
name = "cam_b"
resolution = [512, 384]
intrinsics = { hfov_deg = 90.0 }
distortion = { k1 = -0.05, k2 = 0.012 }
pose = { position = [1.2, -1.5, 1.6], look_at = [0.0, 3.0, 1.6] }
bit_depth = 10
read_noise_dn = 1.0
full_well_e = 10000.0
exposure = 0.7
psf_sigma_px = 0.7
supersamples = 4
[[surfaces]]
name = "screen"
type = "cylinder"
base = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
radius = 3.0
height = 3.5
albedo = 0.85
)");
  auto r = calibrate({"patterns", "--projector", "640x400", "--mode", "gray+phase", "--phase-steps",
                      "3", "--out", dir.file("patterns")});
  ASSERT_EQ(r.status, 0) << r.err;
  int seed = 11;
  for (const char* projector : {"left", "right"}) {
    for (const char* cam : {"cam_a", "cam_b"}) {
      const std::string failed =
          renderCaptures(scene, dir.file("patterns"), projector, cam,
                         dir.file(std::string(projector) + "_" + cam), ++seed);
      ASSERT_TRUE(failed.empty()) << failed;
    }
  }
  const nlohmann::json truth = sceneTruth(scene);
  ASSERT_FALSE(truth.is_null());
  dir.write("cameras.json", camerasJson(truth, {"cam_a", "cam_b"}));
  fs::create_directories(dir.file("rig"));
  r = calibrate({"solve", "--cameras", dir.file("cameras.json"), "--out", dir.file("rig/rig.json"),
                 "--projector", "left", "--patterns", dir.file("patterns"), "--captures",
                 dir.file("left_cam_a"), dir.file("left_cam_b"), "--projector", "right",
                 "--patterns", dir.file("patterns"), "--captures", dir.file("right_cam_a"),
                 dir.file("right_cam_b")});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json rig = readJsonFile(dir.file("rig/rig.json"));
  ASSERT_FALSE(rig.is_discarded());
  expectProjector(rig, device(truth, "projectors", "left"), true, 2, 0);
  expectProjector(rig, device(truth, "projectors", "right"), true, 2, 1);
  EXPECT_EQ(rig["surface"]["meshes"],
            nlohmann::json({{"left", "surface-left.ply"}, {"right", "surface-right.ply"}}));
  // Every mesh vertex on the true wall: within 1 mm of the radius.
  for (const char* name : {"left", "right"}) {
    std::ifstream ply(dir.file(std::string("rig/surface-") + name + ".ply"));
    std::string line;
    int vertices = -1;
    while (std::getline(ply, line) && line != "end_header")
      if (line.rfind("element vertex ", 0) == 0) vertices = std::stoi(line.substr(15));
    ASSERT_GT(vertices, 100) << name;
    double sq = 0;
    for (int i = 0; i < vertices; ++i) {
      double x = 0, y = 0, z = 0;
      ASSERT_TRUE(std::getline(ply, line));
      ASSERT_EQ(std::sscanf(line.c_str(), "%lf %lf %lf", &x, &y, &z), 3) << line;
      sq += std::pow(std::hypot(x, y) - 3.0, 2);
    }
    std::printf("[ figures  ] %s: %d mesh vertices, %.3f mm RMS from the cylinder\n", name,
                vertices, 1000 * std::sqrt(sq / vertices));
    EXPECT_LE(std::sqrt(sq / vertices), 0.001) << name;
  }
  // The wrong shapes of a group are command-line errors naming the option.
  r = calibrate({"solve", "--cameras", dir.file("cameras.json"), "--out", dir.file("x.json"),
                 "--projector", "left", "--patterns", dir.file("patterns"), "--captures",
                 dir.file("left_cam_a")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--captures"), std::string::npos) << r.err;
  r = calibrate({"solve", "--cameras", dir.file("cameras.json"), "--out", dir.file("x.json"),
                 "--projector", "../up", "--patterns", dir.file("patterns"), "--captures",
                 dir.file("left_cam_a"), dir.file("left_cam_b")});
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(dir.file("x.json")));

  // procam-render draws the calibrated pair as one display for a viewer.
  cv::imwrite(dir.file("white.png"), cv::Mat(300, 1200, CV_8UC3, cv::Scalar::all(255)));
  const procam::itest::RunResult drawn = procam::itest::runProgram(
      {PROCAM_RENDER_BIN, "--rig", dir.file("rig/rig.json"), "--content", dir.file("white.png"),
       "--out", dir.file("frames"), "--viewer", "0,-0.6,1.6"});
  ASSERT_EQ(drawn.status, 0) << drawn.err;
  const nlohmann::json display = readJsonFile(dir.file("frames/display.json"));
  EXPECT_EQ(display["display"]["surface"], "mesh");
  EXPECT_EQ(display["projectors"].size(), 2u);
  EXPECT_FALSE(cv::imread(dir.file("frames/left.png")).empty());
}

// wall_oblique: `solve` (route a) on the plane fails with the coplanar error naming
// solve-planes; `solve-planes` (route b) with the wall at two orientations meets the
// intrinsics accuracy bounds.
TEST(CalibrateCli, WallObliqueCoplanarErrorAndSolvePlanes) {
  TempDir dir;
  const std::string straight = issueWallOblique(0.0), turned = issueWallOblique(25.0);
  ASSERT_FALSE(straight.empty());
  ASSERT_FALSE(turned.empty());
  const std::string scene0 = writeScene(dir, "wall0", straight);
  const std::string scene1 = writeScene(dir, "wall25", turned);
  auto r = calibrate({"patterns", "--projector", "960x540", "--mode", "gray+phase", "--out",
                      dir.file("patterns")});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const auto& [scene, cam, out, seed] :
       {std::tuple{scene0, "cam", "wall0_cam", 6}, std::tuple{scene0, "cam2", "wall0_cam2", 7},
        std::tuple{scene1, "cam", "wall25_cam", 8}}) {
    const std::string failed =
        renderCaptures(scene, dir.file("patterns"), "proj", cam, dir.file(out), seed);
    ASSERT_TRUE(failed.empty()) << failed;
  }
  const nlohmann::json truth = sceneTruth(scene0);
  ASSERT_FALSE(truth.is_null());
  dir.write("cameras.json", camerasJson(truth, {"cam", "cam2"}));

  r = calibrate({"solve", "--patterns", dir.file("patterns"), "--captures", dir.file("wall0_cam"),
                 dir.file("wall0_cam2"), "--cameras", dir.file("cameras.json"), "--out",
                 dir.file("rig_a.json")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("coplanar"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("solve-planes"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("rig_a.json")));

  // Camera centre (-0.6, -0.6, 1.5) to the first wall, the plane y = 3.
  r = calibrate({"solve-planes", "--patterns", dir.file("patterns"), "--captures",
                 dir.file("wall0_cam"), dir.file("wall25_cam"), "--cameras",
                 dir.file("cameras.json"), "--camera", "cam", "--plane-distance", "3.6", "--step",
                 "4", "--out", dir.file("rig_b.json")});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json rig = readJsonFile(dir.file("rig_b.json"));
  ASSERT_FALSE(rig.is_discarded());
  expectProjector(rig, device(truth, "projectors", "proj"), false);
  EXPECT_FALSE(rig["projectors"][0].contains("translation_up_to_scale"));
}

// Route (c): fiducials on both corner_stereo walls lit by the true projector.
TEST(CalibrateCli, SolveFiducials) {
  TempDir dir;
  const nlohmann::json truth = sceneTruth("corner_stereo");
  ASSERT_FALSE(truth.is_null());
  const nlohmann::json& proj = device(truth, "projectors", "proj");
  Mat34 P;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) P(r, c) = proj.at("P").at(r).at(c).get<double>();
  nlohmann::json points = nlohmann::json::array();
  // Back wall y = 3 and side wall x = 0, 1.0 .. 1.6 m high.
  for (const Vec3& X :
       {Vec3(-0.9, 3, 1.0), Vec3(-0.5, 3, 1.6), Vec3(-0.2, 3, 1.2), Vec3(-1.2, 3, 1.4),
        Vec3(0, 2.7, 1.1), Vec3(0, 2.4, 1.5), Vec3(0, 2.1, 1.25), Vec3(0, 2.8, 1.55)}) {
    const Vec3 x = P * X.homogeneous();
    points.push_back(
        {{"world", {X.x(), X.y(), X.z()}}, {"projector", {x.x() / x.z(), x.y() / x.z()}}});
  }
  dir.write("points.json", nlohmann::json({{"points", points}}).dump());
  auto r = calibrate({"solve-fiducials", "--fiducials", dir.file("points.json"), "--projector",
                      "1280x800", "--out", dir.file("rig.json")});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json rig = readJsonFile(dir.file("rig.json"));
  ASSERT_FALSE(rig.is_discarded());
  expectProjector(rig, proj, true);
  EXPECT_EQ(rig["projectors"][0].at("points"), 8);
  EXPECT_EQ(rig["projectors"][0].at("width"), 1280);

  // Five fiducials are too few; eight on the back wall alone are coplanar.
  nlohmann::json five = points;
  five.erase(five.begin() + 5, five.end());
  dir.write("five.json", nlohmann::json({{"points", five}}).dump());
  r = calibrate({"solve-fiducials", "--fiducials", dir.file("five.json"), "--projector", "1280x800",
                 "--out", dir.file("rig5.json")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("at least 6"), std::string::npos) << r.err;
  nlohmann::json flat = nlohmann::json::array();
  for (int i = 0; i < 8; ++i) {
    const Vec3 X(-1.4 + 0.17 * i, 3, 1.0 + 0.08 * ((i * 5) % 8));
    const Vec3 x = P * X.homogeneous();
    flat.push_back(
        {{"world", {X.x(), X.y(), X.z()}}, {"projector", {x.x() / x.z(), x.y() / x.z()}}});
  }
  dir.write("flat.json", nlohmann::json({{"points", flat}}).dump());
  r = calibrate({"solve-fiducials", "--fiducials", dir.file("flat.json"), "--projector", "1280x800",
                 "--out", dir.file("rigf.json")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("coplanar"), std::string::npos) << r.err;
}

namespace {

// A wall (the plane y = 3) with a 10 x 7 square checkerboard (9 x 6 inner corners)
// projected head-on: the projector at 3 m looks along +Y with f = 1000 px, so one
// projector pixel is 3 mm on the wall and a 40 px square is 0.12 m. Fifteen cameras
// (one per view) at varied distance, tilt and roll look at it.
std::string checkerScene(int views) {
  std::string s = R"([scene]
name = "checker_wall"
ambient = 0.02

[[projectors]]
name = "proj"
resolution = [800, 600]
intrinsics = { fx = 1000.0, fy = 1000.0, cx = 399.5, cy = 299.5 }
pose = { position = [0.0, 0.0, 1.5], look_at = [0.0, 3.0, 1.5] }
gamma = 2.2
brightness = 9.0

[[surfaces]]
name = "wall"
type = "plane"
point = [0.0, 3.0, 0.0]
normal = [0.0, -1.0, 0.0]
albedo = 0.8
)";
  for (int i = 0; i < views; ++i) {
    const double yaw = 0.5 * std::sin(1.7 * i + 0.3), pitch = 0.35 * std::cos(2.3 * i + 0.1);
    const double roll = 0.25 * std::sin(0.9 * i), dist = 1.75 + 0.2 * std::sin(1.3 * i);
    const Vec3 centre(0, 3, 1.5);
    const Vec3 eye = centre + dist * Vec3(std::sin(yaw) * std::cos(pitch),
                                          -std::cos(yaw) * std::cos(pitch), std::sin(pitch));
    const Vec3 at = centre + Vec3(0.05 * std::sin(2.1 * i), 0, 0.04 * std::cos(1.1 * i));
    char camera[640];
    std::snprintf(camera, sizeof camera, R"(
[[cameras]]
name = "cam%02d"
resolution = [640, 480]
intrinsics = { fx = 620.0, fy = 622.0, cx = 322.0, cy = 236.0 }
distortion = { k1 = -0.12, k2 = 0.03, p1 = 0.0005, p2 = -0.0003 }
pose = { position = [%.6f, %.6f, %.6f], look_at = [%.6f, %.6f, %.6f], up = [%.6f, 0.0, %.6f] }
bit_depth = 8
read_noise_dn = 1.0
psf_sigma_px = 0.6
exposure = 0.8
)",
                  i, eye.x(), eye.y(), eye.z(), at.x(), at.y(), at.z(), std::sin(roll),
                  std::cos(roll));
    s += camera;
  }
  return s;
}

}  // namespace

// Camera calibration from 15 rendered checkerboard views: focal within 0.3%.
TEST(CalibrateCli, CameraFromFifteenCheckerboardViews) {
  TempDir dir;
  const int views = 15;
  const std::string scene = writeScene(dir, "checker", checkerScene(views));
  // Squares of 40 px, the board centred; white around it.
  cv::Mat board(600, 800, CV_8UC1, cv::Scalar(255));
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 10; ++i)
      if ((i + j) % 2 == 0) board(cv::Rect(200 + 40 * i, 160 + 40 * j, 40, 40)).setTo(0);
  ASSERT_TRUE(cv::imwrite(dir.file("board.png"), board));
  fs::create_directories(dir.file("views"));
  for (int i = 0; i < views; ++i) {
    char name[16];
    std::snprintf(name, sizeof name, "cam%02d", i);
    auto r = simulate({"render", "--scene", scene, "--show", "proj=" + dir.file("board.png"),
                       "--camera", name, "--seed", std::to_string(i + 1), "--out",
                       dir.file("views/" + std::string(name) + ".png")});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  auto r = calibrate({"camera", "--images", dir.file("views"), "--board", "checker:9x6:0.12",
                      "--name", "test_cam", "--out", dir.file("camera.json")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("not found"), std::string::npos) << r.err;  // every view detected
  const nlohmann::json j = readJsonFile(dir.file("camera.json"));
  ASSERT_FALSE(j.is_discarded());
  ASSERT_EQ(j.at("cameras").size(), 1u);
  const auto& c = j["cameras"][0];
  EXPECT_EQ(c.at("name"), "test_cam");
  EXPECT_EQ(c.at("width"), 640);
  const Mat3 K = matrix9(c.at("K"));
  EXPECT_NEAR(K(0, 0), 620.0, 0.003 * 620.0);
  EXPECT_NEAR(K(1, 1), 622.0, 0.003 * 622.0);
  std::printf(
      "[ figures  ] camera: fx %.2f (620) fy %.2f (622) cx %.2f (322) cy %.2f (236), "
      "k1 %.4f (-0.12), RMS %.3f px\n",
      K(0, 0), K(1, 1), K(0, 2), K(1, 2), c.at("dist").at(0).get<double>(),
      c.at("reprojection_rms_px").get<double>());
}

// Errors: missing frames, wrong sizes and too few decoded points exit with 1 and a
// message naming the cause. The "captures" are the pattern files themselves (a
// camera that sees the projector's framebuffer one to one), so nothing is rendered.
TEST(CalibrateCli, ErrorsNameTheCause) {
  TempDir dir;
  auto r = calibrate({"patterns", "--projector", "64x40", "--out", dir.file("patterns")});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json seq = readJsonFile(dir.file("patterns/sequence.json"));
  auto copyCaptures = [&](const std::string& name) {
    fs::create_directories(dir.file(name));
    for (const auto& f : seq.at("frames"))
      fs::copy_file(dir.file("patterns/" + f.at("file").get<std::string>()),
                    dir.file(name + "/" + f.at("file").get<std::string>()));
  };
  auto decode = [&](const std::string& captures) {
    return calibrate({"decode", "--patterns", dir.file("patterns"), "--captures",
                      dir.file(captures), "--out", dir.file(captures + ".pfm")});
  };
  copyCaptures("direct");
  r = decode("direct");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto pfm = readPfm(dir.file("direct.pfm"));
  ASSERT_TRUE(pfm);
  EXPECT_EQ(pfm->u.at<float>(0, 0), 0.0f);  // top-left pixel: projector (0, 0)
  EXPECT_EQ(pfm->u.at<float>(39, 63), 63.0f);
  EXPECT_EQ(pfm->v.at<float>(39, 63), 39.0f);

  copyCaptures("missing");
  const std::string gone = seq["frames"][7].at("file");
  fs::remove(dir.file("missing/" + gone));
  r = decode("missing");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("missing frame"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(gone), std::string::npos) << r.err;

  copyCaptures("small");
  const std::string shrunk = seq["frames"][4].at("file");
  ASSERT_TRUE(cv::imwrite(dir.file("small/" + shrunk), cv::Mat(20, 32, CV_8UC1, cv::Scalar(0))));
  r = decode("small");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("32x20"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(shrunk), std::string::npos) << r.err;

  // The projector never reached the camera: every capture black.
  fs::create_directories(dir.file("dark"));
  for (const auto& f : seq.at("frames"))
    cv::imwrite(dir.file("dark/" + f.at("file").get<std::string>()),
                cv::Mat(40, 64, CV_8UC1, cv::Scalar(3)));
  r = decode("dark");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("could be decoded"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("dark.pfm")));

  // solve: captures that do not match the cameras' size, and too few decoded points.
  const nlohmann::json cam = {{"width", 64},
                              {"height", 40},
                              {"K", {60, 0, 31.5, 0, 60, 19.5, 0, 0, 1}},
                              {"R", {1, 0, 0, 0, 1, 0, 0, 0, 1}}};
  nlohmann::json left = cam, right = cam;
  left["name"] = "left";
  left["t"] = {0, 0, 0};
  right["name"] = "right";
  right["t"] = {-0.1, 0, 0};
  dir.write("cameras.json", nlohmann::json({{"cameras", {left, right}}}).dump());
  left["width"] = 80;
  dir.write("cameras_wide.json", nlohmann::json({{"cameras", {left, right}}}).dump());
  auto solve = [&](const std::string& a, const std::string& b, const std::string& cameras) {
    return calibrate({"solve", "--patterns", dir.file("patterns"), "--captures", dir.file(a),
                      dir.file(b), "--cameras", dir.file(cameras), "--out", dir.file("rig.json")});
  };
  r = solve("direct", "direct", "cameras_wide.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("'left'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("64x40"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("80x40"), std::string::npos) << r.err;
  r = solve("dark", "direct", "cameras.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("too-few-points"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("could be decoded"), std::string::npos) << r.err;
  r = solve("direct", "missing", "cameras.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("missing frame"), std::string::npos) << r.err;
  r = calibrate({"solve", "--patterns", dir.file("patterns"), "--captures", dir.file("direct"),
                 "--cameras", dir.file("cameras.json"), "--out", dir.file("rig.json")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("solve-planes"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("rig.json")));
}
