// Shader lamps in procamd from a calibrated rig (route (a)): object_box with nothing
// handed over but its cameras' calibration. calibrate triangulates both projectors and
// their meshes of the scene through the two cameras and measures their responses and
// brightness; the box's model, placed from corners picked 4 mm off, is refined against the
// measured surface (`object refine`), and the look painted on it is judged through the
// colour camera (object_box_daemon.hpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <utility>

#include "core/units.hpp"
#include "daemon_harness.hpp"
#include "object_box_daemon.hpp"
#include "object_meshes.hpp"
#include "shader_lamps/rig_lamps.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"
#include "wave_texture.hpp"

namespace procam::itest {
namespace {

using namespace std::chrono_literals;

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
  auto placed = placeBox(c, 0.004);
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
  expectPaintedBox(seen, "painted from the calibrated rig");
}

}  // namespace
}  // namespace procam::itest
