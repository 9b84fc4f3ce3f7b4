// The object model: shading normals smooth across a tessellated curve and across the
// seams of its texture, sharp at a box's edges; texture coordinates interpolated.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "core/units.hpp"
#include "integration/object_meshes.hpp"
#include "lamp_rig.hpp"
#include "shader_lamps/object_model.hpp"
#include "shader_lamps/object_placement.hpp"
#include "shader_lamps/object_refinement.hpp"
#include "sim/mesh_io.hpp"

namespace procam::lamps {
namespace {

// A unit sphere in latitude-longitude quads whose seam column repeats its vertices (as a
// textured mesh does), u = longitude / 2pi.
struct SeamedSphere {
  geom::TriangleMesh mesh;
  std::vector<Vec2> uv;
};

SeamedSphere seamedSphere(int segments) {
  SeamedSphere s;
  const double pi = std::numbers::pi;
  const int rings = segments / 2;
  for (int j = 0; j <= rings; ++j) {
    for (int i = 0; i <= segments; ++i) {
      const double theta = pi * j / rings, phi = 2 * pi * i / segments;
      s.mesh.vertices.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                   std::cos(theta));
      s.uv.emplace_back(static_cast<double>(i) / segments, 1 - static_cast<double>(j) / rings);
    }
  }
  const auto at = [&](int i, int j) { return j * (segments + 1) + i; };
  for (int j = 0; j < rings; ++j) {
    for (int i = 0; i < segments; ++i) {
      if (j > 0) s.mesh.faces.emplace_back(at(i, j), at(i + 1, j + 1), at(i + 1, j));
      if (j + 1 < rings) s.mesh.faces.emplace_back(at(i, j), at(i, j + 1), at(i + 1, j + 1));
    }
  }
  return s;
}

double angleDeg(const Vec3& a, const Vec3& b) {
  return radToDeg(std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)));
}

TEST(ShaderLampObject, NormalsOfATessellatedSphereAreRadialAcrossItsSeam) {
  SeamedSphere s = seamedSphere(32);
  auto model = ObjectModel::build(s.mesh, s.uv);
  ASSERT_TRUE(model) << model.error().message;
  // Rays at the sphere from outside, at every longitude, through the seam at phi = 0.
  double worst = 0, worst_seam = 0;
  for (int k = 0; k < 720; ++k) {
    const double phi = 2 * std::numbers::pi * (k + 0.5) / 720 - 0.05, z = 0.3;
    const Vec3 aim(std::cos(phi), std::sin(phi), z);
    const geom::Ray ray{3 * aim, -aim.normalized()};
    const auto hit = model->intersect(ray);
    ASSERT_TRUE(hit);
    const double err = angleDeg(hit->normal, hit->point);
    worst = std::max(worst, err);
    if (std::abs(phi) < 0.05) worst_seam = std::max(worst_seam, err);
  }
  // Interpolated vertex normals of a 32-gon: a small fraction of its 11.25 deg facets.
  EXPECT_LT(worst, 0.5);
  EXPECT_LT(worst_seam, 0.5);
  // Without welding the seam, its two columns would average over one side only: the
  // normals there would lean by about half a facet.
  std::printf("sphere normals: worst %.3f deg, at the seam %.3f deg\n", worst, worst_seam);
}

TEST(ShaderLampObject, ABoxKeepsItsEdges) {
  // A unit cube from 8 shared vertices: every corner is shared by three faces at 90 deg.
  geom::TriangleMesh cube;
  for (int k = 0; k < 8; ++k) cube.vertices.emplace_back(k & 1, (k >> 1) & 1, (k >> 2) & 1);
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    cube.faces.emplace_back(q[0], q[1], q[2]);
    cube.faces.emplace_back(q[0], q[2], q[3]);
  }
  auto model = ObjectModel::build(cube);
  ASSERT_TRUE(model);
  // Near a corner of the top face (z = 1), the normal is still straight up.
  const auto hit = model->intersect({Vec3(0.97, 0.02, 2), Vec3(0, 0, -1)});
  ASSERT_TRUE(hit);
  EXPECT_LT(angleDeg(hit->normal, Vec3::UnitZ()), 1e-9);
  // With no crease at all every corner is averaged over its three faces.
  auto smooth = ObjectModel::build(cube, {}, 180);
  ASSERT_TRUE(smooth);
  const auto corner = smooth->intersect({Vec3(0.999, 0.001, 2), Vec3(0, 0, -1)});
  ASSERT_TRUE(corner);
  EXPECT_GT(angleDeg(corner->normal, Vec3::UnitZ()), 30);
}

TEST(ShaderLampObject, TextureCoordinatesAreInterpolated) {
  geom::TriangleMesh m = test::plate(1.0, 0.5, 1);  // 4 vertices: (i, j) at x, z
  std::vector<Vec2> uv;
  for (const Vec3& v : m.vertices) uv.emplace_back(v.x() + 0.5, v.z() + 0.5);
  auto model = ObjectModel::build(m, uv);
  ASSERT_TRUE(model);
  EXPECT_TRUE(model->textured());
  const auto hit = model->intersect({Vec3(0.1, 0, -0.2), Vec3(0, 1, 0)});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->texcoord.x(), 0.6, 1e-12);
  EXPECT_NEAR(hit->texcoord.y(), 0.3, 1e-12);
  EXPECT_LT(angleDeg(hit->normal, -Vec3::UnitY()), 1e-9);  // facing the ray
}

TEST(ShaderLampObject, BadModelsAreRefused) {
  EXPECT_EQ(ObjectModel::build({}).error().code, ErrorCode::kInvalidInput);
  geom::TriangleMesh m = test::plate(1.0, 0.5, 1);
  EXPECT_EQ(ObjectModel::build(m, {Vec2(0, 0)}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(ObjectModel::build(m, {}, 200).error().code, ErrorCode::kInvalidInput);
  std::vector<Vec2> bad(m.vertices.size(), Vec2(std::nan(""), 0));
  EXPECT_EQ(ObjectModel::build(m, bad).error().code, ErrorCode::kInvalidInput);
  m.faces.emplace_back(0, 0, 1);  // no area
  EXPECT_EQ(ObjectModel::build(m).error().code, ErrorCode::kDegenerate);
}

// The placed model as it is kept beside rig.json reads back as the same model.
TEST(ShaderLampPlacement, ModelPlyKeepsVerticesFacesAndTextureCoordinates) {
  geom::TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {0.3, 0, 0}, {0, 0.2, 0}, {0.123456789012, -1e-7, 2.5}};
  mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  mesh.texcoord = {{0, 0}, {1, 0}, {0, 1}, {0.3333333, 0.25}};
  auto back = sim::parseMesh(modelPly(mesh), "object-model.ply");
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->vertices.size(), 4u);
  ASSERT_EQ(back->faces, mesh.faces);
  ASSERT_EQ(back->texcoord.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_LT((back->vertices[i] - mesh.vertices[i]).norm(), 1e-9);
    EXPECT_LT((back->texcoord[i] - mesh.texcoord[i]).norm(), 1e-6);
  }
  mesh.texcoord.clear();  // untextured: no s t
  auto plain = sim::parseMesh(modelPly(mesh), "object-model.ply");
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_TRUE(plain->texcoord.empty());
}

}  // namespace
}  // namespace procam::lamps

namespace procam::lamps {
namespace {

TEST(ShaderLampPlacement, FourOrMorePointsPlaceTheModel) {
  const Mat3 R = (Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())).toRotationMatrix();
  const Vec3 t(0.3, 1.2, -0.4);
  const std::vector<Vec3> model = {
      {0, 0, 0}, {0.3, 0, 0}, {0, 0.2, 0}, {0, 0, 0.25}, {0.3, 0.2, 0.25}};
  std::vector<Vec3> world;
  for (const Vec3& p : model) world.push_back(R * p + t);
  world[4].x() += 0.002;  // one point picked 2 mm off
  auto placement = placeObject(model, world);
  ASSERT_TRUE(placement) << placement.error().message;
  EXPECT_LT((placement->R - R).norm(), 0.02);
  EXPECT_LT((placement->t - t).norm(), 0.002);
  EXPECT_GT(placement->max_m, 0.001);  // the mis-picked point shows in the residual
  EXPECT_LT(placement->max_m, 0.002);
  ASSERT_EQ(placement->residuals_m.size(), model.size());
  EXPECT_EQ(*std::max_element(placement->residuals_m.begin(), placement->residuals_m.end()),
            placement->max_m);
  EXPECT_EQ(std::max_element(placement->residuals_m.begin(), placement->residuals_m.end()) -
                placement->residuals_m.begin(),
            4);  // the mis-picked one
  geom::TriangleMesh mesh;
  mesh.vertices = model;
  mesh.faces.emplace_back(0, 1, 2);
  const geom::TriangleMesh placed = placedMesh(mesh, *placement);
  EXPECT_LT((placed.vertices[3] - (R * model[3] + t)).norm(), 0.002);

  const std::vector<Vec3> three(model.begin(), model.begin() + 3);
  EXPECT_EQ(placeObject(three, std::vector<Vec3>(world.begin(), world.begin() + 3)).error().code,
            ErrorCode::kTooFewPoints);
  EXPECT_EQ(placeObject(model, three).error().code, ErrorCode::kInvalidInput);
  const std::vector<Vec3> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  EXPECT_EQ(placeObject(line, line).error().code, ErrorCode::kDegenerate);
  std::vector<Vec3> bad = model;
  bad[0].x() = std::nan("");
  EXPECT_EQ(placeObject(bad, world).error().code, ErrorCode::kInvalidInput);
}

// A box's model placed 1 degree and 4 mm off (picked corners), refined against the box
// as a route (a) calibration measured it: its front, top and right faces triangulated on
// a grid of their own with 0.5 mm of noise, the table in front of it and the wall behind
// it. The measured points on the box fix all six degrees of freedom.
TEST(ShaderLampRefinement, MeasuredSurfaceFixesAPickedPlacement) {
  const Vec3 size(0.3, 0.2, 0.25);
  const itest::ObjectMesh model = itest::boxMesh(Vec3::Zero(), size, 0.02);
  const Mat3 R0 = Eigen::AngleAxisd(degToRad(25.0), Vec3::UnitZ()).toRotationMatrix();
  const Vec3 t0(0.1, 1.5, 0.875);
  // The three faces the projectors see, in the model's frame, then into the world.
  itest::ObjectMesh seen;
  const Vec3 h = 0.5 * size;
  itest::addGrid(seen, Vec3(-h.x(), -h.y(), -h.z()), Vec3(size.x(), 0, 0), Vec3(0, 0, size.z()), 23,
                 19, 0, Vec2::Zero(), Vec2::Ones());  // front, y = -h
  itest::addGrid(seen, Vec3(-h.x(), -h.y(), h.z()), Vec3(size.x(), 0, 0), Vec3(0, size.y(), 0), 23,
                 15, 1, Vec2::Zero(), Vec2::Ones());  // top
  itest::addGrid(seen, Vec3(h.x(), -h.y(), -h.z()), Vec3(0, size.y(), 0), Vec3(0, 0, size.z()), 15,
                 19, 2, Vec2::Zero(), Vec2::Ones());  // right
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.0005);
  for (Vec3& v : seen.mesh.vertices) v = R0 * v + t0 + Vec3(noise(rng), noise(rng), noise(rng));
  itest::ObjectMesh around;  // the table in front of the box and a wall behind it
  itest::addGrid(around, Vec3(-0.8, 1.05, 0.75), Vec3(1.6, 0, 0), Vec3(0, 0.3, 0), 40, 8, 0,
                 Vec2::Zero(), Vec2::Ones());
  itest::addGrid(around, Vec3(-1, 2.6, 0.5), Vec3(2, 0, 0), Vec3(0, 0, 2), 20, 20, 1, Vec2::Zero(),
                 Vec2::Ones());
  const geom::TriangleMesh measured[] = {seen.mesh, around.mesh};

  ObjectPlacement start;
  start.R = Eigen::AngleAxisd(degToRad(1.0), Vec3(1, -2, 1).normalized()).toRotationMatrix() * R0;
  start.t = t0 + Vec3(0.003, -0.002, 0.0017);
  auto refined = refinePlacement(measured, model.mesh, start);
  ASSERT_TRUE(refined) << refined.error().message;
  const double angle = radToDeg(Eigen::AngleAxisd(refined->placement.R * R0.transpose()).angle());
  const double shift = (refined->placement.t - t0).norm();
  std::printf(
      "refined from %ld of %ld measured points in %d iterations: %.4f deg, %.3f mm off the truth "
      "(moved %.2f mm, turned %.3f deg); residuals %.3f mm RMS\n",
      refined->points, refined->candidates, refined->iterations, angle, 1000 * shift,
      1000 * refined->moved_m, refined->turned_deg, 1000 * refined->placement.rms_m);
  // 0.5 mm of noise over some 400 points a face, levers of about 0.09 m: each axis's
  // turn to 0.5 mm / (0.09 m · 20) = 0.016 deg (one sigma), 0.028 deg over three; the
  // centroid to 0.5 mm / sqrt(400) = 0.025 mm. Bounds at about three sigma.
  EXPECT_LT(angle, 0.08);
  EXPECT_LT(shift, 0.0001);
  EXPECT_NEAR(refined->placement.rms_m, 0.0005, 0.0001);
  EXPECT_GT(refined->points, 800);
  // None of the table's or the wall's: the same pull without them.
  const geom::TriangleMesh box_only[] = {seen.mesh};
  EXPECT_EQ(refinePlacement(box_only, model.mesh, start)->points, refined->points);
  EXPECT_NEAR(refined->turned_deg, 1.0, 0.05);

  EXPECT_TRUE(refined->free.empty());

  // The front face alone fixes the box's distance and tilt to it, not a slide along it or
  // a turn about its normal: those stay as the start had them, and are reported.
  itest::ObjectMesh front;
  itest::addGrid(front, Vec3(-h.x(), -h.y(), -h.z()), Vec3(size.x(), 0, 0), Vec3(0, 0, size.z()),
                 23, 19, 0, Vec2::Zero(), Vec2::Ones());
  for (Vec3& v : front.mesh.vertices) v = R0 * v + t0;
  const geom::TriangleMesh plane[] = {front.mesh};
  const ObjectPlacement shifted{R0, t0 + Vec3(0.003, -0.002, 0.0017), 0, 0, {}};
  auto partial = refinePlacement(plane, model.mesh, shifted);
  ASSERT_TRUE(partial) << partial.error().message;
  ASSERT_EQ(partial->free.size(), 3u);
  const Vec3 normal = R0 * Vec3(0, -1, 0);
  int slides = 0;
  for (const FreeDirection& f : partial->free) {
    if (f.turn) {
      EXPECT_GT(std::abs(f.axis.dot(normal)), 0.999);
    } else {
      ++slides;
      EXPECT_LT(std::abs(f.axis.dot(normal)), 1e-3);
    }
  }
  EXPECT_EQ(slides, 2);
  const Vec3 moved = partial->placement.t - t0, had = shifted.t - t0;
  EXPECT_LT(std::abs(moved.dot(normal)), 1e-6);                                // its distance found
  EXPECT_LT((moved - had - (moved - had).dot(normal) * normal).norm(), 1e-6);  // the rest kept
  const geom::TriangleMesh nothing[] = {around.mesh};
  EXPECT_EQ(refinePlacement(nothing, model.mesh, start).error().code, ErrorCode::kTooFewPoints);
  EXPECT_EQ(refinePlacement(measured, model.mesh, start, {.final_distance_m = 0.05}).error().code,
            ErrorCode::kInvalidInput);
  ObjectPlacement skew = start;
  skew.R(0, 1) += 0.1;
  EXPECT_EQ(refinePlacement(measured, model.mesh, skew).error().code, ErrorCode::kInvalidInput);
  geom::TriangleMesh broken = around.mesh;
  broken.faces.emplace_back(0, 1, 100000);
  const geom::TriangleMesh bad[] = {broken};
  EXPECT_EQ(refinePlacement(bad, model.mesh, start).error().code, ErrorCode::kInvalidInput);
}

// A cylinder seen from one side: its turn about its own axis and its slide along it are
// free, and the turn is reported about that axis (not about the seen points' centroid).
TEST(ShaderLampRefinement, ACylinderTurnsFreelyAboutItsOwnAxis) {
  const Vec3 base(0.2, 1.5, 0.7);
  const double radius = 0.1, height = 0.3;
  // Side `from`..`to` radians of a cylinder about +Z through `base`, `n` segments.
  const auto cylinder = [&](double from, double to, int n, int stacks) {
    geom::TriangleMesh m;
    for (int j = 0; j <= stacks; ++j)
      for (int i = 0; i <= n; ++i) {
        const double a = from + (to - from) * i / n;
        m.vertices.push_back(base +
                             Vec3(radius * std::cos(a), radius * std::sin(a), height * j / stacks));
      }
    for (int j = 0; j < stacks; ++j)
      for (int i = 0; i < n; ++i) {
        const int v = j * (n + 1) + i;
        m.faces.emplace_back(v, v + 1, v + n + 2);
        m.faces.emplace_back(v, v + n + 2, v + n + 1);
      }
    return m;
  };
  const geom::TriangleMesh model = cylinder(0, 2 * std::numbers::pi, 360, 6);
  // Its front (facing -Y) measured on another grid.
  const geom::TriangleMesh measured[] = {
      cylinder(-0.85 * std::numbers::pi, -0.15 * std::numbers::pi, 90, 12)};
  ObjectPlacement start;
  start.t = Vec3(0, -0.003, 0);  // 3 mm nearer the projector
  auto refined = refinePlacement(measured, model, start);
  ASSERT_TRUE(refined) << refined.error().message;
  EXPECT_LT(refined->placement.t.norm(), 2e-4);  // the distance found
  ASSERT_EQ(refined->free.size(), 2u);
  for (const FreeDirection& f : refined->free) {
    EXPECT_GT(std::abs(f.axis.z()), 0.999);
    if (!f.turn) continue;
    const Vec3 off = f.through - base;
    EXPECT_LT(Vec2(off.x(), off.y()).norm(), 0.002) << f.through.transpose();
  }
  EXPECT_NE(refined->free[0].turn, refined->free[1].turn);
}

}  // namespace
}  // namespace procam::lamps
