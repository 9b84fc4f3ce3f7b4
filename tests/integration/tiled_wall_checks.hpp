#pragma once
// What the tiled-wall tests share: the virtual rig's tiled_wall and wall_views scenes
// calibrated over the socket, the display the daemon reports, and the checks against the
// TRUE projectors and wall (seams, the light the viewer and a camera see).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "blend/feather.hpp"
#include "blend/response.hpp"
#include "blend/rig_tiles.hpp"
#include "blend/tiled_display.hpp"
#include "daemon_harness.hpp"
#include "render/cpu_renderer.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"
#include "unit/calibration/plane_corners.hpp"

namespace procam::itest {

inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;
inline const char* const kOutputs[] = {"proj_tl", "proj_tr", "proj_bl", "proj_br"};
inline const json kWallPlane = {0.0, 1.0, 0.0, -3.0};  // y = 3, as measured by the installer

inline Mat3 rowMajor3(const json& j) {
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = j[i].get<double>();
  return m;
}

inline bool inFrame(const geom::CameraModel& p, const Vec2& x, double margin) {
  return x.x() >= -0.5 + margin && x.y() >= -0.5 + margin && x.x() <= p.width - 0.5 - margin &&
         x.y() <= p.height - 0.5 - margin;
}

// Where projector pixel `x` of the TRUE projector meets the TRUE wall y = 3.
inline Vec3 onTheWall(const geom::CameraModel& p, const Vec2& x) {
  const Mat3 Rt = p.pose.R.transpose();
  const Vec3 centre = p.pose.center();
  const Vec3 dir = Rt * p.K.matrix().inverse() * x.homogeneous();
  return centre + dir * ((3.0 - centre.y()) / dir.y());
}

// calibrate of every projector on the wall's plane through `cameras`: Gray + 3-step phase,
// nodes every 8 px, no settle frames (the virtual rig shows a frame at once); id 1.
inline json calibrateEveryProjector(const json& cameras) {
  return {{"cmd", "calibrate"},  {"id", 1},
          {"projectors", "all"}, {"cameras", cameras},
          {"plane", kWallPlane}, {"mode", "gray+phase"},
          {"phase_steps", 3},    {"grid", 8},
          {"settle_frames", 0}};
}

// The homographies the outputs draw a kW x kH content with once `count` of them show
// their tile of the display (`display`: the keystone's display record); fewer when they
// do not within 30 s.
inline std::map<std::string, Mat3> tiles(Connection& c, int kW, int kH, std::size_t count,
                                         json& display) {
  std::map<std::string, Mat3> H;
  eventually(
      [&] {
        auto s = c.call({{"cmd", "status"}});
        if (!s) return false;
        display = (*s)["keystone"].value("display", json());
        H.clear();
        for (const json& o : (*s)["outputs"]["shown"]) {
          if (o["source"] == "content" && o.contains("display") && o.contains("homography") &&
              display.is_object() && display.value("content_size", json()) == json({kW, kH})) {
            H[o["name"].get<std::string>()] = rowMajor3(o["homography"]);
          }
        }
        return H.size() == count;
      },
      30s);
  return H;
}

// Seams: a content point (every 10 content px) lit by two projectors lands, through the
// TRUE rig, where the other projector puts the same content point; the distance in the
// other projector's pixels.
struct Seams {
  double rms = 0, max = 0;
  int pairs = 0;
};
inline Seams seamsOnTheTruth(const std::map<std::string, Mat3>& H,
                             const std::map<std::string, geom::CameraModel>& truth, int kW,
                             int kH) {
  Seams out;
  double sq = 0;
  for (int y = 0; y < kH; y += 10) {
    for (int x = 0; x < kW; x += 10) {
      const Vec3 content(x, y, 1);
      for (const auto& [a, Ha] : H) {
        const geom::CameraModel& ta = truth.at(a);
        const Vec2 pa = (Ha * content).hnormalized();
        if (!inFrame(ta, pa, 1)) continue;
        const Vec3 wall = onTheWall(ta, pa);
        for (const auto& [b, Hb] : H) {
          if (a >= b) continue;
          const geom::CameraModel& tb = truth.at(b);
          const Vec2 pb = (Hb * content).hnormalized();
          if (!inFrame(tb, pb, 1)) continue;
          const double e = (*tb.project(wall) - pb).norm();
          sq += e * e;
          out.max = std::max(out.max, e);
          ++out.pairs;
        }
      }
    }
  }
  out.rms = out.pairs ? std::sqrt(sq / out.pairs) : 0;
  std::printf("[ figures  ] seams: %d content points lit twice, RMS %.3f px, max %.3f px\n",
              out.pairs, out.rms, out.max);
  return out;
}

// The display as the daemon reports it: per output its homography, the display
// rectangle and basis, and every image's footprint.
struct Reported {
  keystone::AxisRect rect;
  geom::PlaneBasis basis;  // the display's, world
  std::map<std::string, Mat3> H;
  std::map<std::string, std::array<Vec2, 4>> footprint;
};

inline Reported reported(const json& display, const std::map<std::string, Mat3>& H) {
  Reported r;
  r.H = H;
  r.rect.centre = Vec2(display["rect_m"]["centre"][0].get<double>(),
                       display["rect_m"]["centre"][1].get<double>());
  r.rect.half_width = 0.5 * display["rect_m"]["size"][0].get<double>();
  r.rect.half_height = 0.5 * display["rect_m"]["size"][1].get<double>();
  auto vec = [&](const char* key) {
    const json& v = display["basis"][key];
    return Vec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
  };
  r.basis.origin = vec("origin");
  r.basis.u = vec("u");
  r.basis.v = vec("v");
  for (const json& t : display["tiles"]) {
    const std::string name = t["output"].get<std::string>();
    for (int k = 0; k < 4; ++k) {
      r.footprint[name][k] =
          Vec2(t["footprint_m"][k][0].get<double>(), t["footprint_m"][k][1].get<double>());
    }
  }
  return r;
}

// White content through each output's homography and feathering weights (the daemon's
// render setup rebuilt from what it reports) with the assumed gamma 2.2 and no
// photometric matching, lit by the TRUE projectors (their own gamma and brightness)
// and seen from the scene's viewer in linear light: the largest relative step between
// neighbouring viewer pixels over the display (inset by 3 %) and its uniformity
// (min / max): what matching starts from.
struct Luminance {
  double step = 0, uniformity = 0;
  Vec2 at = Vec2::Zero();  // viewer pixel of the largest step
};
inline Luminance unmatchedWhiteSeenByTheViewer(const sim::Scene& scene,
                                               const sim::SceneState& state, const Reported& r,
                                               int kW, int kH) {
  const Mat3 c2w = blend::contentToWall(r.rect, kW, kH);
  std::vector<blend::FeatherTile> tiles;
  std::vector<std::string> names;
  for (const auto& [name, H] : r.H) {
    names.push_back(name);
    tiles.push_back({r.footprint.at(name), H * c2w.inverse(), 1280, 800});
  }
  auto weights = blend::featherWeights(tiles);
  EXPECT_TRUE(weights);
  if (!weights) return {};
  const cv::Mat white(kH, kW, CV_8UC4, cv::Scalar::all(255));
  sim::Framebuffers shown;
  for (std::size_t t = 0; t < names.size(); ++t) {
    render::RenderSetup setup;
    setup.output_size = cv::Size(1280, 800);
    setup.content_size = cv::Size(kW, kH);
    setup.homography = r.H.at(names[t]);
    setup.final_stage.alpha = blend::alphaMask((*weights)[t]);
    setup.final_stage.weight_lut = *blend::weightLut(2.2, 1.0);
    render::CpuRenderer cpu;
    EXPECT_TRUE(cpu.configure(setup));
    EXPECT_TRUE(cpu.render({&white, nullptr, 1}));
    cv::Mat bgr;
    cv::cvtColor(cpu.frame(), bgr, cv::COLOR_RGBA2BGR);
    shown[names[t]] = bgr;
  }
  auto lit = sim::Renderer::create(scene, state, shown);
  EXPECT_TRUE(lit);
  if (!lit) return {};
  const cv::Mat view = lit->renderViewer(4);
  // Viewer pixels whose wall point lies inside the inset display rectangle.
  const geom::CameraModel& eye = state.viewer;
  Luminance out;
  double lo = 1e9, hi = 0;
  auto inside = [&](int x, int y) {
    auto ray = eye.backproject(Vec2(x, y));
    if (!ray || !(ray->dir.y() > 0)) return false;
    const Vec3 p = ray->origin + ray->dir * ((3.0 - ray->origin.y()) / ray->dir.y());
    const Vec2 q = r.basis.toPlane(p) - r.rect.centre;
    return std::abs(q.x()) < 0.97 * r.rect.half_width &&
           std::abs(q.y()) < 0.97 * r.rect.half_height;
  };
  for (int y = 0; y + 1 < view.rows; ++y) {
    for (int x = 0; x + 1 < view.cols; ++x) {
      if (!inside(x, y) || !inside(x + 1, y + 1)) continue;
      const double l = view.at<cv::Vec3f>(y, x)[0];
      const double right = view.at<cv::Vec3f>(y, x + 1)[0], down = view.at<cv::Vec3f>(y + 1, x)[0];
      const double st = std::max(std::abs(right - l) / l, std::abs(down - l) / l);
      if (st > out.step) {
        out.step = st;
        out.at = Vec2(x, y);
      }
      lo = std::min(lo, l);
      hi = std::max(hi, l);
    }
  }
  out.uniformity = hi > 0 ? lo / hi : 0;
  return out;
}

// The daemon's own frames on the wall, through the virtual rig's camera `camera` (linear,
// 8-bit, 1 DN read noise): the camera image over the display (inset by 3 %, wall
// points from the TRUE camera and wall) averaged in blocks of 12 x 12 pixels (about
// 25 content pixels: shot and read noise then move a block's mean by under 0.2 %), the
// largest relative step between neighbouring blocks and the uniformity (min / max).
inline Luminance whiteSeenByTheCamera(Connection& c, const sim::SceneState& state,
                                      const Reported& r, const std::string& camera) {
  Luminance out;
  auto shot = c.call({{"cmd", "snapshot"}, {"camera", camera}}, 30s);
  EXPECT_TRUE(shot);
  if (!shot) return out;
  EXPECT_EQ((*shot)["class"], "SNAPSHOT") << shot->dump();
  EXPECT_LT((*shot).value("saturated_pct", 100.0), 0.01) << shot->dump();
  const cv::Mat img = cv::imread((*shot).value("path", ""), cv::IMREAD_UNCHANGED);
  EXPECT_FALSE(img.empty());
  if (img.empty()) return out;
  const geom::CameraModel* model = nullptr;
  for (const auto& cam : state.cameras) {
    if (cam.spec.name == camera) model = &cam.model;
  }
  EXPECT_NE(model, nullptr);
  if (!model) return out;
  auto inside = [&](int x, int y) {
    auto ray = model->backproject(Vec2(x, y));
    if (!ray || !(ray->dir.y() > 0)) return false;
    const Vec3 p = ray->origin + ray->dir * ((3.0 - ray->origin.y()) / ray->dir.y());
    const Vec2 q = r.basis.toPlane(p) - r.rect.centre;
    return std::abs(q.x()) < 0.97 * r.rect.half_width &&
           std::abs(q.y()) < 0.97 * r.rect.half_height;
  };
  constexpr int kBlock = 12;
  const int bx = img.cols / kBlock, by = img.rows / kBlock;
  cv::Mat mean(by, bx, CV_64FC1, cv::Scalar(-1));
  for (int j = 0; j < by; ++j) {
    for (int i = 0; i < bx; ++i) {
      const int x0 = i * kBlock, y0 = j * kBlock, x1 = x0 + kBlock - 1, y1 = y0 + kBlock - 1;
      if (!inside(x0, y0) || !inside(x1, y0) || !inside(x0, y1) || !inside(x1, y1)) continue;
      mean.at<double>(j, i) = cv::mean(img(cv::Rect(x0, y0, kBlock, kBlock)))[0];
    }
  }
  double lo = 1e9, hi = 0;
  for (int j = 0; j < by; ++j) {
    for (int i = 0; i < bx; ++i) {
      const double l = mean.at<double>(j, i);
      if (l < 0) continue;
      EXPECT_GT(l, 5) << "an unlit block inside the display at camera pixel " << i * kBlock << ","
                      << j * kBlock;
      lo = std::min(lo, l);
      hi = std::max(hi, l);
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (i + dx >= bx || j + dy >= by) continue;
        const double n = mean.at<double>(j + dy, i + dx);
        if (n < 0) continue;
        const double st = std::abs(n - l) / l;
        if (st > out.step) {
          out.step = st;
          out.at = Vec2((i + 0.5) * kBlock, (j + 0.5) * kBlock);
        }
      }
    }
  }
  out.uniformity = hi > 0 ? lo / hi : 0;
  return out;
}

// A projector's TRUE white across its frame on the wall y = 3: brightness cos θ / d²
// (the virtual rig's point source, [Raskar02] §5.2.4).
inline double trueWhite(const sim::ProjectorSpec& spec, const geom::CameraModel& p,
                        const Vec2& px) {
  const Vec3 to_lamp = p.pose.center() - onTheWall(p, px);
  const double d = to_lamp.norm();
  return spec.brightness * (-to_lamp.y() / d) / (d * d);
}

}  // namespace procam::itest
