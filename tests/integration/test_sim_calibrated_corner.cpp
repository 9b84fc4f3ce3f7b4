// Content on the calibrated corner, over the socket only: corner_stereo at half
// resolution calibrated by the daemon (route (a), the cameras handed over), then image and
// mesh content drawn through the lookup warp for a configured viewer and compared with
// what the true rig draws.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "content/mesh_content.hpp"
#include "content/mesh_placement.hpp"
#include "daemon_harness.hpp"
#include "json_matrix.hpp"
#include "mesh_ray_cast.hpp"
#include "sim/truth_rig.hpp"
#include "sim_calibrate_run.hpp"
#include "truth_rig_file.hpp"

namespace procam::itest {
namespace {

// The calibrated-corner tests: corner_stereo at half resolution, the viewer configured
// at kCornerEye, the cameras handed over (as an offline camera calibration gives them).
const Vec3 kCornerEye(-1.6, 0.4, 1.6);

DaemonProcess::Launch cornerWithViewer(const TempDir& dir, const std::string& scene) {
  dir.write("procamd.toml",
            "[sim]\nscene = \"" + scene + "\"\n[content]\nviewer = [-1.6, 0.4, 1.6]\n");
  return DaemonProcess::Launch{{"--config", dir.file("procamd.toml"), "--rig",
                                truthRigFile(dir, scene, TruthParts::kCamerasOnly)},
                               {},
                               -1,
                               true};
}

// The first output's status entry once it shows content through the lookup warp.
std::optional<json> shownByLookupWarp(Connection& c) {
  json shown;
  const bool ok = eventually(
      [&] {
        auto s = c.call({{"cmd", "status"}});
        if (!s || (*s)["outputs"]["shown"].empty()) return false;
        shown = (*s)["outputs"]["shown"][0];
        return shown["source"] == "content" && shown.value("path", "") == "lookup-warp" &&
               shown["lit_fraction"].get<double>() > 0;
      },
      20s);
  if (!ok) {
    ADD_FAILURE() << "no content through the lookup warp: " << shown.dump();
    return std::nullopt;
  }
  return shown;
}

// `label(surface point)` for every pixel of the scene's TRUE projector whose ray meets a
// TRUE surface (0 elsewhere), as a CV_16S image of the projector's size.
template <class Label>
cv::Mat labelTrueSurface(const std::string& scene, Label label) {
  auto truth = sim::Scene::load(scene);
  EXPECT_TRUE(truth) << truth.error().message;
  if (!truth) return {};
  const sim::SceneState state = truth->at(0);
  const auto& proj = state.projectors.at(0);
  const Mat34 P = proj.model.projectionMatrix();
  const Mat3 Minv = P.leftCols<3>().inverse();
  const Vec3 C = -Minv * P.col(3);
  cv::Mat labels(proj.spec.height, proj.spec.width, CV_16S, cv::Scalar(0));
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      const auto hit = truth->world().intersect({C, (Minv * Vec3(x, y, 1)).normalized()});
      if (hit) labels.at<int16_t>(y, x) = static_cast<int16_t>(label(hit->hit.point));
    }
  }
  return labels;
}

// Fraction of pixels within 2 px of a change of label: where two renderings of the same
// geometry may legitimately differ.
double edgeBand(const cv::Mat& labels) {
  cv::Mat lo, hi;
  const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5));
  cv::erode(labels, lo, k);
  cv::dilate(labels, hi, k);
  return cv::countNonZero(lo != hi) / double(labels.total());
}

// End to end with nothing taken from truth but the cameras (calibrated beforehand, as
// procam-calibrate gives them): calibrate finds the projector and the two walls, image
// content is then drawn for the configured viewer by the lookup warp ([Raskar02] §4.1.5),
// and the frame the output shows matches a double-precision ray cast of the TRUE projector
// and walls: each projector pixel shows the content pixel where the viewer's ray through its
// wall point meets the content's plane (the viewer matrix the daemon reports: where the
// content is placed is its choice, not a fact of the rig). Tolerance: pixels within 2 px of
// a colour boundary of the ray cast (1 px of bilinear resampling, 0.5 px of calibration
// error: 2 mm at 3 m, 0.5 px of linear interpolation between the warp's 8 px nodes).
TEST(SimCalibrate, ImageContentOnTheCalibratedCornerMatchesTheTrueRig) {
  TempDir dir;
  const std::string scene = sceneFile(dir);
  DaemonProcess d(dir, cornerWithViewer(dir, scene));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_NO_FATAL_FAILURE(calibrateToTheEnd(c, d));

  // Content: left half red, right half blue.
  constexpr int kW = 320, kH = 200;
  cv::Mat bgr(kH, kW, CV_8UC3, cv::Scalar(0, 0, 255));
  bgr(cv::Rect(kW / 2, 0, kW / 2, kH)).setTo(cv::Scalar(255, 0, 0));
  const std::string png = contentFile(dir, "halves.png");
  ASSERT_TRUE(cv::imwrite(png, bgr));
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}}, 30s);
  ASSERT_TRUE(load);
  ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
  const auto shown_now = shownByLookupWarp(c);
  ASSERT_TRUE(shown_now);
  const json shown = *shown_now;
  EXPECT_EQ(shown["chosen_path"], "lookup-warp");
  ASSERT_EQ(shown["viewer_matrix"].size(), 12u) << shown.dump();
  const Mat34 V = rowMajor34(shown["viewer_matrix"]);

  // The true rig: 1 red, 2 blue, 0 dark.
  const cv::Mat cls = labelTrueSurface(scene, [&](const Vec3& point) {
    const Vec3 q = V * point.homogeneous();
    if (q.z() <= 0) return 0;
    const double u = q.x() / q.z(), v = q.y() / q.z();
    if (u < -0.5 || u >= kW - 0.5 || v < -0.5 || v >= kH - 0.5) return 0;
    return u < kW / 2 - 0.5 ? 1 : 2;
  });
  ASSERT_FALSE(cls.empty());
  const double n = double(cls.total());
  const double red = cv::countNonZero(cls == 1) / n, blue = cv::countNonZero(cls == 2) / n;
  const double band = edgeBand(cls);
  const double lit = shown["lit_fraction"].get<double>();
  const double r = shown["mean_rgb"][0].get<double>(), b = shown["mean_rgb"][2].get<double>();
  std::printf(
      "[ figures  ] lookup warp on the calibrated corner: lit %.5f (true rig %.5f), red %.3f "
      "(%.3f), blue %.3f (%.3f), 2 px edge band %.5f\n",
      lit, red + blue, r, 255 * red, b, 255 * blue, band);
  EXPECT_GT(red, 0.05);
  EXPECT_GT(blue, 0.05);
  EXPECT_NEAR(lit, red + blue, band);
  EXPECT_NEAR(r, 255 * red, 255 * band);
  EXPECT_NEAR(b, 255 * blue, 255 * band);
  EXPECT_EQ(shown["mean_rgb"][1].get<double>(), 0.0);
}

// 3D content on the calibrated corner, end to end with nothing from truth but the
// cameras: the cube is placed on the plane through the calibrated surface at the projector's
// centre, inside the content image the viewer sees (content/mesh_placement.hpp rules; the
// plane and image reported), drawn from the viewer and shown through the lookup warp; the frame
// must match a double-precision ray cast of the TRUE projector and walls: each projector pixel
// shows the cube face the viewer's ray through its wall point meets, Lambert grey. Tolerance:
// pixels within 2 px of a change of face (resampling the viewer's image 1 px, calibration 0.5 px,
// warp interpolation 0.5 px), each worth one pixel of lit fraction and 255 grey, plus 0.5 grey of
// rounding.
TEST(SimCalibrate, MeshContentOnTheCalibratedCornerMatchesTheTrueRig) {
  TempDir dir;
  const std::string scene = sceneFile(dir);
  writeContent(dir, "cube.obj",
               "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\n"
               "v -1 1 1\nf 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 7 3\n"
               "f 4 8 7\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n");
  DaemonProcess d(dir, cornerWithViewer(dir, scene));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_NO_FATAL_FAILURE(calibrateToTheEnd(c, d));
  std::optional<json> load;
  ASSERT_TRUE(eventually(
      [&] {
        load = c.call(
            {{"cmd", "content"}, {"action", "load"}, {"path", contentFile(dir, "cube.obj")}}, 30s);
        return load && (*load)["class"] == "CONTENT";
      },
      10s))
      << (load ? load->dump() : "no reply");
  const json placement = (*load)["content"]["mesh"]["placement"]["proj"];
  ASSERT_TRUE(placement.is_object()) << load->dump();
  const auto shown_now = shownByLookupWarp(c);
  ASSERT_TRUE(shown_now);
  const json shown = *shown_now;

  // The placement the daemon made, from what it reports (placement is the daemon's
  // choice, not a fact of the rig): the plane and the viewer's content image.
  auto cube = content::loadMeshContent(contentFile(dir, "cube.obj"));
  ASSERT_TRUE(cube);
  auto vec = [](const json& j) {
    return Vec3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
  };
  ASSERT_EQ(placement["viewer_matrix"].size(), 12u) << placement.dump();
  content::PlanarView view;
  view.projector = rowMajor34(placement["viewer_matrix"]);
  view.size = {placement["size"][0].get<int>(), placement["size"][1].get<int>()};
  view.plane_point = vec(placement["plane_point"]);
  view.plane_normal = vec(placement["plane_normal"]);
  view.eye = kCornerEye;
  auto placed = content::placeMeshContent(*cube, view);
  ASSERT_TRUE(placed) << placed.error().message;

  // The true rig: each projector pixel's wall point, the viewer's ray through it, the
  // nearest cube face (label face + 1), Lambert grey.
  const cv::Mat faces = labelTrueSurface(scene, [&](const Vec3& point) {
    return nearestFace(placed->mesh, kCornerEye, point - kCornerEye) + 1;
  });
  ASSERT_FALSE(faces.empty());
  const double n = double(faces.total());
  double lit_true = 0, grey_true = 0;
  for (int y = 0; y < faces.rows; ++y) {
    for (int x = 0; x < faces.cols; ++x) {
      const int face = faces.at<int16_t>(y, x) - 1;
      if (face < 0) continue;
      lit_true += 1 / n;
      grey_true += lambertGrey(*placed, face) / n;
    }
  }
  const double band = edgeBand(faces);
  const double lit = shown["lit_fraction"].get<double>();
  std::printf(
      "[ figures  ] cube on the calibrated corner (lookup warp): lit %.5f (true rig %.5f), "
      "mean grey %.3f (%.3f), 2 px edge band %.5f\n",
      lit, lit_true, shown["mean_rgb"][0].get<double>(), grey_true, band);
  ASSERT_GT(lit_true, 0.01);  // the cube is in view
  EXPECT_NEAR(lit, lit_true, band);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(shown["mean_rgb"][ch].get<double>(), grey_true, 255 * band + 0.5) << ch;
  }
}

}  // namespace
}  // namespace procam::itest
