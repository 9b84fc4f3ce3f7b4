// procam-render --object on the virtual rig's object_box (two projectors, shader lamps,
// [Raskar02] §5.2), from the scene's true rig handed over explicitly with each
// projector's true response and brightness across its frame as its photometric record
// (grey: the brightness map holds the surface's mean albedo, so colour is judged as
// luminance), and the box's model as a PLY with texture coordinates:
//  - the frames lighting the scene, seen from the scene's viewer in linear light, give
//    the texture at the white level display.json reports;
//  - a projector switched off: its frame dark, the part only it lit reported unlit;
//  - bad input: clear errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "blend/brightness_map.hpp"
#include "daemon_harness.hpp"
#include "object_meshes.hpp"
#include "object_render.hpp"
#include "render_command.hpp"
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

using nlohmann::json;

const Vec3 kBoxCentre(0.1, 1.5, 0.875), kBoxSize(0.3, 0.2, 0.25);

struct BoxRig {
  sim::Scene scene;
  sim::SceneState state;
  std::string rig, mesh, texture;
};

double luma(const Vec3& rgb) {
  return 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
}

BoxRig boxRig(const TempDir& dir) {
  auto scene = sim::resolveScene("object_box");
  EXPECT_TRUE(scene);
  BoxRig r{*scene, scene->at(0), "", "", ""};
  auto rig = sim::truthRig(r.scene, 0.0);
  EXPECT_TRUE(rig);
  addTruePhotometry(r.scene, r.state, *rig);
  dir.write("rig.json", rig::rigToJson(*rig).dump(2) + "\n");
  r.rig = dir.file("rig.json");
  // The box's model with its texture atlas, as an ASCII PLY.
  const ObjectMesh box = boxMesh(kBoxCentre, kBoxSize, 0.01);
  dir.write("box.ply", texturedPly(box));
  r.mesh = dir.file("box.ply");
  // The same as OBJ, texture coordinates per face corner.
  std::ostringstream obj;
  obj.precision(17);
  for (const Vec3& x : box.mesh.vertices)
    obj << "v " << x.x() << ' ' << x.y() << ' ' << x.z() << '\n';
  for (const Vec2& t : box.uv) obj << "vt " << t.x() << ' ' << t.y() << '\n';
  for (const auto& f : box.mesh.faces)
    obj << "f " << f[0] + 1 << '/' << f[0] + 1 << ' ' << f[1] + 1 << '/' << f[1] + 1 << ' '
        << f[2] + 1 << '/' << f[2] + 1 << '\n';
  dir.write("box.obj", obj.str());
  // A smooth texture, sRGB-encoded.
  EXPECT_TRUE(cv::imwrite(dir.file("look.png"), waveTextureSrgb()));
  r.texture = dir.file("look.png");
  return r;
}

Result<json> run(const std::vector<std::string>& args) {
  auto parsed = render_cli::parseRenderArgs(args);
  if (!parsed) return tl::unexpected(parsed.error());
  return render_cli::runRender(*parsed);
}

// What the viewer sees of the box lit by the frames in DIR against white · texture, as
// luminance: the mean relative error over box pixels two in from its outline on one face.
double appearanceError(const BoxRig& r, const std::string& dir, double white, long* judged) {
  sim::Framebuffers frames;
  for (const auto& p : r.state.projectors)
    frames[p.spec.name] = cv::imread(dir + "/" + p.spec.name + ".png", cv::IMREAD_UNCHANGED);
  auto lit = sim::Renderer::create(r.scene, r.state, frames);
  auto dark = sim::Renderer::create(r.scene, r.state, {});
  EXPECT_TRUE(lit && dark);
  if (!lit || !dark) return 1;
  const cv::Mat seen = lit->renderViewer(4) - dark->renderViewer(4);
  const ObjectMesh box = boxMesh(kBoxCentre, kBoxSize, 0.01);
  auto model = lamps::ObjectModel::build(box.mesh, box.uv);
  EXPECT_TRUE(model);
  const cv::Mat texture = lamps::linearTexture(cv::imread(r.texture, cv::IMREAD_UNCHANGED));
  const geom::CameraModel& eye = r.state.viewer;
  cv::Mat group(eye.height, eye.width, CV_32SC1, cv::Scalar(-1));
  std::vector<double> target(static_cast<std::size_t>(eye.width * eye.height), 0);
  for (int y = 0; y < eye.height; ++y) {
    for (int x = 0; x < eye.width; ++x) {
      const sim::PixelTruth t = lit->truthAt(eye, Vec2(x, y));
      if (!t.hit || r.scene.world().surfaces()[static_cast<std::size_t>(t.surface)].name != "box")
        continue;
      const auto s = model->intersect(*eye.backproject(Vec2(x, y)));
      if (!s) continue;
      // Face by its normal: one group per side of the box.
      group.at<int>(y, x) = boxSideOf(t.normal);
      target[static_cast<std::size_t>(y * eye.width + x)] =
          white * luma(lamps::textureAt(texture, s->texcoord));
    }
  }
  double sum = 0;
  *judged = 0;
  for (int y = 2; y + 2 < eye.height; ++y) {
    for (int x = 2; x + 2 < eye.width; ++x) {
      const int g = group.at<int>(y, x);
      if (g < 0) continue;
      bool one_face = true;
      for (int dy = -2; dy <= 2 && one_face; ++dy)
        for (int dx = -2; dx <= 2; ++dx) one_face &= group.at<int>(y + dy, x + dx) == g;
      if (!one_face) continue;
      const cv::Vec3f bgr = seen.at<cv::Vec3f>(y, x);
      const double want = target[static_cast<std::size_t>(y * eye.width + x)];
      sum += std::abs(luma(Vec3(bgr[2], bgr[1], bgr[0])) - want) / want;
      ++*judged;
    }
  }
  return *judged ? sum / *judged : 1;
}

TEST(RenderCliObject, FramesPaintTheBoxWithItsTexture) {
  TempDir dir;
  const BoxRig r = boxRig(dir);
  auto doc = run(
      {"--rig", r.rig, "--object", r.mesh, "--texture", r.texture, "--out", dir.file("frames")});
  ASSERT_TRUE(doc) << doc.error().message;
  const json& display = (*doc)["display"];
  EXPECT_EQ(display["surface"], "object");
  EXPECT_EQ(display["units"], "camera 'truth' units");
  EXPECT_EQ(display["coverage"]["unlit_m2"].get<double>(), 0.0);
  ASSERT_EQ((*doc)["projectors"].size(), 2u);
  for (const auto& p : (*doc)["projectors"]) {
    EXPECT_EQ(p["gain_source"], "brightness map");
    EXPECT_GT(p["lit_pixels"].get<long>(), 10000);
  }
  long judged = 0;
  const double error =
      appearanceError(r, dir.file("frames"), display["white"].get<double>(), &judged);
  std::printf(
      "procam-render --object: white %.4f, %ld viewer pixels, mean relative luminance "
      "error %.2f %%\n",
      display["white"].get<double>(), judged, 100 * error);
  EXPECT_GT(judged, 20000);
  EXPECT_LT(error, 0.03);
  // The same model as OBJ: the same frames.
  auto from_obj = run({"--rig", r.rig, "--object", dir.file("box.obj"), "--texture", r.texture,
                       "--out", dir.file("obj")});
  ASSERT_TRUE(from_obj) << from_obj.error().message;
  EXPECT_TRUE((*from_obj)["object"]["textured"].get<bool>());
  for (const auto& p : r.state.projectors) {
    const cv::Mat a = cv::imread(dir.file("frames/" + p.spec.name + ".png"), cv::IMREAD_UNCHANGED);
    const cv::Mat b = cv::imread(dir.file("obj/" + p.spec.name + ".png"), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_LE(cv::norm(a, b, cv::NORM_INF), 1) << p.spec.name;
  }
}

TEST(RenderCliObject, AProjectorSwitchedOffIsDarkAndItsPartReported) {
  TempDir dir;
  const BoxRig r = boxRig(dir);
  auto doc = run({"--rig", r.rig, "--object", r.mesh, "--texture", r.texture, "--off", "proj_right",
                  "--out", dir.file("frames")});
  ASSERT_TRUE(doc) << doc.error().message;
  EXPECT_GT((*doc)["display"]["coverage"]["unlit_m2"].get<double>(), 0.001);
  EXPECT_GT((*doc)["display"]["coverage"]["unlit_faces"].get<long>(), 0);
  const cv::Mat off = cv::imread(dir.file("frames/proj_right.png"), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(off.empty());
  EXPECT_EQ(cv::countNonZero(off.reshape(1)), 0);
}

TEST(RenderCliObject, BadInputIsNamed) {
  TempDir dir;
  const BoxRig r = boxRig(dir);
  const auto code = [&](const std::vector<std::string>& args) {
    auto doc = run(args);
    return doc ? std::optional<ErrorCode>() : doc.error().code;
  };
  EXPECT_EQ(
      code({"--rig", r.rig, "--object", r.mesh, "--content", r.texture, "--out", dir.file("x")}),
      ErrorCode::kInvalidInput);
  EXPECT_EQ(code({"--rig", r.rig, "--content", r.texture, "--off", "proj", "--out", dir.file("x")}),
            ErrorCode::kInvalidInput);
  EXPECT_EQ(code({"--rig", r.rig, "--object", dir.file("none.ply"), "--out", dir.file("x")}),
            ErrorCode::kIo);
  EXPECT_EQ(code({"--rig", r.rig, "--object", r.mesh, "--off", "nobody", "--out", dir.file("x")}),
            ErrorCode::kNotFound);
  EXPECT_EQ(code({"--rig", r.rig, "--object", r.mesh, "--specular", "2", "--out", dir.file("x")}),
            ErrorCode::kInvalidInput);
  EXPECT_EQ(code({"--rig", r.rig, "--object", r.mesh, "--off", "proj", "--off", "proj_right",
                  "--out", dir.file("x")}),
            ErrorCode::kInvalidInput);
  // Highlight options without an object.
  EXPECT_EQ(
      code({"--rig", r.rig, "--content", r.texture, "--specular", "0.5", "--out", dir.file("x")}),
      ErrorCode::kInvalidInput);
  // A texture for a model without texture coordinates.
  dir.write("bare.obj", "v 0 1.4 0.9\nv 0.1 1.4 0.9\nv 0 1.4 1\nf 1 2 3\n");
  EXPECT_EQ(code({"--rig", r.rig, "--object", dir.file("bare.obj"), "--texture", r.texture, "--out",
                  dir.file("x")}),
            ErrorCode::kInvalidInput);
  // One projector's brightness measured, the other's not: gains that do not compare.
  json rig = json::parse(std::ifstream(r.rig));
  for (auto& p : rig["projectors"])
    if (p["name"] == "proj_right") p["photometric"].erase("brightness");
  dir.write("half.json", rig.dump());
  EXPECT_EQ(code({"--rig", dir.file("half.json"), "--object", r.mesh, "--out", dir.file("x")}),
            ErrorCode::kInvalidInput);
  // With it switched off, the one that is on decides.
  EXPECT_FALSE(code({"--rig", dir.file("half.json"), "--object", r.mesh, "--off", "proj_right",
                     "--out", dir.file("x")}));
}

}  // namespace
}  // namespace procam::itest
