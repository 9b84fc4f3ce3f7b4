// 3D content on the virtual rig: `content load` of an OBJ cube on `wall_oblique` (a
// planar wall; the scene's viewer, or [content] viewer from the configuration) is drawn through the
// planar 3D path, and the output's statistics (status.outputs.shown) match a double-precision ray
// cast of the placed cube seen by the viewer ([Raskar02] §4.2.1: a projector pixel shows what the
// viewer's ray through that pixel's wall point meets). A non-planar surface makes the load
// `unavailable`. With a tracker the drawing follows the viewer as they move, and not while
// they stand still (noise below [content] viewer_threshold_m).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "content/mesh_placement.hpp"
#include "daemon_harness.hpp"
#include "mesh_ray_cast.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"

namespace procam::itest {
namespace {

const char* kCubeObj = R"(# unit cube
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 4 7 3
f 4 8 7
f 1 5 8
f 1 8 4
f 2 3 7
f 2 7 6
)";

json shownStats(Connection& c) {
  auto s = c.call({{"cmd", "status"}});
  if (!s || (*s)["outputs"]["shown"].empty()) return nullptr;
  return (*s)["outputs"]["shown"][0];
}

struct Expected {
  double lit = 0, mean = 0;  // lit fraction, mean grey level (0..255)
  double boundary = 0;       // fraction of pixels next to a change of the visible face
};

// Ray cast in double over every projector pixel: wall point, viewer ray, nearest face,
// Lambert grey of that face as documented in content/mesh_placement.hpp.
Expected rayCast(const content::PlacedMesh& placed, const Mat34& P, cv::Size size,
                 const Vec3& eye) {
  const Mat3 Minv = P.leftCols<3>().inverse();
  const Vec3 C = -Minv * P.col(3);
  const keystone::DisplayRect& S = placed.S;
  const Vec3 n = S.u.cross(S.v);
  cv::Mat face(size, CV_32S, cv::Scalar(-1));
  Expected e;
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const Vec3 d = Minv * Vec3(x, y, 1);
      const Vec3 wall = C + (n.dot(S.corner - C) / n.dot(d)) * d;
      face.at<int>(y, x) = nearestFace(placed.mesh, eye, wall - eye);
      if (face.at<int>(y, x) < 0) continue;
      e.lit += 1;
      e.mean += lambertGrey(placed, face.at<int>(y, x));
    }
  }
  // Pixels whose right or lower neighbour shows another face (or none): where two
  // rasterizations may legitimately differ by one pixel.
  for (int y = 0; y + 1 < size.height; ++y) {
    for (int x = 0; x + 1 < size.width; ++x) {
      const int f = face.at<int>(y, x);
      e.boundary += f != face.at<int>(y, x + 1) || f != face.at<int>(y + 1, x);
    }
  }
  const double total = static_cast<double>(size.area());
  e.lit /= total;
  e.mean /= total;
  e.boundary /= total;
  return e;
}

// Loads the cube on a daemon running wall_oblique and checks what its output shows
// against the ray cast for `eye` (reported as `source`).
void expectCubeShown(Connection& c, const TempDir& dir, const Vec3& eye,
                     const std::string& source) {
  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "off"}}))["pattern"], "off");
  auto load =
      c.call({{"cmd", "content"}, {"action", "load"}, {"path", contentFile(dir, "cube.obj")}}, 30s);
  ASSERT_TRUE(load);
  ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
  const json info = (*load)["content"];
  EXPECT_EQ(info["path"], contentFile(dir, "cube.obj"));
  EXPECT_EQ(info["mesh"]["triangles"], 12);
  EXPECT_EQ(info["mesh"]["viewer"]["source"], source);
  const json p = info["mesh"]["viewer"]["position"];
  ASSERT_TRUE(p.is_array()) << info.dump();
  EXPECT_LT((Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>()) - eye).norm(), 1e-12);
  json shown;
  ASSERT_TRUE(eventually(
      [&] {
        shown = shownStats(c);
        return shown.is_object() && shown["source"] == "content" &&
               shown["lit_fraction"].get<double>() > 0;
      },
      20s))
      << shown.dump();

  // The truth: the scene at time 0, the cube placed by the documented rule.
  auto scene = sim::resolveScene("wall_oblique");
  ASSERT_TRUE(scene);
  const sim::SceneState state = scene->at(0);
  const geom::CameraModel& proj = state.projector("proj")->model;
  auto cube = content::loadMeshContent(contentFile(dir, "cube.obj"));
  ASSERT_TRUE(cube);
  content::PlanarView view;
  view.projector = proj.projectionMatrix();
  view.size = {proj.width, proj.height};
  view.plane_point = Vec3(0, 3, 1.5);  // the wall: y = 3, normal -Y
  view.plane_normal = Vec3(0, -1, 0);
  view.eye = eye;
  auto placed = content::placeMeshContent(*cube, view);
  ASSERT_TRUE(placed) << placed.error().message;
  // Placement: the back of the cube on the wall, its front toward the viewer.
  double y_max = -INFINITY, y_min = INFINITY;
  for (const Vec3& q : placed->mesh.vertices)
    y_max = std::max(y_max, q.y()), y_min = std::min(y_min, q.y());
  EXPECT_NEAR(y_max, 3.0, 1e-9);
  EXPECT_LT(y_min, 3.0 - 0.05);

  const Expected e = rayCast(*placed, view.projector, view.size, view.eye);
  const double lit = shown["lit_fraction"].get<double>();
  std::printf(
      "cube (%s viewer): lit %.5f (ray cast %.5f), mean grey %.3f (ray cast %.3f), "
      "edge band %.5f\n",
      source.c_str(), lit, e.lit, shown["mean_rgb"][0].get<double>(), e.mean, e.boundary);
  ASSERT_GT(e.lit, 0.01);  // the cube is in view
  // Every pixel off the edge band is decided alike; a pixel of the band may flip,
  // changing the lit fraction by one pixel and the mean by at most 255 per pixel, plus
  // the rounding of each shade to an integer (0.5).
  EXPECT_NEAR(lit, e.lit, e.boundary);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(shown["mean_rgb"][k].get<double>(), e.mean, 255 * e.boundary + 0.5) << k;
  }
  auto get = c.call({{"cmd", "content"}});
  EXPECT_EQ((*get)["content"]["mesh"]["triangles"], 12);
}

TEST(SimMeshContent, ObjCubeOnTheObliqueWallIsDrawnForTheSceneViewer) {
  TempDir dir;
  writeContent(dir, "cube.obj", kCubeObj);
  DaemonProcess d(dir, simWithTruth(dir, "wall_oblique"));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto scene = sim::resolveScene("wall_oblique");
  ASSERT_TRUE(scene);
  expectCubeShown(c, dir, scene->viewerPosition(0), "rig");
  ASSERT_TRUE(c.call({{"cmd", "content"}, {"action", "clear"}}));
  ASSERT_TRUE(eventually([&] { return shownStats(c)["source"] == "none"; }));
  // A missing file is an I/O error, not `unavailable`.
  auto missing =
      c.call({{"cmd", "content"}, {"action", "load"}, {"path", contentFile(dir, "none.obj")}}, 30s);
  ASSERT_TRUE(missing);
  EXPECT_EQ((*missing)["code"], "io-error") << missing->dump();
}

TEST(SimMeshContent, ConfiguredViewerWinsOverTheScenes) {
  TempDir dir;
  writeContent(dir, "cube.obj", kCubeObj);
  dir.write("procamd.toml",
            "[sim]\nscene = \"wall_oblique\"\n[content]\nviewer = [0.6, 0.9, 1.3]\n");
  DaemonProcess d(dir, DaemonProcess::Launch{{"--config", dir.file("procamd.toml"), "--rig",
                                              truthRigFile(dir, "wall_oblique")},
                                             {},
                                             -1,
                                             true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  expectCubeShown(c, dir, Vec3(0.6, 0.9, 1.3), "config");
}

// `content load` of the cube on a daemon started with `launch`: the ERROR reply,
// checked to be `unavailable`.
json unavailableLoad(const TempDir& dir, DaemonProcess::Launch launch) {
  writeContent(dir, "cube.obj", kCubeObj);
  DaemonProcess d(dir, std::move(launch));
  EXPECT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto load =
      c.call({{"cmd", "content"}, {"action", "load"}, {"path", contentFile(dir, "cube.obj")}}, 30s);
  if (!load) {
    ADD_FAILURE() << "no reply";
    return nullptr;
  }
  EXPECT_EQ((*load)["class"], "ERROR") << load->dump();
  EXPECT_EQ((*load)["code"], "unavailable") << load->dump();
  return *load;
}

// Without a rig model the daemon has no geometry: the virtual rig's devices alone
// give no projector pose and no surface.
TEST(SimMeshContent, UncalibratedRigIsUnavailable) {
  TempDir dir;
  unavailableLoad(dir, DaemonProcess::Launch{{"--sim", "corner_stereo"}, {}, -1, true});
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/state/rig.json"));
}

// The dome's truth has no plane: a rig without a planar surface cannot take the
// planar 3D path (the calibrated, non-planar case is in daemon_calibrate_tests).
TEST(SimMeshContent, NonPlanarSurfaceIsUnavailable) {
  TempDir dir;
  const json load = unavailableLoad(dir, simWithTruth(dir, "dome3"));
  ASSERT_TRUE(load.is_object());
  EXPECT_NE(load["message"].get<std::string>().find("display surface"), std::string::npos)
      << load.dump();
}

// wall_oblique's wall and projector (at half resolution) with a tracked viewer who stands
// at A until t = 6 s, walks to B by t = 7 s and stays there; tracker noise 0.5 mm.
const char* kFollowScene = R"([scene]
name = "follow_viewer"
ambient = 0.02

[[projectors]]
name = "proj"
resolution = [960, 540]
intrinsics = { fx = 1200.0, fy = 1200.0, cx = 479.5, cy = 269.5 }
pose = { position = [1.3, 0.0, 0.5], yaw_deg = -30.0, pitch_deg = 15.0, roll_deg = 0.0 }
gamma = 2.2
brightness = 11.0

[[surfaces]]
name = "wall"
type = "rectangle"
center = [0.0, 3.0, 1.5]
normal = [0.0, -1.0, 0.0]
size = [8.0, 4.0]
albedo = 0.85

[[trajectories]]
name = "head"
loop = false
keyframes = [
  { t = 0.0, position = [0.0, 0.5, 1.6] },
  { t = 6.0, position = [0.0, 0.5, 1.6] },
  { t = 7.0, position = [0.45, 0.7, 1.45] },
]

[viewer]
trajectory = "head"

[[trackers]]
name = "head_tracker"
noise_sigma_m = 0.0005
rate_hz = 60.0
trajectory = "head"
)";

Vec3 vec(const json& p) {
  return Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
}

TEST(SimMeshContent, DrawingFollowsTheTrackedViewerAndNotItsNoise) {
  const Vec3 A(0.0, 0.5, 1.6), B(0.45, 0.7, 1.45);
  constexpr double kThreshold = 0.005;  // [content] viewer_threshold_m (the default)
  TempDir dir;
  writeContent(dir, "cube.obj", kCubeObj);
  dir.write("follow.toml", kFollowScene);
  dir.write("procamd.toml", "[sim]\nscene = \"" + dir.file("follow.toml") +
                                "\"\n[content]\nviewer_threshold_m = 0.005\n");
  DaemonProcess d(dir, DaemonProcess::Launch{{"--config", dir.file("procamd.toml"), "--rig",
                                              truthRigFile(dir, dir.file("follow.toml"))},
                                             {},
                                             -1,
                                             true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "off"}}))["pattern"], "off");
  ASSERT_TRUE(eventually([&] { return (*c.call({{"cmd", "status"}}))["viewer"].is_object(); }));
  auto load =
      c.call({{"cmd", "content"}, {"action", "load"}, {"path", contentFile(dir, "cube.obj")}}, 30s);
  ASSERT_TRUE(load);
  ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
  const json viewer = (*load)["content"]["mesh"]["viewer"];
  EXPECT_EQ(viewer["source"], "tracker");
  EXPECT_EQ(viewer["tracker"], "head_tracker");
  const Vec3 placed_for = vec(viewer["position"]);
  EXPECT_LT((placed_for - A).norm(), 0.004);  // 8 sigma of the noise
  EXPECT_EQ((*load)["content"]["mesh"]["view_updates"], 0);

  // Standing still: the noise stays below the threshold, so nothing is drawn again.
  json status;
  ASSERT_TRUE(eventually([&] {
    status = *c.call({{"cmd", "status"}});
    return !status["outputs"]["shown"].empty() &&
           status["outputs"]["shown"][0]["source"] == "content";
  }));
  const auto frames_still = status["outputs"]["frames"].get<uint64_t>();
  std::this_thread::sleep_for(1s);
  status = *c.call({{"cmd", "status"}});
  ASSERT_LT((vec(status["viewer"]["position"]) - A).norm(), 0.004)
      << "the viewer started walking before the still check ended";
  EXPECT_EQ(status["content"]["mesh"]["view_updates"], 0) << status["content"].dump();
  EXPECT_EQ(status["outputs"]["frames"].get<uint64_t>(), frames_still);

  // Walking to B: the drawing follows, the last one within the threshold of B.
  json content;
  ASSERT_TRUE(eventually(
      [&] {
        content = (*c.call({{"cmd", "content"}}))["content"];
        return (vec(content["mesh"]["viewer"]["position"]) - B).norm() < kThreshold + 0.004;
      },
      15s))
      << content.dump();
  std::this_thread::sleep_for(500ms);  // the last update near B has been shown
  status = *c.call({{"cmd", "status"}});
  const auto updates = status["content"]["mesh"]["view_updates"].get<uint64_t>();
  const auto frames_at_b = status["outputs"]["frames"].get<uint64_t>();
  // The 0.52 m walk takes 1 s: at most one update per 60 Hz tracker sample (each moves
  // 8.6 mm, above the threshold; the output refresh allows as many), plus one on arrival.
  EXPECT_GE(updates, 2u);
  EXPECT_LE(updates, 62u);
  const Vec3 eye = vec(status["content"]["mesh"]["viewer"]["position"]);
  const json shown = status["outputs"]["shown"][0];
  std::this_thread::sleep_for(1s);
  status = *c.call({{"cmd", "status"}});
  EXPECT_EQ(status["content"]["mesh"]["view_updates"].get<uint64_t>(), updates);
  EXPECT_EQ(status["outputs"]["frames"].get<uint64_t>(), frames_at_b);

  // The frame shown: the cube where it was placed (for the load-time viewer), seen from
  // the viewer position reported for this frame.
  auto scene = sim::resolveScene(dir.file("follow.toml"));
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);  // by value: keep it while `proj` is used
  const geom::CameraModel& proj = state.projector("proj")->model;
  auto cube = content::loadMeshContent(contentFile(dir, "cube.obj"));
  ASSERT_TRUE(cube);
  content::PlanarView view;
  view.projector = proj.projectionMatrix();
  view.size = {proj.width, proj.height};
  view.plane_point = Vec3(0, 3, 1.5);
  view.plane_normal = Vec3(0, -1, 0);
  view.eye = placed_for;
  auto placed = content::placeMeshContent(*cube, view);
  ASSERT_TRUE(placed) << placed.error().message;
  const Expected now = rayCast(*placed, view.projector, view.size, eye);
  const Expected stale = rayCast(*placed, view.projector, view.size, placed_for);
  const double lit = shown["lit_fraction"].get<double>(), mean = shown["mean_rgb"][0].get<double>();
  std::printf(
      "followed viewer: %llu view updates; lit %.5f (ray cast %.5f, for the load-time viewer "
      "%.5f), mean grey %.3f (ray cast %.3f, load-time %.3f), edge band %.5f\n",
      static_cast<unsigned long long>(updates), lit, now.lit, stale.lit, mean, now.mean, stale.mean,
      now.boundary);
  ASSERT_GT(now.lit, 0.01);
  EXPECT_NEAR(lit, now.lit, now.boundary);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(shown["mean_rgb"][k].get<double>(), now.mean, 255 * now.boundary + 0.5) << k;
  }
  // The move is large enough that the drawing for the load-time viewer would fail.
  EXPECT_TRUE(std::abs(stale.lit - now.lit) > 2 * now.boundary ||
              std::abs(stale.mean - now.mean) > 2 * (255 * now.boundary + 0.5))
      << "lit " << stale.lit << " vs " << now.lit << ", mean " << stale.mean << " vs " << now.mean;
}

}  // namespace
}  // namespace procam::itest
