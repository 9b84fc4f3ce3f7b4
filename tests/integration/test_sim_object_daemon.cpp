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
#include "object_meshes.hpp"
#include "rig/rig_model.hpp"
#include "shader_lamps/appearance.hpp"
#include "shader_lamps/object_model.hpp"
#include "shader_lamps/rig_lamps.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "true_brightness.hpp"
#include "truth_rig_file.hpp"
#include "wave_texture.hpp"

namespace procam::itest {
namespace {

using namespace std::chrono_literals;

const Vec3 kBoxCentre(0.1, 1.5, 0.875), kBoxSize(0.3, 0.2, 0.25);
constexpr double kCutoffDeg = 60;
// Snapshots averaged: the painted box is near 25 DN in this camera (its exposure is the
// scene's), 1 DN of read noise and shot noise to about 0.3 DN.
constexpr int kShots = 16;

double luma(const Vec3& rgb) {
  return 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
}

// world = kModelR · model + kBoxCentre: the model's own frame, as a modelling tool left it.
Mat3 modelRotation() {
  return (Eigen::AngleAxisd(degToRad(25.0), Vec3::UnitZ()) *
          Eigen::AngleAxisd(degToRad(10.0), Vec3::UnitX()))
      .toRotationMatrix();
}

// The mean of `n` snapshots of `camera`, linear camera units (BGR, float).
cv::Mat meanSnapshot(Connection& c, const std::string& camera, int n) {
  cv::Mat sum;
  for (int i = 0; i < n; ++i) {
    auto shot = c.call({{"cmd", "snapshot"}, {"camera", camera}}, 60s * kSlowdown);
    if (!shot || (*shot)["class"] != "SNAPSHOT") {
      ADD_FAILURE() << (shot ? shot->dump() : "no reply");
      return {};
    }
    cv::Mat img = cv::imread((*shot)["path"].get<std::string>(), cv::IMREAD_UNCHANGED), f;
    img.convertTo(f, CV_32FC3);
    if (sum.empty())
      sum = f;
    else
      sum += f;
  }
  return sum / n;
}

struct Seen {
  double mean_rel = 1;  // mean |ratio / median - 1| where a projector faces the box < 60°
  long judged = 0;
  double median_dn = 0;  // the seen luminance's median over the judged pixels
  double spill_px = 0;   // farthest brightened camera pixel off the box from its outline
  long spilled = 0;      // brightened pixels off the box farther than 2 camera pixels
};

// What the camera sees of the painted box (lit minus dark), against albedo · texture.
Seen judge(const sim::Scene& scene, const sim::SceneState& state, const cv::Mat& lit,
           const cv::Mat& dark, const cv::Mat& texture) {
  Seen out;
  const geom::CameraModel* cam = nullptr;
  for (const auto& c : state.cameras)
    if (c.spec.name == "cam_colour") cam = &c.model;
  auto renderer = sim::Renderer::create(scene, state, {});
  if (!cam || !renderer || lit.empty() || dark.empty()) {
    ADD_FAILURE() << "no camera, renderer or snapshot";
    return out;
  }
  const ObjectMesh box = boxMesh(kBoxCentre, kBoxSize, 0.01);
  auto model = lamps::ObjectModel::build(box.mesh, box.uv);
  EXPECT_TRUE(model);
  Vec3 albedo = Vec3::Ones();
  int box_id = -1;
  for (std::size_t s = 0; s < scene.world().surfaces().size(); ++s) {
    if (scene.world().surfaces()[s].name != "box") continue;
    box_id = static_cast<int>(s);
    const auto& a = scene.world().surfaces()[s].albedo_rgb;
    albedo = Vec3(a[0], a[1], a[2]);
  }
  const int W = cam->width, H = cam->height;
  cv::Mat group(H, W, CV_32SC1, cv::Scalar(-1)), on_box(H, W, CV_8UC1, cv::Scalar(0));
  cv::Mat ratio(H, W, CV_64FC1, cv::Scalar(0));
  const cv::Mat seen = lit - dark;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const sim::PixelTruth t = renderer->truthAt(*cam, Vec2(x, y));
      if (!t.hit || t.surface != box_id) continue;
      on_box.at<std::uint8_t>(y, x) = 255;
      bool facing = false;
      for (const auto& p : t.projectors)
        facing |= p.lit && p.cos_incidence >= std::cos(degToRad(kCutoffDeg));
      const auto ray = cam->backproject(Vec2(x, y));
      const auto s = ray ? model->intersect(*ray) : std::nullopt;
      if (!facing || !s) continue;
      group.at<int>(y, x) = boxSideOf(t.normal);
      const Vec3 want = albedo.cwiseProduct(lamps::textureAt(texture, s->texcoord));
      const cv::Vec3f bgr = seen.at<cv::Vec3f>(y, x);
      ratio.at<double>(y, x) = luma(Vec3(bgr[2], bgr[1], bgr[0])) / luma(want);
    }
  }
  // Judged two pixels in from any face edge, crease or cut-off (a pixel's light and the
  // camera's supersampling spread over about one pixel).
  std::vector<double> ratios;
  std::vector<cv::Point> where;
  for (int y = 2; y + 2 < H; ++y) {
    for (int x = 2; x + 2 < W; ++x) {
      const int g = group.at<int>(y, x);
      if (g < 0) continue;
      bool inner = true;
      for (int dy = -2; dy <= 2 && inner; ++dy)
        for (int dx = -2; dx <= 2; ++dx) inner &= group.at<int>(y + dy, x + dx) == g;
      if (!inner) continue;
      ratios.push_back(ratio.at<double>(y, x));
      where.emplace_back(x, y);
    }
  }
  out.judged = static_cast<long>(ratios.size());
  if (ratios.empty()) return out;

  std::vector<double> sorted = ratios;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                   sorted.end());
  const double median = sorted[sorted.size() / 2];
  double sum = 0;
  for (double r : ratios) sum += std::abs(r / median - 1);
  out.mean_rel = sum / static_cast<double>(ratios.size());
  std::vector<double> dn;
  for (const cv::Point& p : where) {
    const cv::Vec3f bgr = seen.at<cv::Vec3f>(p);
    dn.push_back(luma(Vec3(bgr[2], bgr[1], bgr[0])));
  }
  std::nth_element(dn.begin(), dn.begin() + static_cast<long>(dn.size() / 2), dn.end());
  out.median_dn = dn[dn.size() / 2];
  // Spill: light on the table, the wall or the floor, away from the box.
  cv::Mat off_box, distance;
  cv::bitwise_not(on_box, off_box);
  cv::distanceTransform(off_box, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      if (on_box.at<std::uint8_t>(y, x)) continue;
      const cv::Vec3f bgr = seen.at<cv::Vec3f>(y, x);
      // Well over the noise of the difference of two means of 16 captures (0.4 DN).
      if (luma(Vec3(bgr[2], bgr[1], bgr[0])) < 5.0) continue;
      const double d = distance.at<float>(y, x);
      out.spill_px = std::max(out.spill_px, d);
      out.spilled += d > 2;
    }
  }
  return out;
}

// The eight corners of the box: in the model's frame and in the world, the world ones
// off by `pick_m` per axis (normal, seeded).
json cornerPoints(double pick_m) {
  const Mat3 R = modelRotation();
  json points = json::array();
  std::mt19937 rng(7);
  std::normal_distribution<double> pick(0, 1);
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner =
        kBoxCentre + 0.5 * Vec3((k & 1 ? 1 : -1) * kBoxSize.x(), (k & 2 ? 1 : -1) * kBoxSize.y(),
                                (k & 4 ? 1 : -1) * kBoxSize.z());
    const Vec3 m = R.transpose() * (corner - kBoxCentre);
    const Vec3 w = corner + pick_m * Vec3(pick(rng), pick(rng), pick(rng));
    points.push_back({{"model", {m.x(), m.y(), m.z()}}, {"world", {w.x(), w.y(), w.z()}}});
  }
  return points;
}

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
  std::printf(
      "procamd object content: %ld camera pixels (median %.1f DN), mean relative luminance "
      "error %.2f %% (up to the white level), brightened pixels off the box: farthest %.1f px from "
      "its "
      "outline, %ld beyond 2 px\n",
      seen.judged, seen.median_dn, 100 * seen.mean_rel, seen.spill_px, seen.spilled);
  EXPECT_GT(seen.judged, 20000);
  EXPECT_LT(seen.mean_rel, 0.03);
  EXPECT_EQ(seen.spilled, 0);

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
  auto placed = c.call({{"cmd", "object"},
                        {"action", "place"},
                        {"model", "box_model.ply"},
                        {"points", cornerPoints(0)}},
                       30s);
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

// Route (a): nothing handed over but the cameras' calibration. calibrate triangulates
// both projectors and their meshes of the scene through the two cameras and measures
// their responses and brightness; the box's model, placed from corners picked 4 mm off,
// is refined against the measured surface (`object refine`), and the look painted on it
// is judged through the colour camera as above.
TEST(ShaderLamp, DaemonRefinesAPlacementOnTheSurfaceItMeasured) {
  TempDir dir;
  auto scene = sim::resolveScene("object_box");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  const ObjectMesh box = boxMesh(kBoxCentre, kBoxSize, 0.01);
  writeContent(dir, "box_model.ply", texturedPly(box, modelRotation(), kBoxCentre));
  ASSERT_TRUE(cv::imwrite(contentFile(dir, "look.png"), waveTextureSrgb()));
  DaemonProcess d(dir, simWithTruth(dir, "object_box", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_TRUE(c.ok());

  // Nothing to refine yet: no object, then no measured surface.
  auto bad = c.call({{"cmd", "object"}, {"action", "refine"}});
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "unavailable") << bad->dump();
  auto placed = c.call({{"cmd", "object"},
                        {"action", "place"},
                        {"model", "box_model.ply"},
                        {"points", cornerPoints(0.004)}},
                       30s);
  ASSERT_TRUE(placed) << d.log();
  ASSERT_EQ((*placed)["class"], "OBJECT") << placed->dump();
  bad = c.call({{"cmd", "object"}, {"action", "refine"}}, 30s);
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "unavailable") << bad->dump();
  bad = c.call({{"cmd", "object"}, {"action", "refine"}, {"max_distance_m", 0.5}});
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "bad-argument") << bad->dump();

  auto started = c.call({{"cmd", "calibrate"},
                         {"id", 1},
                         {"projectors", "all"},
                         {"cameras", {"cam", "cam_colour"}},
                         {"settle_frames", 0}});
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  auto done = finalReply(c, 1, kSlowdown * 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  ASSERT_EQ((*done)["outputs"].size(), 2u) << done->dump();
  for (const json& o : (*done)["outputs"]) EXPECT_EQ(o["surface_type"], "mesh") << o.dump();

  // How far a placement is from the truth: the box's turn, and its centre's shift across
  // the directions the measured surface fixes (`free` slides taken out).
  const auto offTruth = [&](const json& object, const json& free) {
    Mat3 R;
    for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = object["R"][i].get<double>();
    Vec3 shift = Vec3(object["t"][0].get<double>(), object["t"][1].get<double>(),
                      object["t"][2].get<double>()) -
                 kBoxCentre;
    for (const json& f : free) {
      if (f["kind"] != "slide") continue;
      const Vec3 a(f["axis"][0].get<double>(), f["axis"][1].get<double>(),
                   f["axis"][2].get<double>());
      shift -= shift.dot(a) * a;
    }
    return std::pair{radToDeg(Eigen::AngleAxisd(R * modelRotation().transpose()).angle()),
                     1000 * shift.norm()};
  };
  int status = -1;
  const json refined = ctlJson(d, {"object", "refine"}, status);
  ASSERT_EQ(status, 0) << refined.dump();
  ASSERT_EQ(refined["class"], "OBJECT") << refined.dump();
  const json& r = refined["refined"];
  const auto [picked_deg, picked_mm] = offTruth((*placed)["object"], r["free"]);
  const auto [refined_deg, refined_mm] = offTruth(refined["object"], r["free"]);
  std::printf(
      "object refine: from %ld of %ld measured points, %.2f mm RMS, free: %s; the placement from "
      "corners picked 4 mm off was %.3f deg and %.2f mm off the truth (across the fixed "
      "directions), refined %.3f deg and %.2f mm\n",
      r["points"].get<long>(), r["candidates"].get<long>(), 1000 * r["rms_m"].get<double>(),
      r["free"].dump().c_str(), picked_deg, picked_mm, refined_deg, refined_mm);
  EXPECT_GT(r["points"].get<long>(), 500);
  EXPECT_LT(r["points"].get<long>(), r["candidates"].get<long>());  // not the table or the wall
  // Both cameras see the box's front and top, neither its sides: the slide along their
  // common edge (x) is the one direction they leave free.
  ASSERT_EQ(r["free"].size(), 1u) << r.dump();
  EXPECT_EQ(r["free"][0]["kind"], "slide");
  EXPECT_GT(std::abs(r["free"][0]["axis"][0].get<double>()), 0.99) << r.dump();
  // The measured surface to its triangulation noise (about a millimetre here), over
  // hundreds of points a face: the pose to a tenth of a degree and half a millimetre.
  EXPECT_LT(refined_deg, 0.1);
  EXPECT_LT(refined_mm, 0.5);
  EXPECT_LT(refined_deg, picked_deg);
  EXPECT_LT(refined_mm, picked_mm);
  EXPECT_NE(refined["object"]["placed"]["method"].get<std::string>().find("refined from"),
            std::string::npos);

  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "off"}}))["pattern"], "off");
  const cv::Mat dark = meanSnapshot(c, "cam_colour", kShots);
  auto loaded =
      c.call({{"cmd", "content"}, {"action", "load"}, {"path", "look.png"}}, 120s * kSlowdown);
  ASSERT_TRUE(loaded);
  ASSERT_EQ((*loaded)["class"], "CONTENT") << loaded->dump();
  for (const auto& p : (*loaded)["content"]["projectors"]) {
    EXPECT_EQ(p["gain_source"], "brightness map") << p.dump();
    EXPECT_EQ(p["response"], "measured") << p.dump();
  }
  ASSERT_TRUE(eventually(
      [&] {
        auto s = c.call({{"cmd", "status"}});
        if (!s || (*s)["outputs"]["shown"].size() != 2) return false;
        for (const auto& o : (*s)["outputs"]["shown"])
          if (o["path"] != "shader-lamps" || !(o["lit_fraction"].get<double>() > 0.02))
            return false;
        return true;
      },
      20s * kSlowdown))
      << c.call({{"cmd", "status"}})->dump();
  const cv::Mat lit = meanSnapshot(c, "cam_colour", kShots);
  cv::Mat texture_bgr = waveTextureSrgb();
  const Seen seen = judge(*scene, state, lit, dark, lamps::linearTexture(texture_bgr));
  std::printf(
      "painted from the calibrated rig: %ld camera pixels (median %.1f DN), mean relative "
      "luminance error %.2f %%, brightened pixels off the box: farthest %.1f px from its outline, "
      "%ld beyond 2 px\n",
      seen.judged, seen.median_dn, 100 * seen.mean_rel, seen.spill_px, seen.spilled);
  EXPECT_GT(seen.judged, 20000);
  EXPECT_LT(seen.mean_rel, 0.03);
  EXPECT_EQ(seen.spilled, 0);
}

}  // namespace
}  // namespace procam::itest
