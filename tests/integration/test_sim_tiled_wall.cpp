// Four projectors on one flat wall shown as one display, end to end on the virtual
// rig over the socket only: tiled_wall (2x2 projectors of 1280x800 with unmatched
// responses, two cameras) with nothing handed over but the cameras' calibration
// (TruthParts::kCamerasOnly) and the wall's plane as an installer measures it.
// calibrate (route b′) maps each projector onto the wall, `keystone rig on` makes one
// display of them ([Raskar02] §4.2.4) with feathered overlaps (eq. 4.3), and the
// homographies the outputs draw with are judged with the TRUE projectors and wall.
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
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
const char* const kOutputs[] = {"proj_tl", "proj_tr", "proj_bl", "proj_br"};
const json kWallPlane = {0.0, 1.0, 0.0, -3.0};  // y = 3, as measured by the installer

Mat3 rowMajor3(const json& j) {
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = j[i].get<double>();
  return m;
}

bool inFrame(const geom::CameraModel& p, const Vec2& x, double margin) {
  return x.x() >= -0.5 + margin && x.y() >= -0.5 + margin && x.x() <= p.width - 0.5 - margin &&
         x.y() <= p.height - 0.5 - margin;
}

// Where projector pixel `x` of the TRUE projector meets the TRUE wall y = 3.
Vec3 onTheWall(const geom::CameraModel& p, const Vec2& x) {
  const Mat3 Rt = p.pose.R.transpose();
  const Vec3 centre = p.pose.center();
  const Vec3 dir = Rt * p.K.matrix().inverse() * x.homogeneous();
  return centre + dir * ((3.0 - centre.y()) / dir.y());
}

// calibrate of every projector on the wall's plane through `cameras`: Gray + 3-step phase,
// nodes every 8 px, no settle frames (the virtual rig shows a frame at once); id 1.
json calibrateEveryProjector(const json& cameras) {
  return {{"cmd", "calibrate"},  {"id", 1},
          {"projectors", "all"}, {"cameras", cameras},
          {"plane", kWallPlane}, {"mode", "gray+phase"},
          {"phase_steps", 3},    {"grid", 8},
          {"settle_frames", 0}};
}

// The homographies the outputs draw a kW x kH content with once `count` of them show
// their tile of the display (`display`: the keystone's display record); fewer when they
// do not within 30 s.
std::map<std::string, Mat3> tiles(Connection& c, int kW, int kH, std::size_t count, json& display) {
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
Seams seamsOnTheTruth(const std::map<std::string, Mat3>& H,
                      const std::map<std::string, geom::CameraModel>& truth, int kW, int kH) {
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

Reported reported(const json& display, const std::map<std::string, Mat3>& H) {
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
Luminance unmatchedWhiteSeenByTheViewer(const sim::Scene& scene, const sim::SceneState& state,
                                        const Reported& r, int kW, int kH) {
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
Luminance whiteSeenByTheCamera(Connection& c, const sim::SceneState& state, const Reported& r,
                               const std::string& camera) {
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
double trueWhite(const sim::ProjectorSpec& spec, const geom::CameraModel& p, const Vec2& px) {
  const Vec3 to_lamp = p.pose.center() - onTheWall(p, px);
  const double d = to_lamp.norm();
  return spec.brightness * (-to_lamp.y() / d) / (d * d);
}

TEST(SimTiledWall, FourProjectorsCalibratedIntoOneSeamlessDisplay) {
  auto scene = sim::resolveScene("tiled_wall");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  std::map<std::string, geom::CameraModel> truth;
  std::map<std::string, sim::ProjectorSpec> spec;
  for (const auto& p : state.projectors) {
    truth[p.spec.name] = p.model;
    spec[p.spec.name] = p.spec;
  }
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "tiled_wall", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  // Malformed projector lists are refused before anything is shown.
  for (const json& bad : {json::array(), json({"proj_tl", "proj_tl"}), json("some"), json(7)}) {
    auto r = c.call({{"cmd", "calibrate"}, {"projectors", bad}, {"plane", kWallPlane}});
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["code"], "bad-argument") << bad.dump() << " " << r->dump();
    EXPECT_NE((*r)["message"].get<std::string>().find("\"projectors\" must be"), std::string::npos)
        << r->dump();
  }
  auto both = c.call({{"cmd", "calibrate"}, {"projectors", "all"}, {"output", "proj_tl"}});
  ASSERT_TRUE(both);
  EXPECT_EQ((*both)["code"], "bad-argument") << both->dump();
  EXPECT_NE((*both)["message"].get<std::string>().find("either"), std::string::npos)
      << both->dump();

  // Every projector, one after the other, through the camera that sees the whole wall;
  // one rig model written at the end.
  const auto t0 = std::chrono::steady_clock::now();
  auto started = c.call(calibrateEveryProjector(json({"cam_a"})));
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["outputs"], json({"proj_tl", "proj_tr", "proj_bl", "proj_br"}));
  auto done = finalReply(c, 1, 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  ASSERT_EQ((*done)["outputs"].size(), 4u) << done->dump();
  for (const json& o : (*done)["outputs"]) {
    std::printf("[ figures  ] %s: collineation RMS %.4f projector px, %d nodes\n",
                o["output"].get<std::string>().c_str(),
                o["homography"]["rms_projector_px"].get<double>(),
                o["homography"]["inliers"].get<int>());
    // Gray + phase decodes within 0.1 projector px RMS (ARCHITECTURE.md).
    EXPECT_LT(o["homography"]["rms_projector_px"].get<double>(), 0.15);
    // The response from the grey ramp, through a linear camera: its mean over some
    // 100k pixels at levels of 5-170 units fixes gamma to about 0.01; 0.05 allowed.
    const std::string name = o["output"].get<std::string>();
    const double gamma = o["response"]["response_gamma"].get<double>();
    std::printf("[ figures  ] %s: response gamma %.4f (true %.1f), white %.1f, black %.2f\n",
                name.c_str(), gamma, spec[name].gamma, o["response"]["white"].get<double>(),
                o["response"]["black"].get<double>());
    EXPECT_NEAR(gamma, spec[name].gamma, 0.05) << name;
  }
  EXPECT_EQ((*done)["rig"]["projectors"], 4);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Every image overlaps every other in the middle of the wall: one projector at a time.
  EXPECT_EQ((*done)["scan"]["batches"].size(), 4u) << done->dump();
  std::printf("[ figures  ] four projectors calibrated in %.1f s (%d captures, %zu scan batches)\n",
              seconds, (*done)["scan"]["captures"].get<int>(), (*done)["scan"]["batches"].size());

  // A 16:9 white slide on the one display.
  constexpr int kW = 1600, kH = 900;
  const std::string png = contentFile(dir, "slide.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255))));
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}}, 30s);
  ASSERT_TRUE(load);
  ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
  auto on = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(on);
  ASSERT_EQ((*on)["class"], "KEYSTONE") << on->dump();

  // Every output draws its tile of the display.
  json display;
  std::map<std::string, Mat3> H = tiles(c, kW, kH, 4, display);
  ASSERT_EQ(H.size(), 4u) << display.dump() << "\n" << d.log();
  EXPECT_EQ(display["outputs"].size(), 4u);
  // Matched per pixel: every projector's white across its frame, measured by cam_a at
  // calibration, is the TRUE brightness cos θ / d² times one factor (the camera's units
  // and the wall's albedo) within 2 %: each node averages over 100 camera pixels (noise
  // 0.1 %); nodes within two of the frame's edge, where the camera's blur and the
  // fill-in from seen neighbours reach, are not judged.
  EXPECT_EQ(display["blend"]["response"], "measured") << display.dump();
  const json& matching = display["blend"]["photometric"];
  ASSERT_EQ(matching["matching"], "per-pixel") << display.dump();
  std::printf(
      "[ figures  ] matching: uniformity %.3f before, %.3f after, light kept %.3f, "
      "largest target step %.4f %% per content px\n",
      matching["uniformity_before"].get<double>(), matching["uniformity_after"].get<double>(),
      matching["light_kept"].get<double>(), 100 * matching["largest_step_per_px"].get<double>());
  for (const json& t : display["tiles"]) EXPECT_EQ(t["gain"].get<double>(), 1.0);
  std::ifstream written(dir.file("state/rig.json"));
  auto calibrated = rig::rigFromJson(json::parse(written, nullptr, false), "rig.json");
  ASSERT_TRUE(calibrated) << calibrated.error().message;
  std::vector<double> ratios;
  std::map<std::string, blend::BrightnessMap> maps;
  for (const auto& p : calibrated->projectors) {
    auto r = blend::projectorResponse(p);
    ASSERT_TRUE(r && r->brightness) << p.name << ": " << p.photometric.dump();
    maps[p.name] = *r->brightness;
  }
  for (const auto& [name, map] : maps) {
    for (int j = 2; j + 2 < map.white.rows; ++j) {
      for (int i = 2; i + 2 < map.white.cols; ++i) {
        const Vec2 px(i * map.step, j * map.step);
        ratios.push_back(map.white.at<float>(j, i) / trueWhite(spec[name], truth[name], px));
      }
    }
  }
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  const double factor = ratios[ratios.size() / 2];
  double worst = 0;
  for (double q : ratios) worst = std::max(worst, std::abs(q / factor - 1));
  std::printf(
      "[ figures  ] brightness maps: %zu interior nodes within %.2f %% of the true "
      "fall-off and brightness\n",
      ratios.size(), 100 * worst);
  EXPECT_LE(worst, 0.02);

  // Seams: within 0.3 px RMS, 1 px at most (ARCHITECTURE.md).
  const Seams seams = seamsOnTheTruth(H, truth, kW, kH);
  ASSERT_GT(seams.pairs, 1000);
  EXPECT_LE(seams.rms, 0.3);
  EXPECT_LE(seams.max, 1.0);

  // The display on the TRUE wall: its corners through a projector that shows them.
  auto wallPoint = [&](const Vec2& content) -> std::optional<Vec3> {
    for (const char* a : kOutputs) {
      const Vec2 p = (H[a] * content.homogeneous()).hnormalized();
      if (inFrame(truth[a], p, -1)) return onTheWall(truth[a], p);
    }
    return std::nullopt;
  };
  const auto tl = wallPoint({-0.5, -0.5}), tr = wallPoint({kW - 0.5, -0.5}),
             bl = wallPoint({-0.5, kH - 0.5}), br = wallPoint({kW - 0.5, kH - 0.5});
  ASSERT_TRUE(tl && tr && bl && br) << "a corner of the display is not lit";
  const Vec3 top = *tr - *tl, left = *tl - *bl;
  const double tilt_deg = std::atan2(top.z(), top.x()) * kDeg;
  const double lean_deg = std::atan2(left.x(), left.z()) * kDeg;
  const double aspect = top.norm() / left.norm() / (double(kW) / kH) - 1;
  const double area =
      0.5 * ((*tr - *tl).cross(*bl - *tl).norm() + (*tr - *br).cross(*bl - *br).norm());
  // The optimum from the TRUE footprints.
  std::vector<blend::DisplayTile> tiles;
  const geom::Plane wall{Vec3(0, 1, 0), -3};
  auto basis = geom::uprightBasis(wall, Vec3(0, 0, 1.5), Vec3(0, 3, 1.5));
  ASSERT_TRUE(basis);
  for (const char* a : kOutputs) {
    auto to_image = geom::planeToImage(truth[a].K, truth[a].pose, *basis);
    ASSERT_TRUE(to_image);
    tiles.push_back({{*basis, to_image->inverse()}, truth[a].width, truth[a].height});
  }
  auto optimum =
      blend::solveTiledDisplay(tiles, kW, kH, {.raster_cells = 2048, .rect = {}, .world_rect = {}});
  ASSERT_TRUE(optimum) << optimum.error().message;
  const double of_optimum = area / optimum->rect.area();
  std::printf(
      "[ figures  ] display %.3f x %.3f m: top edge %.4f deg off level, side %.4f deg off "
      "plumb, aspect %+.4f %%, area %.2f %% of the optimum from the true footprints\n",
      top.norm(), left.norm(), tilt_deg, lean_deg, 100 * aspect, 100 * of_optimum);
  EXPECT_LE(std::abs(tilt_deg), 0.05);
  EXPECT_LE(std::abs(lean_deg), 0.05);
  EXPECT_LE(std::abs(aspect), 1e-3);
  EXPECT_GE(of_optimum, 0.98);

  // Luminance: the daemon's white on the wall, through the camera in linear light, has
  // no step above 2 % between neighbouring blocks over the display (a seam would step
  // by the overlap's error). For scale: the same display drawn with the assumed gamma
  // 2.2 and no matching, seen from the viewer.
  const Reported rep = reported(display, H);
  const Luminance before = unmatchedWhiteSeenByTheViewer(*scene, state, rep, kW, kH);
  const Luminance after = whiteSeenByTheCamera(c, state, rep, "cam_a");
  std::printf(
      "[ figures  ] white through cam_a: largest step %.2f %% between 12 px blocks at camera "
      "pixel (%.0f, %.0f), uniformity min/max %.3f (assumed gamma 2.2, no matching, seen "
      "from the viewer: step %.2f %% between pixels, uniformity %.3f)\n",
      100 * after.step, after.at.x(), after.at.y(), after.uniformity, 100 * before.step,
      before.uniformity);
  EXPECT_LE(after.step, 0.02);
  EXPECT_GT(after.uniformity, 0.5);
  EXPECT_LE(of_optimum, 1.0 + 2 * 4 * optimum->cell_m / left.norm());
}

// While one projector is calibrated every other output shows black: with all four
// showing white before, a neighbour left white would saturate the camera where it
// overlaps the scanned image (~20-25 % of it) and those nodes would not decode. The
// camera sees the whole wall, so all but the frame's edge nodes decode (95 % of the
// 160 x 100 nodes of an 8 px grid asked), and the response ramp at level 0 sees only
// the ambient light (the scene's 0.02 against a projector's 9-13 at 2 m: under 1 % of
// its white).
TEST(SimTiledWall, OtherOutputsAreBlackWhileOneIsCalibrated) {
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "tiled_wall", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto white = c.call({{"cmd", "pattern"}, {"name", "white"}});
  ASSERT_TRUE(white && (*white)["shown"] == true) << (white ? white->dump() : "none");
  const json request = {{"cmd", "calibrate"},  {"id", 1},
                        {"output", "proj_tl"}, {"cameras", {"cam_a"}},
                        {"plane", kWallPlane}, {"mode", "gray+phase"},
                        {"phase_steps", 3},    {"grid", 8},
                        {"settle_frames", 0},  {"response", true}};
  auto started = c.call(request);
  ASSERT_TRUE(started && (*started)["class"] == "CALIBRATE")
      << (started ? started->dump() : "none");
  auto done = finalReply(c, 1, 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  const double black = (*done)["response"]["black"].get<double>();
  const double level = (*done)["response"]["white"].get<double>();
  std::printf(
      "[ figures  ] proj_tl alone, the others black: response black %.2f, white %.1f "
      "(%.2f %%); %d of %d nodes, collineation RMS %.4f px\n",
      black, level, 100 * black / level, (*done)["homography"]["inliers"].get<int>(),
      (*done)["homography"]["samples"].get<int>(),
      (*done)["homography"]["rms_projector_px"].get<double>());
  EXPECT_LT(black, 0.02 * level);
  EXPECT_GE((*done)["homography"]["samples"].get<int>(), 0.95 * (1280 / 8) * (800 / 8));
}

// Two calibrated cameras and no plane: route (a) finds the wall coplanar (no projection
// matrix follows from a plane), triangulates it instead and takes route (b′) on it.
// With Gray codes alone the pair triangulates a node to about 2 mm RMS; over the
// ~4,000 nodes of one projector the fitted plane's noise averages out (0.03 mm), and
// 1 mm and 0.05 degrees leave room for the bias all nodes share (Gray codes decode
// cell centres).
TEST(SimTiledWall, TwoCamerasOnThePlanarWallTakeThePlaneTheyTriangulate) {
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "tiled_wall", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  // Gray codes alone on a 16 px grid: the fewest captures that still give thousands of
  // nodes (the plane is what is judged here, not the decoding's resolution).
  const json request = {
      {"cmd", "calibrate"}, {"id", 1},    {"output", "proj_tl"}, {"cameras", {"cam_a", "cam_b"}},
      {"mode", "gray"},     {"grid", 16}, {"settle_frames", 0}};
  auto started = c.call(request);
  ASSERT_TRUE(started && (*started)["class"] == "CALIBRATE")
      << (started ? started->dump() : "none");
  EXPECT_EQ((*started)["route"], "a");
  auto done = finalReply(c, 1, 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  EXPECT_EQ((*done)["route"], "b'");
  EXPECT_EQ((*done)["plane_source"], "cameras");
  const json& plane = (*done)["surface"]["plane"];
  ASSERT_EQ(plane.size(), 4u) << done->dump();
  const Vec3 n(plane[0].get<double>(), plane[1].get<double>(), plane[2].get<double>());
  const double angle_deg = std::acos(std::min(1.0, n.normalized().dot(Vec3::UnitY()))) * 180 / M_PI;
  const double offset_mm = std::abs(plane[3].get<double>() / n.norm() + 3.0) * 1000;
  std::printf(
      "[ figures  ] proj_tl, two cameras, no plane: wall triangulated from %d nodes "
      "(RMS %.3f mm), normal %.4f deg and %.3f mm off the truth; collineation RMS %.4f px\n",
      (*done)["triangulated_plane"]["inliers"].get<int>(),
      1000 * (*done)["triangulated_plane"]["rms_m"].get<double>(), angle_deg, offset_mm,
      (*done)["homography"]["rms_projector_px"].get<double>());
  EXPECT_LT(angle_deg, 0.05);
  EXPECT_LT(offset_mm, 1.0);
  // The plane is the rig's surface now, and the projector has its collineation.
  std::ifstream in(dir.file("state/rig.json"));
  const json rig = json::parse(in, nullptr, false);
  ASSERT_TRUE(rig.is_object());
  EXPECT_EQ(rig["surface"]["plane"], plane);
  ASSERT_EQ(rig["projectors"].size(), 1u);
  EXPECT_TRUE(rig["projectors"][0].contains("plane_homography"));
}

// A display rectangle from the configuration ([keystone] display_centre, display_size:
// world metres) instead of the largest one, on the true rig handed over explicitly (its
// projectors have intrinsics and poses and the wall is a plane: each one's collineation
// with the wall follows from them).
TEST(SimTiledWall, ConfiguredDisplayRectangleIsUsed) {
  TempDir dir;
  dir.write("procamd.toml",
            "[keystone]\ndisplay_centre = [0.1, 3.0, 1.45]\ndisplay_size = [1.6, 0.9]\n");
  auto launch = simWithTruth(dir, "tiled_wall");
  launch.args.insert(launch.args.end(), {"--config", dir.file("procamd.toml")});
  DaemonProcess d(dir, launch);
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  const std::string png = contentFile(dir, "slide.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(450, 800, CV_8UC3, cv::Scalar(255, 255, 255))));
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}}, 30s);
  ASSERT_TRUE(load && (*load)["class"] == "CONTENT") << (load ? load->dump() : "none");
  auto on = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(on && (*on)["class"] == "KEYSTONE") << (on ? on->dump() : "none");
  json display;
  ASSERT_TRUE(eventually(
      [&] {
        auto s = c.call({{"cmd", "status"}});
        display = s ? (*s)["keystone"].value("display", json()) : json();
        return display.is_object() && display.value("state", "") == "ready";
      },
      30s))
      << display.dump() << "\n"
      << d.log();
  EXPECT_EQ(display["rect_source"], "config");
  EXPECT_EQ(display["outputs"].size(), 4u);
  EXPECT_NEAR(display["rect_m"]["size"][0].get<double>(), 1.6, 1e-9);
  EXPECT_NEAR(display["rect_m"]["size"][1].get<double>(), 0.9, 1e-9);
  const json& b = display["basis"];
  Vec3 centre = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    centre[i] = b["origin"][i].get<double>() +
                display["rect_m"]["centre"][0].get<double>() * b["u"][i].get<double>() +
                display["rect_m"]["centre"][1].get<double>() * b["v"][i].get<double>();
  }
  EXPECT_NEAR((centre - Vec3(0.1, 3.0, 1.45)).norm(), 0, 1e-9) << centre.transpose();
}

// Cameras at several positions (wall_views): cam_l sees most of proj_l and nothing of
// proj_r, cam_r sees proj_r whole and a fifth of proj_l, and only cam_l has a pose in
// the rig; cam_r is known by its intrinsics alone. calibrate registers cam_r through
// the projector both see ([Chen02]'s homography tree) and maps both projectors onto the
// wall; the display they make is judged with the TRUE projectors.
TEST(SimWallViews, CamerasThatEachSeeOneProjectorCalibrateTheDisplayTogether) {
  auto scene = sim::resolveScene("wall_views");
  ASSERT_TRUE(scene) << scene.error().message;
  std::map<std::string, geom::CameraModel> truth;
  for (const auto& p : scene->at(0).projectors) truth[p.spec.name] = p.model;
  TempDir dir;
  // cam_l posed; cam_r by its intrinsics alone.
  DaemonProcess d(dir, simWithTruth(dir, "wall_views", TruthParts::kFirstCameraPosed));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  // The reference camera must have a pose; cam_r has none.
  auto refused = c.call({{"cmd", "calibrate"},
                         {"projectors", "all"},
                         {"cameras", {"cam_r", "cam_l"}},
                         {"plane", kWallPlane}});
  ASSERT_TRUE(refused);
  EXPECT_EQ((*refused)["code"], "unavailable") << refused->dump();
  EXPECT_NE((*refused)["message"].get<std::string>().find("cam_r"), std::string::npos);
  // A measured settle time would time cam_r on proj_l, which it barely sees.
  auto unmeasurable = c.call({{"cmd", "calibrate"},
                              {"projectors", "all"},
                              {"cameras", {"cam_l", "cam_r"}},
                              {"plane", kWallPlane},
                              {"settle_frames", "auto"}});
  ASSERT_TRUE(unmeasurable);
  EXPECT_EQ((*unmeasurable)["code"], "bad-argument") << unmeasurable->dump();

  auto started = c.call(calibrateEveryProjector(json({"cam_l", "cam_r"})));
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["route"], "b'");
  auto done = finalReply(c, 1, 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  const json& wall = (*done)["wall"];
  ASSERT_TRUE(wall.is_object()) << done->dump();
  EXPECT_EQ(wall["reference_camera"], "cam_l");
  std::printf(
      "[ figures  ] wall views: %d links, %d nodes, residual %.4f camera px (chain %.4f), %d "
      "iterations\n",
      wall["links"].get<int>(), wall["nodes"].get<int>(), wall["rms_camera_px"].get<double>(),
      wall["chain_rms_camera_px"].get<double>(), wall["iterations"].get<int>());
  for (const json& p : wall["projectors"]) {
    std::printf("[ figures  ] %s: %d cameras, %d nodes, %.4f camera px, coverage %.3f\n",
                p["output"].get<std::string>().c_str(), p["cameras"].get<int>(),
                p["nodes"].get<int>(), p["rms_camera_px"].get<double>(),
                p["coverage"].get<double>());
  }
  // proj_l is seen by both cameras; proj_r by cam_r only, two cameras down the chain
  // from cam_l.
  ASSERT_EQ(wall["projectors"].size(), 2u);
  EXPECT_EQ(wall["projectors"][0]["cameras"], 2) << wall.dump();
  EXPECT_EQ(wall["projectors"][1]["cameras"], 1) << wall.dump();
  EXPECT_EQ(wall["projectors"][1]["chain_cameras"], 2) << wall.dump();
  for (const json& o : (*done)["outputs"]) {
    EXPECT_NE(o["projector"]["calibrated"]["method"].get<std::string>().find("several positions"),
              std::string::npos)
        << o.dump();
  }
  // Every corner of both images within the keystone bound (0.5 px) of the TRUE
  // projector's, proj_r's through cam_r alone.
  std::ifstream written(dir.path() + "/state/rig.json");
  auto calibrated = rig::rigFromJson(json::parse(written, nullptr, false), "rig.json");
  ASSERT_TRUE(calibrated) << calibrated.error().message;
  for (const auto& [name, model] : truth) {
    const rig::RigProjector* p = calibrated->projectorForOutput(name);
    ASSERT_TRUE(p && p->plane_homography) << name;
    const double corner = procam::testing::planeCornerErrorPx(*p->plane_homography, model);
    std::printf("[ figures  ] %s: corners within %.3f px of the truth\n", name.c_str(), corner);
    EXPECT_LE(corner, 0.5) << name;
  }
  // The response ramp is measured by the reference camera, which sees nothing of proj_r.
  EXPECT_TRUE((*done)["outputs"][0]["response"].contains("response_gamma")) << done->dump();
  EXPECT_EQ((*done)["outputs"][1]["response"]["measured"], false) << done->dump();
  // The two images overlap: one at a time.
  EXPECT_EQ((*done)["scan"]["batches"].size(), 2u) << done->dump();

  constexpr int kW = 1600, kH = 900;
  const std::string png = contentFile(dir, "slide.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255))));
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}}, 30s);
  ASSERT_TRUE(load && (*load)["class"] == "CONTENT") << (load ? load->dump() : "none");
  auto on = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(on && (*on)["class"] == "KEYSTONE") << (on ? on->dump() : "none");
  json display;
  const std::map<std::string, Mat3> H = tiles(c, kW, kH, 2, display);
  ASSERT_EQ(H.size(), 2u) << display.dump() << "\n" << d.log();
  // Seams within 0.3 px RMS, 1 px at most (ARCHITECTURE.md), where proj_r is placed
  // through cam_r's view of proj_l alone.
  const Seams seams = seamsOnTheTruth(H, truth, kW, kH);
  ASSERT_GT(seams.pairs, 1000);
  EXPECT_LE(seams.rms, 0.3);
  EXPECT_LE(seams.max, 1.0);
}

}  // namespace
}  // namespace procam::itest
