// The rig model (rig.json): version 2 round trip at full precision, version 1
// read, merging that keeps what a calibration did not touch, and refusal of
// malformed or hostile documents with a typed error.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "rig/rig_model.hpp"

namespace procam::rig {
namespace {

using nlohmann::json;

RigProjector projector(const std::string& name, double fx) {
  RigProjector p;
  p.name = p.output = name;
  p.width = 1280;
  p.height = 800;
  p.K = {fx, fx * 1.001, 639.5, 399.5, 0};
  p.dist = {0.01, -0.002, 0, 0, 0};
  p.pose.R = Eigen::AngleAxisd(0.3, Vec3(0.2, 1, 0.1).normalized()).toRotationMatrix();
  p.pose.t = Vec3(0.1, -0.2, 3.0 + 1.0 / 3.0);
  p.rms_px = 0.07;
  p.points = 4321;
  p.calibrated = {"structured light, route (a): cameras a b", "2026-11-26T12:00:00Z"};
  return p;
}

RigCamera camera(const std::string& name) {
  RigCamera c;
  c.name = name;
  c.model.width = 1024;
  c.model.height = 768;
  c.model.K = {900, 900, 511.5, 383.5, 0};
  c.model.dist = {-0.04, 0.01, 0, 0, 0};
  c.model.pose.t = Vec3(1, 2, 3);
  c.rms_px = 0.1;
  return c;
}

TEST(RigModel, Version2RoundTripKeepsEveryDigit) {
  RigModel rig;
  rig.cameras = {camera("cam_left"), camera("cam_right")};
  rig.projectors = {projector("proj_a", 1500), projector("proj_b", 1600)};
  TiltMountModel tilt;
  tilt.sensor = "accel";
  tilt.sensor_from_projector << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  tilt.calibration.offset = Vec3(0.01, -0.02, 0.05);
  tilt.calibration.scale = Vec3(1.01, 0.99, 1.0);
  tilt.fit_rms_g = 1e-4;
  rig.projectors[0].tilt = tilt;
  rig.projectors[1].photometric = {{"gamma", 2.2}};
  rig.surface.plane = geom::Plane{Vec3(0, -1, 0), 3.0};
  rig.surface.plane_rms_m = 1e-4;
  rig.surface.meshes["proj_b"] = "surface-proj_b.ply";
  rig.viewer.position = Vec3(-1.6, 0.4, 1.6);
  rig.viewer.tracker = "ir_head";

  const json j = rigToJson(rig);
  EXPECT_EQ(j["version"], 2);
  auto back = rigFromText(j.dump(2), "rig.json");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(rigToJson(*back), j);  // a fixed point: nothing lost or rounded
  ASSERT_EQ(back->projectors.size(), 2u);
  const RigProjector& p = back->projectors[0];
  EXPECT_EQ(p.pose.t.z(), 3.0 + 1.0 / 3.0);
  EXPECT_EQ(p.pose.R, rig.projectors[0].pose.R);
  ASSERT_TRUE(p.tilt);
  EXPECT_EQ(p.tilt->sensor_from_projector, tilt.sensor_from_projector);
  EXPECT_EQ(p.tilt->calibration.offset, tilt.calibration.offset);
  EXPECT_EQ(back->projectors[1].photometric["gamma"], 2.2);
  EXPECT_EQ(back->viewer.position, rig.viewer.position);
  EXPECT_EQ(back->surface.meshes.at("proj_b"), "surface-proj_b.ply");
  EXPECT_EQ(back->projectorForOutput("proj_b"), &back->projectors[1]);
  EXPECT_EQ(back->projectorForOutput("elsewhere"), nullptr);  // bound projectors only
}

TEST(RigModel, Version1IsReadWithItsOneProjectorUnbound) {
  const char* v1 = R"({"cameras": [{"name": "cam", "width": 640, "height": 480,
      "K": [500, 0, 319.5, 0, 500, 239.5, 0, 0, 1], "R": [1,0,0,0,1,0,0,0,1], "t": [0,0,0]}],
    "projectors": [{"name": "proj", "width": 1280, "height": 800,
      "K": [1500, 0, 639.5, 0, 1500, 399.5, 0, 0, 1], "R": [1,0,0,0,1,0,0,0,1],
      "t": [0, 0, 0], "reprojection_rms_px": 0.1, "points": 10}],
    "surface": {"mesh": "surface.ply"}})";
  auto rig = rigFromText(v1, "v1");
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->projectors.size(), 1u);
  EXPECT_EQ(rig->projectors[0].output, "");
  EXPECT_EQ(rig->projectorForOutput("beamer"), &rig->projectors[0]);
  EXPECT_EQ(rig->surface.meshes.at("proj"), "surface.ply");
  EXPECT_EQ(rig->camera("cam")->model.K.fx, 500);
}

TEST(RigModel, MergeReplacesWhatWasCalibratedAndKeepsTheRest) {
  RigModel base;
  base.cameras = {camera("cam_left"), camera("cam_right")};
  base.projectors = {projector("proj_a", 1500), projector("proj_b", 1600)};
  TiltMountModel tilt;
  tilt.sensor = "accel";
  base.projectors[0].tilt = tilt;
  base.surface.meshes["proj_b"] = "surface-proj_b.ply";
  base.viewer.position = Vec3(1, 2, 3);

  RigModel update;
  update.projectors = {projector("proj_a", 1510), projector("proj_c", 1700)};
  update.surface.meshes["proj_a"] = "surface-proj_a.ply";
  const RigModel merged = mergeRig(base, update);
  ASSERT_EQ(merged.projectors.size(), 3u);
  EXPECT_EQ(merged.projector("proj_a")->K.fx, 1510);
  EXPECT_TRUE(merged.projector("proj_a")->tilt);  // a calibration without the sensor keeps it
  EXPECT_EQ(merged.projector("proj_b")->K.fx, 1600);
  EXPECT_EQ(merged.projector("proj_c")->K.fx, 1700);
  EXPECT_EQ(merged.cameras.size(), 2u);
  EXPECT_EQ(merged.surface.meshes.size(), 2u);
  EXPECT_EQ(merged.viewer.position, Vec3(1, 2, 3));
  EXPECT_EQ(rigToJson(mergeRig(base, RigModel{})), rigToJson(base));  // nothing new: unchanged
}

// An object the projectors paint: its model file and its placement survive the file
// and a merge; a broken entry is a typed error.
TEST(RigModel, ObjectRoundTripAndMerge) {
  RigModel rig;
  rig.projectors = {projector("proj_a", 1500)};
  RigObject object;
  object.mesh = "object-model.ply";
  object.R = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  object.t = Vec3(0.1, 1.5, 0.875);
  object.fit_rms_m = 0.0011;
  object.points = 8;
  object.placed = {"model box.ply placed from 8 points", "2026-11-28T08:00:00Z"};
  rig.surface.object = object;
  EXPECT_FALSE(rig.surface.empty());
  auto back = rigFromJson(rigToJson(rig), "rig.json");
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_TRUE(back->surface.object);
  const RigObject& o = *back->surface.object;
  EXPECT_EQ(o.mesh, object.mesh);
  EXPECT_EQ(o.R, object.R);
  EXPECT_EQ(o.t, object.t);
  EXPECT_EQ(o.fit_rms_m, object.fit_rms_m);
  EXPECT_EQ(o.points, 8);
  EXPECT_EQ(o.placed.method, object.placed.method);
  EXPECT_EQ(o.placed.time, object.placed.time);
  EXPECT_EQ(rigToJson(*back), rigToJson(rig));

  // A merge without an object keeps it; one with an object replaces it.
  RigModel update;
  update.projectors = {projector("proj_a", 1510)};
  EXPECT_EQ(mergeRig(rig, update).surface.object->mesh, "object-model.ply");
  RigObject other;
  other.mesh = "other.ply";
  update.surface.object = other;
  EXPECT_EQ(mergeRig(rig, update).surface.object->mesh, "other.ply");
  EXPECT_EQ(mergeRig(rig, update).surface.object->R, Mat3::Identity());

  for (const char* broken : {R"({"mesh": 3})", R"({"R": [1,0,0,0,1,0,0,0,1]})",
                             R"({"mesh": "m.ply", "R": [2,0,0,0,1,0,0,0,1]})",
                             R"({"mesh": "m.ply", "t": [0, 1]})", R"([])"}) {
    nlohmann::json doc = rigToJson(rig);
    doc["surface"]["object"] = nlohmann::json::parse(broken);
    auto parsed = rigFromJson(doc, "rig.json");
    ASSERT_FALSE(parsed) << broken;
    EXPECT_EQ(parsed.error().code, ErrorCode::kParse) << broken;
  }
}

TEST(RigModel, CameraMountedOnAProjectorStaysMountedWhenRecalibrated) {
  RigModel base;
  base.projectors = {projector("proj_a", 1500)};
  base.cameras = {camera("cam")};
  base.cameras[0].attached_to = "proj_a";
  auto back = rigFromJson(rigToJson(base), "test");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->cameras[0].attached_to, "proj_a");
  EXPECT_EQ(back->attachedCamera("proj_a"), &back->cameras[0]);
  EXPECT_EQ(back->attachedCamera("proj_b"), nullptr);
  // A calibration that does not know the mount keeps it.
  RigModel update;
  update.cameras = {camera("cam")};
  update.cameras[0].rms_px = 0.05;
  const RigModel merged = mergeRig(base, update);
  EXPECT_EQ(merged.cameras[0].attached_to, "proj_a");
  EXPECT_EQ(merged.cameras[0].rms_px, 0.05);
  // A camera without a pose gives no yaw.
  base.cameras[0].pose_known = false;
  EXPECT_EQ(base.attachedCamera("proj_a"), nullptr);
  // Mounted on a projector not calibrated yet: kept, and no yaw from it; a mount that
  // is not a name is refused.
  json doc = rigToJson(base);
  doc["cameras"][0]["attached_to"] = "proj_z";
  auto later = rigFromJson(doc, "test");
  ASSERT_TRUE(later) << later.error().message;
  EXPECT_EQ(later->cameras[0].attached_to, "proj_z");
  doc["cameras"][0]["attached_to"] = 3;
  auto bad = rigFromJson(doc, "test");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kParse);
  EXPECT_NE(bad.error().message.find("attached_to"), std::string::npos);
  EXPECT_FALSE(rigFromJson(doc, "test"));
  doc["cameras"][0]["attached_to"] = "";
  EXPECT_FALSE(rigFromJson(doc, "test"));
}

TEST(RigModel, MalformedDocumentsAreTypedErrors) {
  const std::pair<const char*, ErrorCode> cases[] = {
      {"[]", ErrorCode::kParse},
      {"not json", ErrorCode::kParse},
      {R"({"version": 3})", ErrorCode::kInvalidInput},
      {R"({"version": "2"})", ErrorCode::kParse},
      {R"({"projectors": {}})", ErrorCode::kParse},
      {R"({"projectors": [{"name": "p", "width": 10, "height": 10, "K": [1, 2]}]})",
       ErrorCode::kParse},
      // Not a rotation.
      {R"({"cameras": [{"width": 10, "height": 10, "K": [5,0,5,0,5,5,0,0,1],
          "R": [2,0,0,0,1,0,0,0,1], "t": [0,0,0]}]})",
       ErrorCode::kParse},
      // A focal length of zero.
      {R"({"cameras": [{"width": 10, "height": 10, "K": [0,0,5,0,5,5,0,0,1],
          "R": [1,0,0,0,1,0,0,0,1], "t": [0,0,0]}]})",
       ErrorCode::kParse},
      // Absurd size.
      {R"({"cameras": [{"width": 1000000, "height": 10, "K": [5,0,5,0,5,5,0,0,1],
          "R": [1,0,0,0,1,0,0,0,1], "t": [0,0,0]}]})",
       ErrorCode::kParse},
      {R"({"surface": {"plane": [0, 0, 0, 1]}})", ErrorCode::kParse},
      {R"({"viewer": {"position": [1, 2]}})", ErrorCode::kParse},
      {R"({"projectors": [{"name": "p", "width": 10, "height": 10, "K": [5,0,5,0,5,5,0,0,1],
          "tilt": {"mount": [1,0,0,0,1,0,0,0,1], "scale": [0, 1, 1]}}]})",
       ErrorCode::kParse},
      // Neither K nor a plane mapping.
      {R"({"projectors": [{"name": "p", "width": 10, "height": 10}]})", ErrorCode::kParse},
      // A plane mapping with a basis that is not orthonormal, or a singular H.
      {R"({"projectors": [{"name": "p", "width": 10, "height": 10, "plane_homography":
          {"H": [1,0,0,0,1,0,0,0,1], "origin": [0,3,0], "u": [1,0,0], "v": [1,0,1]}}]})",
       ErrorCode::kParse},
      {R"({"projectors": [{"name": "p", "width": 10, "height": 10, "plane_homography":
          {"H": [1,0,0,2,0,0,0,0,1], "origin": [0,3,0], "u": [1,0,0], "v": [0,0,1]}}]})",
       ErrorCode::kParse},
      {R"({"projectors": [{"name": "p", "width": 10, "height": 10, "plane_homography":
          {"H": [1,0,0,0,1,0,0,0,1], "origin": [0,3], "u": [1,0,0], "v": [0,0,1]}}]})",
       ErrorCode::kParse},
  };
  for (const auto& [text, code] : cases) {
    auto r = rigFromText(text, "test");
    ASSERT_FALSE(r) << text;
    EXPECT_EQ(r.error().code, code) << text << ": " << r.error().message;
  }
  // 65 devices: over the bound.
  json many = {{"cameras", json::array()}};
  for (int i = 0; i < 65; ++i) many["cameras"].push_back(json::object());
  EXPECT_FALSE(rigFromJson(many, "many"));
}

TEST(RigModel, ProjectorWithoutPoseKeepsOnlyItsIntrinsics) {
  auto rig = rigFromText(R"({"version": 2, "projectors": [{"name": "p", "output": "hdmi",
      "width": 1920, "height": 1080, "K": [2000,0,959.5,0,2000,539.5,0,0,1]}]})",
                         "k-only");
  ASSERT_TRUE(rig) << rig.error().message;
  EXPECT_FALSE(rig->projectors[0].pose_known);
  EXPECT_EQ(rig->projectorForOutput("hdmi")->K.fx, 2000);
  EXPECT_FALSE(rigToJson(*rig)["projectors"][0].contains("R"));
}

// Route (b′): a projector known only by its collineation with the display plane.
// It round-trips at full precision, has no K, no pose and no dist in the file, and
// merging it replaces the projector's earlier entry (keeping its tilt mount).
TEST(RigModel, PlaneHomographyRoundTripWithoutIntrinsics) {
  RigModel rig;
  RigProjector p;
  p.name = p.output = "proj";
  p.width = 1920;
  p.height = 1080;
  p.intrinsics_known = false;
  p.pose_known = false;
  p.rms_px = 0.04;
  p.points = 12345;
  geom::PlaneHomography ph;
  ph.basis.origin = Vec3(-0.4, 3.0, 1.0 + 1.0 / 3.0);
  ph.basis.u = Vec3(1, 0, 0);
  ph.basis.v = Vec3(0, 0, 1);
  ph.H << 1.1e-3, 2e-5, -1.05, -3e-5, -9e-4, 0.41, 1e-5, 2e-6, 0.7;
  p.plane_homography = ph;
  rig.projectors = {p};
  rig.surface.plane = geom::Plane{Vec3(0, -1, 0), 3.0};

  const json j = rigToJson(rig);
  const json& pj = j["projectors"][0];
  EXPECT_FALSE(pj.contains("K"));
  EXPECT_FALSE(pj.contains("dist"));
  EXPECT_FALSE(pj.contains("R"));
  EXPECT_EQ(pj["pose_known"], false);
  auto back = rigFromText(j.dump(2), "rig.json");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(rigToJson(*back), j);  // a fixed point
  const RigProjector& b = back->projectors.at(0);
  EXPECT_FALSE(b.intrinsics_known);
  EXPECT_FALSE(b.pose_known);
  ASSERT_TRUE(b.plane_homography);
  EXPECT_EQ(b.plane_homography->H, ph.H);
  EXPECT_EQ(b.plane_homography->basis.origin, ph.basis.origin);
  EXPECT_EQ(b.plane_homography->basis.u, ph.basis.u);
  EXPECT_EQ(b.plane_homography->basis.v, ph.basis.v);

  // Merged over a route (a) entry with a tilt mount: the mapping replaces K and pose.
  RigModel base;
  base.projectors = {projector("proj", 1500)};
  base.projectors[0].tilt = TiltMountModel{};
  const RigModel merged = mergeRig(base, *back);
  ASSERT_EQ(merged.projectors.size(), 1u);
  EXPECT_FALSE(merged.projectors[0].intrinsics_known);
  EXPECT_TRUE(merged.projectors[0].plane_homography);
  EXPECT_TRUE(merged.projectors[0].tilt);
}

// A projector may have K and a plane mapping; files written before plane mappings
// existed have K alone and are read as before.
TEST(RigModel, ProjectorWithKAndPlaneHomographyKeepsBoth) {
  auto rig = rigFromText(R"({"version": 2, "projectors": [{"name": "p", "width": 1920,
      "height": 1080, "K": [2000,0,959.5,0,2000,539.5,0,0,1], "plane_homography":
      {"H": [1,0,0,0,1,0,0,0,1], "origin": [0,3,0], "u": [1,0,0], "v": [0,0,1]}}]})",
                         "both");
  ASSERT_TRUE(rig) << rig.error().message;
  EXPECT_TRUE(rig->projectors[0].intrinsics_known);
  EXPECT_EQ(rig->projectors[0].K.fx, 2000);
  EXPECT_TRUE(rig->projectors[0].plane_homography);
  auto old = rigFromText(R"({"version": 2, "projectors": [{"name": "p", "width": 1920,
      "height": 1080, "K": [2000,0,959.5,0,2000,539.5,0,0,1]}]})",
                         "old");
  ASSERT_TRUE(old) << old.error().message;
  EXPECT_TRUE(old->projectors[0].intrinsics_known);
  EXPECT_FALSE(old->projectors[0].plane_homography);
}

}  // namespace
}  // namespace procam::rig
