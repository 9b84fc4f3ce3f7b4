#pragma once
// Checks of one display across projectors on a curved surface against the virtual rig's
// TRUE projectors and surface, shared by the cylinder (static viewer, lookup warps;
// tracked viewer, two-pass) and dome-master tests. Each output is described by its lookup from its
// projector's pixels to content pixels (for the two-pass path: the same lookup rebuilt
// from the viewer matrix it drew with and the calibrated surface).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "blend/curved_display.hpp"
#include "blend/rig_tiles.hpp"
#include "content/mesh_content.hpp"
#include "daemon_harness.hpp"
#include "render/cpu_renderer.hpp"
#include "render/post_render_warp.hpp"
#include "render/render_setup.hpp"
#include "render/viewer_view.hpp"
#include "render/warp_map.hpp"
#include "rig/rig_model.hpp"
#include "sim/scene.hpp"

namespace procam::itest {

// d lookup / d pixel at u, numerically.
inline std::optional<Eigen::Matrix2d> lookupJacobian(const render::WarpGrid& g, const Vec2& u) {
  const auto x0 = render::gridSource(g, u - Vec2(0.5, 0)),
             x1 = render::gridSource(g, u + Vec2(0.5, 0));
  const auto y0 = render::gridSource(g, u - Vec2(0, 0.5)),
             y1 = render::gridSource(g, u + Vec2(0, 0.5));
  if (!x0 || !x1 || !y0 || !y1) return std::nullopt;
  Eigen::Matrix2d J;
  J.col(0) = *x1 - *x0;
  J.col(1) = *y1 - *y0;
  return J;
}

// The pixel of a projector whose lookup shows content pixel c: Newton from the nearest node.
inline std::optional<Vec2> showing(const render::WarpGrid& g, const Vec2& c) {
  double best = 1e300;
  Vec2 u;
  for (int j = 0; j < g.rows; ++j) {
    for (int i = 0; i < g.cols; ++i) {
      const Vec2& s = g.at(i, j);
      if (s.x() == render::kOutside) continue;
      if (const double d = (s - c).squaredNorm(); d < best) {
        best = d;
        u = g.node(i, j);
      }
    }
  }
  if (best > 4 * g.step.squaredNorm() * 16) return std::nullopt;  // c is not in this image
  for (int it = 0; it < 8; ++it) {
    const auto at = render::gridSource(g, u);
    const auto J = lookupJacobian(g, u);
    if (!at || !J) return std::nullopt;
    u += J->inverse() * (c - *at);
  }
  const auto at = render::gridSource(g, u);
  if (!at || (*at - c).norm() > 1e-3) return std::nullopt;
  return u;
}

struct Calibrated {
  rig::RigModel rig;
  std::vector<geom::MeshIntersector> surfaces;      // per output, in the order asked
  std::vector<render::SurfaceMesh> meshes;          // the same, as the two-pass path draws them
  std::vector<blend::SurfaceProjector> projectors;  // with their post-rendering warps
  std::vector<std::shared_ptr<const render::PostRenderWarp>> warps;
  std::vector<std::optional<blend::ProjectorResponse>> responses;
};

// The rig model calibrate wrote, with each projector's mesh, in `outputs` order.
inline void readCalibrated(const std::string& state_dir, const std::vector<std::string>& outputs,
                           Calibrated& out) {
  std::ifstream in(state_dir + "/rig.json");
  std::stringstream text;
  text << in.rdbuf();
  auto rig = rig::rigFromText(text.str(), "rig.json");
  ASSERT_TRUE(rig) << rig.error().message;
  out.rig = std::move(*rig);
  out.surfaces.reserve(outputs.size());
  for (const std::string& name : outputs) {
    const rig::RigProjector* p = out.rig.projectorForOutput(name);
    ASSERT_TRUE(p && p->pose_known) << name;
    ASSERT_TRUE(out.rig.surface.meshes.count(p->name)) << name;
    auto mesh = content::loadMeshContent(state_dir + "/" + out.rig.surface.meshes.at(p->name));
    ASSERT_TRUE(mesh) << mesh.error().message;
    render::SurfaceMesh drawn;
    drawn.vertices = mesh->mesh.vertices;
    for (const auto& f : mesh->mesh.faces) drawn.triangles.push_back({f.x(), f.y(), f.z()});
    out.meshes.push_back(std::move(drawn));
    auto intersector = geom::MeshIntersector::build(std::move(mesh->mesh));
    ASSERT_TRUE(intersector);
    out.surfaces.push_back(std::move(*intersector));
  }
  for (std::size_t t = 0; t < outputs.size(); ++t) {
    const rig::RigProjector* p = out.rig.projectorForOutput(outputs[t]);
    auto warp = render::projectorPostRenderWarp(p->model(), &out.surfaces[t].mesh());
    ASSERT_TRUE(warp) << warp.error().message;
    out.warps.push_back(*warp);
    std::shared_ptr<const render::WarpGrid> grid;
    if (*warp) grid = std::shared_ptr<const render::WarpGrid>(*warp, &(*warp)->grid);
    out.projectors.push_back(
        {&out.surfaces[t], p->model().projectionMatrix(), cv::Size(p->width, p->height), grid});
    out.responses.push_back(blend::projectorResponse(*p));
  }
}

// The TRUE rig: each projector's model, and the surfaces its light meets.
struct TrueRig {
  const sim::Scene* scene = nullptr;
  std::vector<geom::CameraModel> projectors;  // in the outputs' order

  // The TRUE surface point TRUE projector m's pixel u lights.
  std::optional<Vec3> lit(std::size_t m, const Vec2& u) const {
    auto ray = projectors[m].backproject(u);  // through the lens
    if (!ray) return std::nullopt;
    auto hit = scene->world().intersect(*ray);
    return hit ? std::optional<Vec3>(hit->hit.point) : std::nullopt;
  }
  bool inFrame(std::size_t m, const Vec2& u, double margin) const {
    const auto& p = projectors[m];
    return u.x() >= -0.5 + margin && u.y() >= -0.5 + margin && u.x() <= p.width - 0.5 - margin &&
           u.y() <= p.height - 0.5 - margin;
  }
};

struct SeamFigures {
  double rms = 0, worst = 0;
  int pairs = 0;
};

// Where one projector puts a content point on the TRUE surface, how far (its own
// pixels) the other projectors lighting that point are from showing the same content
// point: at every lookup node inside the content.
inline SeamFigures seamsOnTheTrueSurface(const std::vector<render::WarpGrid>& lookup,
                                         const TrueRig& truth, cv::Size content) {
  SeamFigures out;
  double sq = 0;
  for (std::size_t m = 0; m < lookup.size(); ++m) {
    const auto& g = lookup[m];
    for (int j = 0; j < g.rows; ++j) {
      for (int i = 0; i < g.cols; ++i) {
        const Vec2 c = g.at(i, j);
        if (c.x() < 0 || c.y() < 0 || c.x() > content.width - 1 || c.y() > content.height - 1)
          continue;
        const auto X = truth.lit(m, g.node(i, j));
        if (!X) continue;
        for (std::size_t n = 0; n < lookup.size(); ++n) {
          if (n == m) continue;
          const auto q = truth.projectors[n].project(*X);
          if (!q || !truth.inFrame(n, *q, 1)) continue;
          const auto other = render::gridSource(lookup[n], *q);
          const auto J = lookupJacobian(lookup[n], *q);
          if (!other || !J) continue;
          const double e = (J->inverse() * (c - *other)).norm();
          sq += e * e;
          out.worst = std::max(out.worst, e);
          ++out.pairs;
        }
      }
    }
  }
  out.rms = out.pairs ? std::sqrt(sq / out.pairs) : 0;
  return out;
}

// Straight lines of the content as the viewer (V: a pinhole at the eye, world -> content
// pixels) sees them: where the TRUE surface point showing content pixel c appears in V,
// along every 10th row and column; the largest distance from a fitted straight line.
inline double bentOnTheTrueSurface(const std::vector<render::WarpGrid>& lookup,
                                   const TrueRig& truth, const Mat34& V, cv::Size content) {
  double bent = 0;
  auto straightness = [&](bool rows, double at) {
    std::vector<Vec2> seen;  // (along, across) in content px
    const int n = rows ? content.width : content.height;
    for (int k = 10; k < n - 10; k += 20) {
      const Vec2 c = rows ? Vec2(k, at) : Vec2(at, k);
      for (std::size_t m = 0; m < lookup.size(); ++m) {
        const auto u = showing(lookup[m], c);
        if (!u || !truth.inFrame(m, *u, 1)) continue;
        const auto X = truth.lit(m, *u);
        if (!X) continue;
        const Vec2 s = (V * X->homogeneous()).hnormalized();
        seen.push_back(rows ? Vec2(k, s.y()) : Vec2(k, s.x()));
      }
    }
    EXPECT_GT(seen.size(), size_t(n / 25));
    if (seen.size() < 3) return;
    // Least-squares line across = a + b along; the largest residual.
    Eigen::MatrixXd A(seen.size(), 2);
    Eigen::VectorXd b(seen.size());
    for (std::size_t i = 0; i < seen.size(); ++i) {
      A(i, 0) = 1;
      A(i, 1) = seen[i].x();
      b(i) = seen[i].y();
    }
    const Eigen::VectorXd line = A.colPivHouseholderQr().solve(b);
    bent = std::max(bent, (A * line - b).cwiseAbs().maxCoeff());
  };
  for (int k = 1; k < 10; ++k) {
    straightness(true, content.height * k / 10.0);
    straightness(false, content.width * k / 10.0);
  }
  return bent;
}

// An output of a route (a) calibrate reply: its figures printed (nodes triangulated,
// reprojection, its centre against the TRUE projector's, its response's gamma), a mesh
// surface and the gamma within 0.05 of the TRUE one.
inline void checkRouteAOutput(const nlohmann::json& o, const geom::CameraModel& truth,
                              double true_gamma) {
  const std::string name = o["output"].get<std::string>();
  const Vec3 centre(o["position"][0].get<double>(), o["position"][1].get<double>(),
                    o["position"][2].get<double>());
  const double centre_mm = 1000 * (centre - truth.pose.center()).norm();
  std::printf(
      "[ figures  ] %s: route a, %d nodes triangulated, reprojection %.4f px, centre %.2f mm "
      "off, response gamma %.3f (true %.1f)\n",
      name.c_str(), o["triangulated"].get<int>(),
      o["projector"]["reprojection_rms_px"].get<double>(), centre_mm,
      o["response"]["response_gamma"].get<double>(), true_gamma);
  EXPECT_EQ(o["surface_type"], "mesh") << name;
  EXPECT_NEAR(o["response"]["response_gamma"].get<double>(), true_gamma, 0.05) << name;
}

// What status says once content is drawn across the surface: its `outputs.display`
// entry and, per output drawing its share by a lookup warp, its `outputs.shown[]` entry.
struct LookupDisplay {
  nlohmann::json display;
  std::map<std::string, nlohmann::json> shown;
  bool ready = false;  // the display ready and `outputs` outputs drawing it
};

// Loads the image `png` as content and waits (60 s, scaled by kSlowdown) until `outputs`
// outputs draw it by their lookup warps from a ready display.
inline LookupDisplay loadOntoLookupDisplay(Connection& c, const std::string& png,
                                           std::size_t outputs) {
  LookupDisplay out;
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}}, kSlowdown * 30s);
  if (!load || (*load)["class"] != "CONTENT") {
    ADD_FAILURE() << "content load: " << (load ? load->dump() : "no answer");
    return out;
  }
  out.ready = eventually(
      [&] {
        auto s = c.call({{"cmd", "status"}});
        if (!s) return false;
        out.display = (*s)["outputs"].value("display", nlohmann::json());
        out.shown.clear();
        if (!out.display.is_object() || out.display.value("state", "") != "ready") return false;
        for (const nlohmann::json& o : (*s)["outputs"]["shown"]) {
          if (o["source"] == "content" && o.value("path", "") == "lookup-warp" &&
              o.contains("display")) {
            out.shown[o["name"].get<std::string>()] = o;
          }
        }
        return out.shown.size() == outputs;
      },
      kSlowdown * 60s);
  return out;
}

// White content drawn by output `t` through its lookup warp and blend, as the daemon
// draws it (BGR, 8 bits), after checking it against the daemon's statistics of that
// output (`shown`: its status `outputs.shown[]` entry): lit fraction and mean.
inline cv::Mat whiteThroughLookup(const render::WarpGrid& lookup, const blend::BlendTables& blend,
                                  std::size_t t, cv::Size output, cv::Size content,
                                  const nlohmann::json& shown, const std::string& name) {
  const cv::Mat white(content, CV_8UC4, cv::Scalar::all(255));
  render::RenderSetup setup;
  setup.output_size = output;
  setup.content_size = content;
  setup.path = render::RenderPath::kLookupWarp;
  setup.lookup = lookup;
  setup.final_stage.alpha = blend.alpha[t];
  setup.final_stage.weight_lut = blend.weight_lut[t];
  render::CpuRenderer cpu;
  EXPECT_TRUE(cpu.configure(setup)) << name;
  EXPECT_TRUE(cpu.render({&white, nullptr, 1})) << name;
  cv::Mat bgr, grey;
  cv::cvtColor(cpu.frame(), bgr, cv::COLOR_RGBA2BGR);
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  const double lit = cv::countNonZero(grey) / double(grey.total());
  const double mean = cv::mean(bgr)[0];
  std::printf("[ figures  ] %s: lit %.5f (daemon %.5f), mean %.3f (daemon %.3f)\n", name.c_str(),
              lit, shown["lit_fraction"].get<double>(), mean, shown["mean_rgb"][0].get<double>());
  EXPECT_NEAR(lit, shown["lit_fraction"].get<double>(), 1e-4) << name;
  EXPECT_NEAR(mean, shown["mean_rgb"][0].get<double>(), 0.01) << name;
  return bgr;
}

// White seen by the viewer (a linear-light CV_32FC3 image): over the pixels `inside`
// takes (each with its right and lower neighbours), the largest relative step between
// neighbouring pixels, the darkest and brightest, and the first unlit pixel if any.
struct ViewerLight {
  double step = 0, lo = 1e300, hi = 0;
  Vec2 at = Vec2::Zero();  // the pixel of the largest step
  long pixels = 0;
  std::optional<Vec2> unlit;
  double uniformity() const { return hi > 0 ? lo / hi : 0; }
};

template <typename Inside>
ViewerLight viewerLight(const cv::Mat& view, Inside inside) {
  ViewerLight out;
  for (int y = 0; y + 1 < view.rows; ++y) {
    for (int x = 0; x + 1 < view.cols; ++x) {
      if (!inside(x, y) || !inside(x + 1, y) || !inside(x, y + 1)) continue;
      const double l = view.at<cv::Vec3f>(y, x)[0];
      if (!(l > 0)) {
        if (!out.unlit) out.unlit = Vec2(x, y);
        continue;
      }
      const double st = std::max(std::abs(view.at<cv::Vec3f>(y, x + 1)[0] - l) / l,
                                 std::abs(view.at<cv::Vec3f>(y + 1, x)[0] - l) / l);
      if (st > out.step) {
        out.step = st;
        out.at = Vec2(x, y);
      }
      out.lo = std::min(out.lo, l);
      out.hi = std::max(out.hi, l);
      ++out.pixels;
    }
  }
  return out;
}

}  // namespace procam::itest
