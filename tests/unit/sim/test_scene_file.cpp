// Scene files: typed errors that name the key and line; every shipped scene loads
// by name (embedded copy) and by path, and its devices see something lit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/units.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_json.hpp"
#include "sim_test_util.hpp"

namespace procam::sim {
namespace {

using testing::flatWallScene;

// Replaces the first occurrence of `from` in the flat-wall scene.
std::string edited(const std::string& from, const std::string& to) {
  std::string text = flatWallScene("");
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

Error parseError(const std::string& text) {
  auto scene = Scene::parse(text, "bad.toml", {});
  EXPECT_FALSE(scene) << "accepted a bad scene";
  return scene ? Error{ErrorCode::kInvalidInput, ""} : scene.error();
}

TEST(SimSceneFile, FlatWallSceneParses) {
  auto scene = Scene::parse(flatWallScene(""), "flat.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->projectors().size(), 1u);
  EXPECT_EQ(scene->cameras().size(), 1u);
}

TEST(SimSceneFile, UnknownKeyIsNamedWithItsLine) {
  const std::string text = edited("gamma = ", "gama = ");
  const auto line = 1 + std::count(text.begin(), text.begin() + text.find("gama"), '\n');
  const Error e = parseError(text);
  EXPECT_EQ(e.code, ErrorCode::kParse);
  EXPECT_NE(e.message.find("projectors[0].gama"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("bad.toml:" + std::to_string(line) + ":"), std::string::npos)
      << e.message;
}

TEST(SimSceneFile, BadValuesNameTheKey) {
  struct Case {
    std::string from, to, key;
  };
  const Case cases[] = {
      {"brightness = 3.0", "brightness = -1.0", "projectors[0].brightness"},
      {"brightness = 3.0", "brightness = \"bright\"", "projectors[0].brightness"},
      {"resolution = [320, 240]", "resolution = [320]", "projectors[0].resolution"},
      {"fx = 300.0,", "fx = 0.0,", "projectors[0].intrinsics.fx"},
      {"yaw_deg = 0.0", "yaw_deg = 0.0, look_at = [0.0, 1.0, 1.0]", "projectors[0].pose"},
      {"albedo = 0.7", "albedo = 1.5", "surfaces[0].albedo"},
      {"type = \"plane\"", "type = \"torus\"", "surfaces[0].type"},
      {"albedo = 0.7",
       "albedo = 0.7\nboard = { spec = \"poster:4x3:0.1\", center = [0.0, 2.0, 1.0] }",
       "surfaces[0].board"},
      {"albedo = 0.7",
       "albedo = 0.7\nboard = { spec = \"checker:4x3:0.1\", center = [0.0, 2.0, 1.0], px_per_m = "
       "1e6 }",
       "surfaces[0].board.px_per_m"},
      {"albedo = 0.7",
       "albedo = 0.7\nboard = { spec = \"checker:40x30:1.0\", center = [0.0, 2.0, 1.0], px_per_m = "
       "1000 }",
       "surfaces[0].board"},
      {"albedo = 0.7", "albedo = 0.7\nboard = { spec = \"checker:4x3:0.1\" }",
       "surfaces[0].board.center"},
      {"normal = [0.0, -1.0, 0.0]", "normal = [0.0, 0.0, 0.0]", "surfaces[0].normal"},
      {"ambient = 0.05", "ambient = 0.05\nshadows = true", "scene.shadows"},
      {"name = \"cam\"", "name = \"cam\"\nbit_depth = 20", "cameras[0].bit_depth"},
      {"name = \"cam\"", "name = \"cam\"\nsupersamples = 5", "cameras[0].supersamples"},
      {"name = \"cam\"", "name = \"cam\"\nchannels = 2", "cameras[0].channels"},
      {"name = \"cam\"", "name = \"cam\"\ndistortion = { k4 = 0.1 }", "cameras[0].distortion.k4"},
      {"pose = { position = [0.2", "attached_to = \"nobody\"\noffset = { position = [0.2",
       "cameras[0].attached_to"},
      {"[[surfaces]]", "[[cameras]]\nname = \"cam\"\n[[surfaces]]", "cameras[1].name"},
      {"[[surfaces]]", "[[tilt_sensors]]\nname = \"t\"\nattached_to = \"projx\"\n[[surfaces]]",
       "tilt_sensors[0].attached_to"},
      {"[[surfaces]]",
       "[[tilt_sensors]]\nname = \"t\"\nattached_to = \"proj\"\nmount_matrix = [[1.0, 0.0, 0.0], "
       "[0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]\n[[surfaces]]",
       "tilt_sensors[0].mount_matrix"},
      {"[[surfaces]]",
       "[[tilt_sensors]]\nname = \"t\"\nattached_to = \"proj\"\nunits = \"mg\"\n"
       "[[surfaces]]",
       "tilt_sensors[0].units"},
      {"pose = { position = [0.0, 0.0, 1.0], yaw_deg = 0.0 }", "trajectory = \"nowhere\"",
       "projectors[0].trajectory"},
      {"[[surfaces]]",
       "[[trajectories]]\nname = \"t\"\nkeyframes = [{ t = 1.0, position = [0.0, "
       "0.0, 0.0] }, { t = 0.5, position = [0.0, 0.0, 0.0] }]\n[[surfaces]]",
       "trajectories[0].keyframes[1].t"},
  };
  for (const Case& c : cases) {
    const Error e = parseError(edited(c.from, c.to));
    EXPECT_EQ(e.code, ErrorCode::kParse) << c.to;
    EXPECT_NE(e.message.find(c.key), std::string::npos) << "'" << c.to << "' -> " << e.message;
    EXPECT_NE(e.message.find("bad.toml:"), std::string::npos) << e.message;
  }
}

TEST(SimSceneFile, TomlSyntaxErrorsCarryTheLine) {
  const Error e = parseError("[scene]\nambient = 0.1\nname = \"unterminated\n");
  EXPECT_EQ(e.code, ErrorCode::kParse);
  EXPECT_NE(e.message.find("bad.toml:3"), std::string::npos) << e.message;
}

TEST(SimSceneFile, UnknownSceneNameListsTheBuiltins) {
  auto scene = resolveScene("no_such_scene");
  ASSERT_FALSE(scene);
  EXPECT_EQ(scene.error().code, ErrorCode::kNotFound);
  EXPECT_NE(scene.error().message.find("wall_oblique"), std::string::npos);
}

TEST(SimSceneFile, EveryShippedSceneLoadsByNameAndByPath) {
  const auto names = builtinSceneNames();
  for (const char* name : testing::kShippedScenes) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    auto embedded = resolveScene(name);
    ASSERT_TRUE(embedded) << name << ": " << embedded.error().message;
    auto from_file = resolveScene(testing::scenePath(name).string());
    ASSERT_TRUE(from_file) << name << ": " << from_file.error().message;
    EXPECT_EQ(embedded->name(), name);
    // The embedded copy is the file.
    EXPECT_EQ(truthJson(*embedded, embedded->at(0.5)), truthJson(*from_file, from_file->at(0.5)))
        << name;
  }
}

// Every camera of every shipped scene sees a good part of some projector's image
// (centre rays on an 8-pixel grid), so the scenes are usable for calibration.
TEST(SimSceneFile, ShippedCamerasSeeProjectedLight) {
  for (const char* name : testing::kShippedScenes) {
    auto scene = resolveScene(name);
    ASSERT_TRUE(scene);
    const SceneState state = scene->at(0.0);
    auto r = Renderer::create(*scene, state, {});
    ASSERT_TRUE(r);
    for (const auto& cam : state.cameras) {
      int lit = 0, total = 0;
      for (int y = 4; y < cam.model.height; y += 8) {
        for (int x = 4; x < cam.model.width; x += 8) {
          const PixelTruth t = r->truthAt(cam.model, Vec2(x, y));
          bool any = false;
          for (const auto& l : t.projectors) any |= l.lit;
          lit += any;
          ++total;
        }
      }
      EXPECT_GT(lit, 0.2 * total) << name << "/" << cam.spec.name;
    }
  }
}

// The per-pixel truth maps agree with single-pixel queries.
TEST(SimSceneFile, TruthMapsMatchPixelQueries) {
  auto scene = resolveScene("object_box");
  ASSERT_TRUE(scene);
  const SceneState state = scene->at(0.0);
  auto r = Renderer::create(*scene, state, {});
  ASSERT_TRUE(r);
  auto maps = r->cameraTruth("cam");
  ASSERT_TRUE(maps);
  const auto& cam = state.cameras.at(0).model;
  for (int y = 3; y < cam.height; y += 37) {
    for (int x = 5; x < cam.width; x += 41) {
      const PixelTruth t = r->truthAt(cam, Vec2(x, y));
      EXPECT_EQ(maps->surface.at<int>(y, x), t.surface);
      if (!t.hit) continue;
      const cv::Vec3d p = maps->point.at<cv::Vec3d>(y, x);
      EXPECT_TRUE(Vec3(p[0], p[1], p[2]).isApprox(t.point));
      EXPECT_EQ(maps->lit[0].at<std::uint8_t>(y, x) != 0, t.projectors[0].lit);
      const cv::Vec2f u = maps->projector_pixel[0].at<cv::Vec2f>(y, x);
      EXPECT_NEAR(u[0], t.projectors[0].pixel.x(), 1e-3);
      EXPECT_NEAR(u[1], t.projectors[0].pixel.y(), 1e-3);
      // The pixel's world point projects back onto the pixel.
      const auto back = cam.project(t.point);
      ASSERT_TRUE(back);
      EXPECT_NEAR(back->x(), x, 1e-6);
      EXPECT_NEAR(back->y(), y, 1e-6);
    }
  }
}

TEST(SimSceneFile, ShippedScenesMatchTheIssue) {
  auto wall = resolveScene("wall_oblique");
  ASSERT_TRUE(wall);
  const SceneState ws = wall->at(0);
  ASSERT_EQ(ws.projectors.size(), 1u);
  EXPECT_EQ(ws.projectors[0].model.width, 1920);
  EXPECT_EQ(ws.projectors[0].model.height, 1080);
  // Optical axis against the wall normal (-Y toward the wall is +Y): turned 30 deg to
  // the left (towards -X: yaw -30), tilted up by 15 deg.
  const Vec3 axis = ws.projectors[0].model.pose.R.row(2).transpose();
  EXPECT_NEAR(radToDeg(std::atan2(axis.x(), axis.y())), -30.0, 1e-9);
  EXPECT_NEAR(radToDeg(std::asin(axis.z())), 15.0, 1e-9);
  ASSERT_EQ(ws.cameras.size(), 1u);
  EXPECT_EQ(ws.cameras[0].model.width, 1280);
  EXPECT_EQ(ws.cameras[0].model.height, 960);

  // The planar multi-projector wall: 2x2 of 1280x800, unmatched responses, two cameras.
  auto tiled = resolveScene("tiled_wall");
  ASSERT_TRUE(tiled);
  ASSERT_EQ(tiled->projectors().size(), 4u);
  EXPECT_EQ(tiled->cameras().size(), 2u);
  double gamma_lo = 9, gamma_hi = 0, bright_lo = 1e9, bright_hi = 0;
  for (const auto& p : tiled->projectors()) {
    EXPECT_EQ(p.width, 1280);
    EXPECT_EQ(p.height, 800);
    gamma_lo = std::min(gamma_lo, p.gamma);
    gamma_hi = std::max(gamma_hi, p.gamma);
    bright_lo = std::min(bright_lo, p.brightness);
    bright_hi = std::max(bright_hi, p.brightness);
  }
  EXPECT_EQ(gamma_lo, 2.0);
  EXPECT_EQ(gamma_hi, 2.6);
  EXPECT_LE(bright_hi / bright_lo, 1.2 / 0.8);
  EXPECT_GT(bright_hi / bright_lo, 1.2);

  auto corner = resolveScene("corner_stereo");
  ASSERT_TRUE(corner);
  EXPECT_EQ(corner->projectors().size(), 1u);
  EXPECT_EQ(corner->cameras().size(), 2u);

  auto hand = resolveScene("handheld");
  ASSERT_TRUE(hand);
  ASSERT_EQ(hand->tiltSensors().size(), 1u);
  EXPECT_EQ(hand->tiltSensors()[0].noise_density_ug, 400.0);
  EXPECT_EQ(hand->tiltSensors()[0].bias_mg.cwiseAbs(), Vec3::Constant(50.0));
  EXPECT_EQ(hand->cameras().at(0).placement.kind, Placement::Kind::kAttached);

  auto dome = resolveScene("dome3");
  ASSERT_TRUE(dome);
  EXPECT_EQ(dome->projectors().size(), 3u);
  EXPECT_EQ(dome->cameras().size(), 2u);  // route (a) triangulates the dome

  // The curved panoramic wall: three projectors, two cameras, a cylinder.
  auto cylinder = resolveScene("cylinder3");
  ASSERT_TRUE(cylinder) << cylinder.error().message;
  EXPECT_EQ(cylinder->projectors().size(), 3u);
  EXPECT_EQ(cylinder->cameras().size(), 2u);
  bool has_cylinder = false;
  for (const auto& s : cylinder->world().surfaces()) has_cylinder |= s.type == "cylinder";
  EXPECT_TRUE(has_cylinder);

  auto box = resolveScene("object_box");
  ASSERT_TRUE(box);
  bool has_box = false;
  for (const auto& s : box->world().surfaces()) has_box |= s.type == "box";
  EXPECT_TRUE(has_box);
}

}  // namespace
}  // namespace procam::sim
