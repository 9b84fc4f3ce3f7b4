// Structured-light bench on the virtual rig: run time against error.
//
// Scene: corner_stereo at half resolution (projector 640x400, cameras 512x384),
// projector gamma 2.2, ambient 10% of white, 8-bit cameras. Every distinct pattern
// frame is ray-traced once (noise-free linear radiance); the camera chain of the
// scene (exposure, read noise, 8-bit quantisation; linear response, no shot noise)
// is applied per noise level, so the sweep costs one render per frame.
//
// 1. Sweep: pattern set (gray, gray+3-phase, gray+8-phase) x step (1, 2, 4, 8, 16) x
//    read noise (0.5, 1, 2, 4 DN): frames, decode time (both cameras), correspondence
//    RMS against the true projector pixel (left camera), route (a) calibration
//    (focal error, centre error, reprojection RMS) and its compute time against the
//    capture time at 60 Hz. -> bench_structured_light_sweep.csv (+ .png)
// 2. OpenCV: cv::structured_light::GrayCodePattern's own set rendered on the same rig
//    (1 DN), decoded by OpenCV (GrayCodePattern::decode for the camera pair, and
//    getProjPixel per pixel for the left camera's correspondences) and by procamd's
//    decoder (both cameras, its Gray set of the same frame count).
//    -> bench_structured_light_opencv.csv
//
//   bench_structured_light [--out DIR] [--quick]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgproc.hpp>
#include <opencv2/structured_light.hpp>
#include <random>
#include <string>
#include <vector>

#include "calibration/projector_calibration.hpp"
#include "sim/camera_response.hpp"
#include "structured_light/decoder.hpp"
#include "surface/projector_samples.hpp"
#include "surface/stereo_points.hpp"
#include "surface/surface_model.hpp"
#include "unit/calibration/rig_capture.hpp"

using namespace procam;
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

const std::vector<std::string> kCameras = {"cam_left", "cam_right"};

struct Rig {
  sim::Scene scene;
  sim::SceneState state;
  std::map<std::string, double> exposure;  // per camera
  std::map<std::string, sim::TruthMaps> truth;
};

Rig makeRig() {
  std::string t = testing::sceneText("corner_stereo");
  testing::scaleDevice(t, 1280, 800, 0.5);
  testing::scaleDevice(t, 1024, 768, 0.5);
  testing::scaleDevice(t, 1024, 768, 0.5);
  testing::edit(t, "bit_depth = 10", "bit_depth = 8");
  t = testing::withIssueLighting(t, "cam_left", "0.02", "bit_depth = 8");
  auto scene = sim::Scene::parse(t, "bench scene", {});
  if (!scene) {
    std::fprintf(stderr, "scene: %s\n", scene.error().message.c_str());
    std::exit(1);
  }
  Rig rig{std::move(*scene), {}, {}, {}};
  rig.state = rig.scene.at(0);
  auto r = sim::Renderer::create(rig.scene, rig.state, {});
  for (const auto& c : rig.state.cameras) {
    rig.exposure[c.spec.name] = c.spec.exposure;
    rig.truth[c.spec.name] = *r->cameraTruth(c.spec.name);
  }
  return rig;
}

// Noise-free luminance radiance per camera for each frame.
using Radiance = std::map<std::string, std::vector<cv::Mat>>;

Radiance renderRadiance(const Rig& rig, const std::vector<cv::Mat>& frames) {
  Radiance out;
  for (const cv::Mat& f : frames) {
    auto r = sim::Renderer::create(rig.scene, rig.state, {{"proj", f}});
    for (const auto& cam : kCameras) {
      cv::Mat bgr = *r->cameraRadiance(cam);
      cv::Mat lum(bgr.size(), CV_32F);
      for (int y = 0; y < bgr.rows; ++y)
        for (int x = 0; x < bgr.cols; ++x)
          lum.at<float>(y, x) = sim::luminance(bgr.at<cv::Vec3f>(y, x));
      out[cam].push_back(lum);
    }
  }
  return out;
}

// 8-bit capture: round(255 * exposure * radiance + read noise), clipped.
std::vector<cv::Mat> expose(const std::vector<cv::Mat>& radiance, double exposure, double noise_dn,
                            unsigned seed) {
  std::vector<cv::Mat> out;
  cv::RNG rng(seed);
  for (const cv::Mat& r : radiance) {
    cv::Mat noise(r.size(), CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0, noise_dn);
    cv::Mat v = r * (255.0 * exposure) + noise, code;
    v.convertTo(code, CV_8U);  // rounds and saturates
    out.push_back(code);
  }
  return out;
}

struct CorrError {
  double rms = 0;
  double decoded_fraction = 0;  // of lit pixels
};

CorrError correspondenceError(const sim::TruthMaps& truth, const cv::Mat& u, const cv::Mat& v,
                              const cv::Mat& ok) {
  double sum = 0;
  int n = 0;
  const int lit = cv::countNonZero(truth.lit[0]);
  for (int y = 0; y < u.rows; ++y)
    for (int x = 0; x < u.cols; ++x) {
      if (!ok.at<std::uint8_t>(y, x) || !truth.lit[0].at<std::uint8_t>(y, x)) continue;
      const cv::Vec2f p = truth.projector_pixel[0].at<cv::Vec2f>(y, x);
      const double du = u.at<float>(y, x) - p[0], dv = v.at<float>(y, x) - p[1];
      sum += du * du + dv * dv;
      ++n;
    }
  return {n ? std::sqrt(sum / (2.0 * n)) : -1, lit ? static_cast<double>(n) / lit : 0};
}

struct SweepRow {
  std::string set;
  int step = 0, frames = 0;
  double noise = 0, decode_ms = 0, calib_ms = 0, capture_ms = 0, corr_rms = 0, decoded = 0;
  double reproj_rms = -1, focal_err_pct = -1, centre_err_mm = -1;
  double sample_ms = 0, fit_ms = 0;  // parts of calib_ms (the rest: the surface model)
  int points = 0;                    // triangulated projector nodes
};

void runSweep(const Rig& rig, const fs::path& out, bool quick) {
  struct SetDef {
    std::string name;
    sl::Mode mode;
    int phase_steps;
  };
  const std::vector<SetDef> sets = {{"gray", sl::Mode::kGray, 0},
                                    {"gray+3phase", sl::Mode::kGrayPhase, 3},
                                    {"gray+8phase", sl::Mode::kGrayPhase, 8}};
  const std::vector<int> steps = quick ? std::vector<int>{1, 8} : std::vector<int>{1, 2, 4, 8, 16};
  const std::vector<double> noises =
      quick ? std::vector<double>{1} : std::vector<double>{0.5, 1, 2, 4};
  const geom::CameraModel& truth = rig.state.projectors[0].model;
  std::vector<SweepRow> rows;
  std::map<std::string, Radiance> cache;  // by frame-set signature
  for (const auto& def : sets)
    for (int step : steps) {
      auto set = sl::makePatternSet({.width = 640,
                                     .height = 400,
                                     .mode = def.mode,
                                     .step = step,
                                     .phase_steps = std::max(3, def.phase_steps)});
      const std::string key = def.name + "/" + std::to_string(set->columns.cell) + "/" +
                              std::to_string(set->columns.period);
      if (!cache.count(key)) {
        std::vector<cv::Mat> frames;
        for (std::size_t i = 0; i < set->frames.size(); ++i)
          frames.push_back(sl::renderFrame(*set, i));
        std::fprintf(stderr, "rendering %s step %d: %zu frames x 2 cameras\n", def.name.c_str(),
                     step, frames.size());
        cache[key] = renderRadiance(rig, frames);
      }
      const Radiance& radiance = cache[key];
      for (double noise : noises) {
        SweepRow row{def.name, step, static_cast<int>(set->frames.size()), noise};
        std::map<std::string, sl::Decoded> decoded;
        std::map<std::string, std::vector<cv::Mat>> captures;
        for (const auto& cam : kCameras)
          captures[cam] = expose(radiance.at(cam), rig.exposure.at(cam), noise, 7 + step);
        row.decode_ms = 1e30;
        for (int rep = 0; rep < 3; ++rep) {
          const auto t0 = Clock::now();
          for (const auto& cam : kCameras) decoded[cam] = *sl::decode(*set, captures[cam]);
          row.decode_ms = std::min(row.decode_ms, msSince(t0));
        }
        const sl::Decoded& left = decoded["cam_left"];
        const CorrError e =
            correspondenceError(rig.truth.at("cam_left"), left.u, left.v, left.flags == 0);
        row.corr_rms = e.rms;
        row.decoded = e.decoded_fraction;
        row.capture_ms = 1000.0 * set->frames.size() / 60.0;
        const auto t0 = Clock::now();
        const int node_step = std::max(4, step);
        const double radius = def.mode == sl::Mode::kGray ? std::max(2, set->columns.cell) : 2.0;
        auto sa = surface::sampleProjectorGrid(decoded["cam_left"], 640, 400,
                                               {.step = node_step, .radius = radius});
        auto sb = surface::sampleProjectorGrid(decoded["cam_right"], 640, 400,
                                               {.step = node_step, .radius = radius});
        auto pts = surface::triangulateStereo(rig.state.camera("cam_left")->model, *sa,
                                              rig.state.camera("cam_right")->model, *sb);
        row.sample_ms = msSince(t0);
        if (pts) {
          const auto t1 = Clock::now();
          auto c = calib::calibrateProjectorFromSurface(*pts);
          row.fit_ms = msSince(t1);
          if (c) {
            row.points = static_cast<int>(pts->world.size());
            auto model = surface::buildSurface(surface::keepPoints(*pts, c->inliers));
            row.calib_ms = msSince(t0);
            row.reproj_rms = c->rms_px;
            row.focal_err_pct = 100 * std::abs(c->K.fx - truth.K.fx) / truth.K.fx;
            row.centre_err_mm = 1000 * (c->pose.center() - truth.pose.center()).norm();
            (void)model;
          }
        }
        std::printf(
            "%-12s step %2d noise %.1f: %2d frames, decode %6.1f ms, corr %.3f px (%.0f%% lit "
            "decoded), "
            "reproj %.3f px, focal err %.3f%%, centre %.2f mm, calib %.1f ms (capture %.0f ms; "
            "%d nodes: sample+triangulate %.1f, fit %.1f, surface %.1f ms)\n",
            row.set.c_str(), step, noise, row.frames, row.decode_ms, row.corr_rms,
            100 * row.decoded, row.reproj_rms, row.focal_err_pct, row.centre_err_mm, row.calib_ms,
            row.capture_ms, row.points, row.sample_ms, row.fit_ms,
            row.calib_ms - row.sample_ms - row.fit_ms);
        rows.push_back(row);
      }
    }
  int within = 0;
  double worst = 0;
  for (const auto& r : rows) {
    const double share = r.calib_ms / r.capture_ms;
    within += r.reproj_rms >= 0 && share < 0.1;
    worst = std::max(worst, share);
  }
  std::printf(
      "goal calibration compute < 10%% of the capture time at 60 Hz: %d of %zu rows (worst "
      "%.1f%%)\n",
      within, rows.size(), 100 * worst);
  std::ofstream csv(out / "bench_structured_light_sweep.csv");
  csv << "set,step,noise_dn,frames,decode_ms,calib_ms,capture_ms_60hz,corr_rms_px,decoded_fraction,"
         "reproj_rms_px,focal_err_pct,centre_err_mm,nodes,sample_ms,fit_ms\n";
  for (const auto& r : rows)
    csv << r.set << ',' << r.step << ',' << r.noise << ',' << r.frames << ',' << r.decode_ms << ','
        << r.calib_ms << ',' << r.capture_ms << ',' << r.corr_rms << ',' << r.decoded << ','
        << r.reproj_rms << ',' << r.focal_err_pct << ',' << r.centre_err_mm << ',' << r.points
        << ',' << r.sample_ms << ',' << r.fit_ms << '\n';
}

void runOpenCv(const Rig& rig, const fs::path& out) {
  cv::structured_light::GrayCodePattern::Params params;
  params.width = 640;
  params.height = 400;
  auto gcp = cv::structured_light::GrayCodePattern::create(params);
  std::vector<cv::Mat> patterns;
  gcp->generate(patterns);
  cv::Mat black, white;
  gcp->getImagesForShadowMasks(black, white);
  std::vector<cv::Mat> frames = patterns;
  frames.push_back(white);
  frames.push_back(black);
  std::fprintf(stderr, "rendering OpenCV GrayCodePattern: %zu frames x 2 cameras\n", frames.size());
  const Radiance radiance = renderRadiance(rig, frames);
  std::vector<std::vector<cv::Mat>> cam_patterns;
  std::vector<cv::Mat> whites, blacks;
  for (const auto& cam : kCameras) {
    auto c = expose(radiance.at(cam), rig.exposure.at(cam), 1.0, 99);
    whites.push_back(c[c.size() - 2]);
    blacks.push_back(c[c.size() - 1]);
    c.resize(c.size() - 2);
    cam_patterns.push_back(c);
  }
  // Per-pixel correspondences of the left camera through OpenCV's getProjPixel
  // (with OpenCV's own shadow mask: white - black > its black threshold).
  const auto& left = cam_patterns[0];
  cv::Mat u(left[0].size(), CV_32F, cv::Scalar(-1)), v = u.clone(),
                                                     ok(left[0].size(), CV_8U, cv::Scalar(0));
  const auto t1 = Clock::now();
  for (int y = 0; y < u.rows; ++y)
    for (int x = 0; x < u.cols; ++x) {
      if (whites[0].at<std::uint8_t>(y, x) - blacks[0].at<std::uint8_t>(y, x) <= 40)
        continue;  // default
      cv::Point p;
      if (gcp->getProjPixel(left, x, y, p)) continue;  // true = error
      u.at<float>(y, x) = static_cast<float>(p.x);
      v.at<float>(y, x) = static_cast<float>(p.y);
      ok.at<std::uint8_t>(y, x) = 1;
    }
  const double opencv_pixel_ms = msSince(t1);
  const CorrError ocv = correspondenceError(rig.truth.at("cam_left"), u, v, ok);

  // procamd on its own Gray set with the same number of frames (40 at 640x400).
  auto set = sl::makePatternSet({.width = 640, .height = 400});
  // OpenCV's frames are the same reflected Gray code with inverses: each of procamd's
  // frames is one of OpenCV's, so procamd decodes OpenCV's captures reordered.
  std::vector<int> from_opencv;
  for (std::size_t i = 0; i < set->frames.size(); ++i) {
    const cv::Mat mine = sl::renderFrame(*set, i);
    for (std::size_t j = 0; j < frames.size(); ++j)
      if (frames[j].size() == mine.size() && cv::norm(frames[j], mine, cv::NORM_INF) == 0) {
        from_opencv.push_back(static_cast<int>(j));
        break;
      }
  }
  const bool same_code = from_opencv.size() == set->frames.size();
  CorrError on_opencv{-1, 0};
  double on_opencv_ms = -1;
  if (same_code) {
    std::vector<cv::Mat> left_frames;
    const auto all = expose(radiance.at("cam_left"), rig.exposure.at("cam_left"), 1.0, 99);
    for (int j : from_opencv) left_frames.push_back(all[static_cast<std::size_t>(j)]);
    std::vector<cv::Mat> right_frames;
    const auto all_r = expose(radiance.at("cam_right"), rig.exposure.at("cam_right"), 1.0, 99);
    for (int j : from_opencv) right_frames.push_back(all_r[static_cast<std::size_t>(j)]);
    on_opencv_ms = 1e30;
    sl::Decoded dl;
    for (int rep = 0; rep < 5; ++rep) {
      const auto t0 = Clock::now();
      dl = *sl::decode(*set, left_frames);
      (void)*sl::decode(*set, right_frames);
      on_opencv_ms = std::min(on_opencv_ms, msSince(t0));
    }
    on_opencv = correspondenceError(rig.truth.at("cam_left"), dl.u, dl.v, dl.flags == 0);
  }
  std::vector<cv::Mat> ours;
  for (std::size_t i = 0; i < set->frames.size(); ++i) ours.push_back(sl::renderFrame(*set, i));
  const Radiance our_radiance = renderRadiance(rig, ours);
  std::map<std::string, std::vector<cv::Mat>> caps;
  for (const auto& cam : kCameras)
    caps[cam] = expose(our_radiance.at(cam), rig.exposure.at(cam), 1.0, 99);
  // Interleaved repetitions, best of each: the machine's load affects both alike.
  double our_ms = 1e30, opencv_ms = 1e30;
  std::map<std::string, sl::Decoded> d;
  for (int rep = 0; rep < 5; ++rep) {
    cv::Mat disparity;
    auto t0 = Clock::now();
    gcp->decode(cam_patterns, disparity, blacks, whites,
                cv::structured_light::DECODE_3D_UNDERWORLD);
    opencv_ms = std::min(opencv_ms, msSince(t0));
    t0 = Clock::now();
    for (const auto& cam : kCameras) d[cam] = *sl::decode(*set, caps[cam]);
    our_ms = std::min(our_ms, msSince(t0));
  }
  const CorrError mine = correspondenceError(rig.truth.at("cam_left"), d["cam_left"].u,
                                             d["cam_left"].v, d["cam_left"].flags == 0);
  std::printf(
      "OpenCV GrayCodePattern::decode (2 cameras, %zu frames each): %.1f ms; getProjPixel over the "
      "left "
      "camera: %.1f ms, %.3f px RMS, %.0f%% of lit pixels\n",
      frames.size(), opencv_ms, opencv_pixel_ms, ocv.rms, 100 * ocv.decoded_fraction);
  std::printf(
      "procamd decode (2 cameras, %zu frames each): %.2f ms, %.3f px RMS, %.0f%% of lit pixels; "
      "time ratio OpenCV/procamd %.1fx (per-pixel API %.1fx)\n",
      set->frames.size(), our_ms, mine.rms, 100 * mine.decoded_fraction, opencv_ms / our_ms,
      opencv_pixel_ms / (our_ms / 2));
  if (same_code)
    std::printf(
        "procamd decode of OpenCV's own captured frames (2 cameras): %.2f ms, %.3f px RMS, %.0f%% "
        "of lit pixels; time ratio OpenCV/procamd %.1fx\n",
        on_opencv_ms, on_opencv.rms, 100 * on_opencv.decoded_fraction, opencv_ms / on_opencv_ms);
  else
    std::printf("OpenCV's frames are not procamd's Gray code; not decoded by procamd\n");
  std::printf("goal decode >= 10x faster than OpenCV: %s (%.1fx)\n",
              opencv_ms / our_ms >= 10 ? "met" : "MISSED", opencv_ms / our_ms);
  std::ofstream csv(out / "bench_structured_light_opencv.csv");
  csv << "method,frames_per_camera,cameras,decode_ms,corr_rms_px,decoded_fraction\n";
  csv << "opencv_GrayCodePattern_decode," << frames.size() << ",2," << opencv_ms << ",,\n";
  csv << "opencv_getProjPixel," << frames.size() << ",1," << opencv_pixel_ms << ',' << ocv.rms
      << ',' << ocv.decoded_fraction << '\n';
  csv << "procamd_decode," << set->frames.size() << ",2," << our_ms << ',' << mine.rms << ','
      << mine.decoded_fraction << '\n';
  if (same_code)
    csv << "procamd_decode_opencv_frames," << set->frames.size() << ",2," << on_opencv_ms << ','
        << on_opencv.rms << ',' << on_opencv.decoded_fraction << '\n';
}

void plot(const fs::path& out) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) return;
  const fs::path gp = out / "bench_structured_light_sweep.gp";
  std::ofstream s(gp);
  s << "set terminal pngcairo size 1200,500\nset output '"
    << (out / "bench_structured_light_sweep.png").string()
    << "'\nset datafile separator ','\nset multiplot layout 1,2\nset key top right\nset logscale "
       "y\n"
       "set xlabel 'frames used'\nset ylabel 'correspondence RMS [projector px]'\n"
       "plot for [s in 'gray gray+3phase gray+8phase'] '"
    << (out / "bench_structured_light_sweep.csv").string()
    << "' using (strcol(1) eq s ? $4 : 1/0):8 with points pt 7 title s\n"
       "set xlabel 'decode time, 2 cameras [ms]'\nset ylabel 'projector reprojection RMS [px]'\n"
       "plot for [s in 'gray gray+3phase gray+8phase'] '"
    << (out / "bench_structured_light_sweep.csv").string()
    << "' using (strcol(1) eq s ? $5 : 1/0):10 with points pt 7 title s\nunset multiplot\n";
  s.close();
  const std::string cmd = "gnuplot '" + gp.string() + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed\n");
}

}  // namespace

int main(int argc, char** argv) {
  fs::path out = ".";
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (a == "--quick") {
      quick = true;
    } else if (a == "--help" || a == "-h") {
      std::printf(
          "usage: bench_structured_light [--out DIR] [--quick]\n"
          "  Sweep (gray, gray+3phase, gray+8phase x step 1..16 x read noise 0.5..4 DN) on\n"
          "  corner_stereo at half resolution, and OpenCV's GrayCodePattern against procamd's\n"
          "  decoder. Writes bench_structured_light_{sweep,opencv}.csv (+ sweep .png with\n"
          "  gnuplot) to DIR (default .). --quick: steps 1 and 8, noise 1 DN only.\n");
      return 0;
    } else {
      std::fprintf(stderr, "usage: bench_structured_light [--out DIR] [--quick]\n");
      return 2;
    }
  }
  fs::create_directories(out);
  const Rig rig = makeRig();
  runOpenCv(rig, out);
  runSweep(rig, out, quick);
  plot(out);
  return 0;
}
