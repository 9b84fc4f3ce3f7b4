// Shader lamps in procamd, end to end on the virtual rig over the socket: object_box's
// two projectors and cameras handed over as a known rig (its TRUE projectors, with the
// brightness a camera measures), the box's model — in its own frame, turned and shifted —
// registered to the rig from its eight corners picked with 1 mm of error (`object place`,
// [Raskar02] eq. 4.2), then `content load` of the model with a texture: every output
// shows its radiance-corrected, feathered frame (§5.2.4-5.2.5), and the colour camera
// beside the viewer sees the texture on the box. What it sees is judged against the
// texture the box should show, with the simulator's own geometry.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>
#include <regex>
#include <sstream>
#include <thread>

#include "core/units.hpp"
#include "daemon_harness.hpp"
#include "object_box_daemon.hpp"
#include "object_meshes.hpp"
#include "rig/rig_model.hpp"
#include "shader_lamps/appearance.hpp"
#include "shader_lamps/object_model.hpp"
#include "shader_lamps/rig_lamps.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "true_brightness.hpp"
#include "wave_texture.hpp"

namespace procam::itest {
namespace {

using namespace std::chrono_literals;

// object_box's TRUE rig with measured-like photometry as rig.json, the model and the
// texture in the content root.
void writeBoxRig(const TempDir& dir, const sim::Scene& scene, const sim::SceneState& state) {
  auto rig = sim::truthRig(scene, 0.0);
  ASSERT_TRUE(rig) << rig.error().message;
  addTruePhotometry(scene, state, *rig);
  rig->surface = {};
  dir.write("rig.json", rig::rigToJson(*rig).dump(2) + "\n");
  const ObjectMesh box = boxMesh(kBoxCentre, kBoxSize, 0.01);
  writeContent(dir, "box_model.ply", texturedPly(box, modelRotation(), kBoxCentre));
  ASSERT_TRUE(cv::imwrite(contentFile(dir, "look.png"), waveTextureSrgb()));
}

TEST(ShaderLamp, DaemonPaintsAModelPlacedFromPickedCorners) {
  TempDir dir;
  auto scene = sim::resolveScene("object_box");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  // A known rig, asked for explicitly, with each projector's brightness as a camera
  // measures it: the rendering is judged here, not a calibration.
  writeBoxRig(dir, *scene, state);
  DaemonProcess d(dir, DaemonProcess::Launch{
                           {"--sim", "object_box", "--rig", dir.file("rig.json")}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_TRUE(c.ok());

  const Mat3 R = modelRotation();
  writeContent(dir, "cube.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n");

  // Bad input first: each answered, nothing changed.
  auto bad = c.call(
      {{"cmd", "content"}, {"action", "load"}, {"path", "box_model.ply"}, {"texture", "look.png"}});
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "bad-argument") << bad->dump();  // no object in the rig yet
  const json points = cornerPoints(0.001);                   // 1 mm of picking error per axis
  json three = json::array({points[0], points[1], points[2]});
  bad = c.call(
      {{"cmd", "object"}, {"action", "place"}, {"model", "box_model.ply"}, {"points", three}});
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "bad-argument") << bad->dump();
  json mispicked = points;
  mispicked[3]["world"][2] = mispicked[3]["world"][2].get<double>() + 0.05;
  bad = c.call(
      {{"cmd", "object"}, {"action", "place"}, {"model", "box_model.ply"}, {"points", mispicked}},
      30s);
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "bad-argument") << bad->dump();
  // Each point's residual is listed ("i: r mm"); the mis-picked one's is the largest.
  {
    const std::string message = (*bad)["message"].get<std::string>();
    const std::regex residual(R"((\d+): ([0-9.]+) mm)");
    int largest = -1;
    double most = -1;
    for (auto it = std::sregex_iterator(message.begin(), message.end(), residual);
         it != std::sregex_iterator(); ++it) {
      if (std::stod((*it)[2]) > most) {
        most = std::stod((*it)[2]);
        largest = std::stoi((*it)[1]);
      }
    }
    EXPECT_EQ(largest, 3) << message;
  }
  bad = c.call({{"cmd", "object"}, {"action", "place"}, {"model", "../x.ply"}, {"points", points}});
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "forbidden") << bad->dump();
  auto got = c.call({{"cmd", "object"}});
  ASSERT_TRUE(got);
  EXPECT_TRUE((*got)["object"].is_null()) << got->dump();

  // Registered from the eight corners, through procamctl as an installer does.
  dir.write("corners.json", json{{"points", points}}.dump());
  int status = -1;
  const json place =
      ctlJson(d, {"object", "place", "box_model.ply", dir.file("corners.json")}, status);
  ASSERT_EQ(status, 0) << place.dump();
  const json* placed = &place;
  ASSERT_EQ((*placed)["class"], "OBJECT") << placed->dump();
  const double fit_mm = 1000 * (*placed)["fit_rms_m"].get<double>();
  Mat3 R_fit;
  for (int i = 0; i < 9; ++i) R_fit(i / 3, i % 3) = (*placed)["object"]["R"][i].get<double>();
  const double angle_deg = radToDeg(Eigen::AngleAxisd(R_fit * R.transpose()).angle());
  Vec3 t_fit((*placed)["object"]["t"][0].get<double>(), (*placed)["object"]["t"][1].get<double>(),
             (*placed)["object"]["t"][2].get<double>());
  const double shift_mm = 1000 * (t_fit - kBoxCentre).norm();
  std::printf("object place: %.2f mm RMS over 8 corners, %.3f deg and %.2f mm off the truth\n",
              fit_mm, angle_deg, shift_mm);
  // 1 mm per axis over 8 points, 6 degrees of freedom fitted: about 1.5 mm RMS expected.
  EXPECT_LT(fit_mm, 3.0);
  EXPECT_LT(angle_deg, 0.5);
  EXPECT_LT(shift_mm, 2.0);
  EXPECT_TRUE((*placed)["model"]["textured"].get<bool>());
  EXPECT_TRUE(std::filesystem::exists(dir.file("state/object-model.ply")));

  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "off"}}))["pattern"], "off");
  const cv::Mat dark = meanSnapshot(c, "cam_colour", kShots);

  // Another mesh is not the object's model: refused, nothing shown changes.
  bad = c.call({{"cmd", "content"}, {"action", "load"}, {"path", "cube.obj"}}, 30s);
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "bad-argument") << bad->dump();
  bad = c.call({{"cmd", "content"}, {"action", "load"}, {"path", "box_model.ply"}, {"specular", 3}},
               30s);
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "bad-argument") << bad->dump();
  EXPECT_TRUE((*c.call({{"cmd", "content"}}))["content"].is_null());

  const json loaded_reply = ctlJson(d,
                                    {"--timeout", std::to_string(120 * kSlowdown), "content",
                                     "load", "box_model.ply", "texture=look.png"},
                                    status);
  ASSERT_EQ(status, 0) << loaded_reply.dump();
  const json* loaded = &loaded_reply;
  ASSERT_EQ((*loaded)["class"], "CONTENT") << loaded->dump();
  const json& content = (*loaded)["content"];
  EXPECT_EQ(content["display"]["surface"], "object");
  EXPECT_EQ(content["display"]["units"], "camera 'truth' units");
  EXPECT_EQ(content["display"]["coverage"]["unlit_m2"].get<double>(), 0.0);
  EXPECT_GT(content["display"]["coverage"]["lit_m2"].get<double>(), 0.1);
  ASSERT_EQ(content["projectors"].size(), 2u) << content.dump();
  for (const auto& p : content["projectors"]) {
    EXPECT_EQ(p["shown_by"], p["name"]);
    EXPECT_EQ(p["gain_source"], "brightness map");
    EXPECT_GT(p["lit_pixels"].get<long>(), 10000);
  }
  // Both outputs draw it by the shader-lamps path, as choosePath chose.
  std::map<std::string, json> shown;  // output -> its mean RGB
  const auto drawnByLamps = [&] {
    auto s = c.call({{"cmd", "status"}});
    if (!s || (*s)["outputs"]["shown"].size() != 2) return false;
    for (const auto& o : (*s)["outputs"]["shown"]) {
      if (o["path"] != "shader-lamps" || o["chosen_path"] != "shader-lamps" ||
          o["source"] != "content" || !(o["lit_fraction"].get<double>() > 0.02))
        return false;
      shown[o["name"]] = o["mean_rgb"];
    }
    return true;
  };
  ASSERT_TRUE(eventually(drawnByLamps, 20s * kSlowdown)) << c.call({{"cmd", "status"}})->dump();
  const std::map<std::string, json> from_model = shown;

  const cv::Mat lit = meanSnapshot(c, "cam_colour", kShots);
  cv::Mat texture_bgr = waveTextureSrgb();
  const cv::Mat texture = lamps::linearTexture(texture_bgr);
  const Seen seen = judge(*scene, state, lit, dark, texture);
  expectPaintedBox(seen, "procamd object content");

  // The image alone is the placed model's texture: the same frames.
  bad = c.call(
      {{"cmd", "content"}, {"action", "load"}, {"path", "look.png"}, {"texture", "look.png"}});
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "bad-argument") << bad->dump();
  auto image =
      c.call({{"cmd", "content"}, {"action", "load"}, {"path", "look.png"}}, 120s * kSlowdown);
  ASSERT_TRUE(image);
  ASSERT_EQ((*image)["class"], "CONTENT") << image->dump();
  EXPECT_EQ((*image)["content"]["path"], "look.png");
  EXPECT_EQ((*image)["content"]["look"]["texture"], "look.png");
  EXPECT_TRUE((*image)["content"]["object"]["textured"].get<bool>());
  EXPECT_TRUE(eventually(
      [&] {
        shown.clear();
        if (!drawnByLamps()) return false;
        for (const auto& [name, rgb] : from_model)
          for (int k = 0; k < 3; ++k)
            if (std::abs(shown[name][k].get<double>() - rgb[k].get<double>()) > 1e-6) return false;
        return true;
      },
      20s * kSlowdown))
      << c.call({{"cmd", "status"}})->dump();

  // The object cleared from the rig: the look goes with it, the outputs go dark.
  auto cleared = c.call({{"cmd", "object"}, {"action", "clear"}}, 10s);
  ASSERT_TRUE(cleared);
  EXPECT_EQ((*cleared)["class"], "OBJECT") << cleared->dump();
  EXPECT_TRUE(eventually(
      [&] {
        if (!(*c.call({{"cmd", "content"}}))["content"].is_null()) return false;
        const json status = *c.call({{"cmd", "status"}});
        for (const auto& o : status["outputs"]["shown"])
          if (o["lit_fraction"].get<double>() != 0 || o["source"] != "none") return false;
        return true;
      },
      10s * kSlowdown))
      << c.call({{"cmd", "status"}})->dump();
}

// A projector whose output is unplugged is off: the others' weights are recomputed and
// the part of the box only it reaches is reported unlit; when it is back, the look is
// painted again with it.
TEST(ShaderLamp, DaemonReportsWhatAnUnpluggedProjectorLeftUnlit) {
  TempDir dir;
  auto scene = sim::resolveScene("object_box");
  ASSERT_TRUE(scene) << scene.error().message;
  writeBoxRig(dir, *scene, scene->at(0));
  // proj_right's output unplugged from `gone` to `back` seconds after the start.
  const int gone = 4 * kSlowdown, back = gone + 8 * kSlowdown;
  const auto t0 = std::chrono::steady_clock::now();
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "object_box", "--rig", dir.file("rig.json")},
                                             {"PROCAM_SIM_UNPLUG=proj_right@" +
                                              std::to_string(gone) + "-" + std::to_string(back)},
                                             -1,
                                             true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_TRUE(c.ok());
  auto placed = placeBox(c, 0);
  ASSERT_TRUE(placed) << d.log();
  ASSERT_EQ((*placed)["class"], "OBJECT") << placed->dump();
  auto loaded = c.call(
      {{"cmd", "content"}, {"action", "load"}, {"path", "box_model.ply"}, {"texture", "look.png"}},
      60s * kSlowdown);
  ASSERT_TRUE(loaded);
  ASSERT_EQ((*loaded)["class"], "CONTENT") << loaded->dump();
  // Painted while both were plugged in (a slow start may already be past `gone`: then
  // the both-projector figures come from their return below).
  std::optional<double> area_first;
  if (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(gone) - 500ms) {
    const json both = (*loaded)["content"];
    EXPECT_EQ(both["display"]["coverage"]["unlit_m2"].get<double>(), 0.0);
    area_first = both["display"]["coverage"]["lit_m2"].get<double>();
  }

  // Unplugged: found at its next frame (a pattern shown and taken back draws two);
  // painted without it.
  std::this_thread::sleep_until(t0 + std::chrono::seconds(gone) + 500ms);
  json one;
  EXPECT_TRUE(eventually(
      [&] {
        c.call({{"cmd", "pattern"}, {"name", "white"}}, 10s);
        c.call({{"cmd", "pattern"}, {"name", "off"}}, 10s);
        one = (*c.call({{"cmd", "content"}}))["content"];
        return one.is_object() && one["display"]["coverage"]["unlit_m2"].get<double>() > 0;
      },
      std::chrono::seconds(back - gone - 1)))
      << one.dump() << d.log();
  std::map<std::string, json> by_name;
  for (const auto& p : one["projectors"]) by_name[p["name"]] = p;
  ASSERT_EQ(by_name.size(), 2u) << one.dump();
  EXPECT_FALSE(by_name["proj_right"]["on"].get<bool>());
  EXPECT_TRUE(by_name["proj_right"]["shown_by"].is_null());
  EXPECT_EQ(by_name["proj"]["shown_by"], "proj");
  const double unlit = one["display"]["coverage"]["unlit_m2"].get<double>();
  const double lit = one["display"]["coverage"]["lit_m2"].get<double>();
  // The box's top far left corner and most of its right side are the right projector's
  // alone (tests/scenes/object_box.toml).
  EXPECT_GT(unlit, 0.001);

  // Back: painted again with both.
  json two;
  EXPECT_TRUE(eventually(
      [&] {
        two = (*c.call({{"cmd", "content"}}))["content"];
        return two.is_object() && two["display"]["coverage"]["unlit_m2"].get<double>() == 0.0;
      },
      std::chrono::seconds(back - gone + 20 * kSlowdown)))
      << two.dump() << d.log();
  const double area = two["display"]["coverage"]["lit_m2"].get<double>();
  std::printf(
      "proj_right unplugged: %.4f m2 of the box lit, %.4f m2 unlit (%zu faces), "
      "%.4f m2 lit with both\n",
      lit, unlit, one["display"]["coverage"]["unlit_faces"].get<std::size_t>(), area);
  // What is lit and what is not make the whole.
  EXPECT_NEAR(lit + unlit, area, 1e-9);
  if (area_first) {
    EXPECT_NEAR(*area_first, area, 1e-9);
  }
  for (const auto& p : two["projectors"]) EXPECT_EQ(p["shown_by"], p["name"]) << two.dump();
}

// A glossy look on object_vase for its head-tracked viewer: the highlight is shaded for
// the eye the tracker gives and follows it as the viewer strolls ([Raskar02] §5.2.3); only
// the view-dependent part is shaded again, views and weights stay.
TEST(ShaderLamp, DaemonHighlightFollowsTheTrackedViewer) {
  TempDir dir;
  auto scene = sim::resolveScene("object_vase");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  // The rig names the vase's model (in world coordinates) as its object; the model lies
  // beside rig.json and comes into the state directory with it.
  const ObjectMesh vase =
      vaseMesh(Vec3(0.0, 1.5, 0.85), 0.1, Vec3(0.0, 1.5, 0.93), 0.045, 0.1, 128);
  const std::string model = texturedPly(vase);
  auto rig = sim::truthRig(*scene, 0.0);
  ASSERT_TRUE(rig) << rig.error().message;
  addTruePhotometry(*scene, state, *rig);
  rig->surface = {};
  rig->viewer = {};
  rig::RigObject object;
  object.mesh = "vase-model.ply";
  object.placed = {"the vase's model, in world coordinates", ""};
  rig->surface.object = object;
  dir.write("rig.json", rig::rigToJson(*rig).dump(2) + "\n");
  dir.write("vase-model.ply", model);
  writeContent(dir, "vase.ply", model);
  ASSERT_TRUE(cv::imwrite(contentFile(dir, "look.png"), waveTextureSrgb()));
  DaemonProcess d(dir, DaemonProcess::Launch{
                           {"--sim", "object_vase", "--rig", dir.file("rig.json")}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  EXPECT_TRUE(std::filesystem::exists(dir.file("state/vase-model.ply")));
  Connection c(d.socketPath());
  ASSERT_TRUE(c.ok());
  auto got = c.call({{"cmd", "object"}});
  ASSERT_TRUE(got);
  EXPECT_EQ((*got)["object"]["mesh"], "vase-model.ply") << got->dump();
  ASSERT_TRUE(eventually([&] { return (*c.call({{"cmd", "status"}}))["viewer"].is_object(); }));
  auto loaded = c.call({{"cmd", "content"},
                        {"action", "load"},
                        {"path", "vase.ply"},
                        {"texture", "look.png"},
                        {"specular", 0.5},
                        {"shininess", 40}},
                       60s * kSlowdown);
  ASSERT_TRUE(loaded);
  ASSERT_EQ((*loaded)["class"], "CONTENT") << loaded->dump();
  const json& display = (*loaded)["content"]["display"];
  EXPECT_EQ(display["viewer"]["source"], "tracker") << display.dump();
  EXPECT_EQ(display["viewer"]["tracker"], "head");
  EXPECT_EQ((*loaded)["content"]["projectors"].size(), 3u);
  EXPECT_EQ(display["coverage"]["unlit_m2"].get<double>(), 0.0);

  // The viewer strolls 0.4 m to the right in 3 s: the look is shaded again for where the
  // tracker puts them, each time they moved more than [content] viewer_threshold_m.
  json content, status;
  double off_m = 1;
  ASSERT_TRUE(eventually(
      [&] {
        content = (*c.call({{"cmd", "content"}}))["content"];
        status = *c.call({{"cmd", "status"}});
        if (content["display"]["view_updates"].get<int>() < 5) return false;
        const json& shaded = content["display"]["viewer"]["position"];
        const json& tracked = status["viewer"]["position"];
        off_m = std::hypot(shaded[0].get<double>() - tracked[0].get<double>(),
                           shaded[1].get<double>() - tracked[1].get<double>(),
                           shaded[2].get<double>() - tracked[2].get<double>());
        return true;
      },
      20s * kSlowdown))
      << content.dump();
  const json& shaded = content["display"]["viewer"]["position"];
  const Vec3 start = state.viewer.pose.center();
  const double moved =
      std::hypot(shaded[0].get<double>() - start.x(), shaded[1].get<double>() - start.y(),
                 shaded[2].get<double>() - start.z());
  std::printf(
      "highlight shaded %d times for the moving viewer, the last for an eye %.1f mm "
      "from the tracker's latest and %.0f mm from where they started\n",
      content["display"]["view_updates"].get<int>(), 1000 * off_m, 1000 * moved);
  // At 0.13 m/s and a repaint per frame or two, the eye shaded lags the tracker by a
  // frame's walk and the time the shading takes (tens of milliseconds, kSlowdown times
  // that under a sanitizer): a few centimetres.
  EXPECT_LT(off_m, 0.05 * kSlowdown);
  EXPECT_GT(moved, 0.01);
  for (const auto& o : status["outputs"]["shown"]) EXPECT_EQ(o["path"], "shader-lamps");
}

// A rig that names an object's model found neither beside it nor in the state directory
// is refused at start, naming the file: not a rig that fails at the first content load.
TEST(ShaderLamp, DaemonRefusesARigWhoseObjectModelIsMissing) {
  TempDir dir;
  auto scene = sim::resolveScene("object_box");
  ASSERT_TRUE(scene) << scene.error().message;
  auto rig = sim::truthRig(*scene, 0.0);
  ASSERT_TRUE(rig) << rig.error().message;
  rig::RigObject object;
  object.mesh = "missing-model.ply";
  rig->surface.object = object;
  dir.write("rig.json", rig::rigToJson(*rig).dump(2) + "\n");
  DaemonProcess d(dir, DaemonProcess::Launch{
                           {"--sim", "object_box", "--rig", dir.file("rig.json")}, {}, -1, false});
  const auto status = d.wait(10s * kSlowdown);
  ASSERT_TRUE(status) << d.log();
  EXPECT_NE(*status, 0);
  EXPECT_NE(d.log().find("missing-model.ply"), std::string::npos) << d.log();
}

}  // namespace
}  // namespace procam::itest
