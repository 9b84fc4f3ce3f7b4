// Multi-projector planar walls against projector count (1, 2, 4, 9, 16 projectors of
// 1280x800 in a grid with ~15 % overlaps, each turned a few degrees off axis):
//  - calibration, route (b′) ([Raskar02] §4.2.1, §4.2.4) from one calibrated camera that
//    sees the whole wall: the projector nodes (every 8 px) the decoder would give, seen
//    by the camera with 0.1 px of noise (a node's scatter under the reference capture
//    conditions) and taken back to the wall through the camera's collineation; each
//    projector's collineation fitted (geom::fitHomography, DLT + LM), then the display,
//    feathering weights and weight tables (blend::makeTiledBlend). Compute time of the
//    fits and of the display; capture frames of the scans (Gray + phase pattern set and
//    the 9-level response ramp, one projector at a time); the seam error: content points
//    shown by two projectors, where the TRUE projectors put them on the wall, apart in
//    projector pixels (RMS, max). Decoding is not included (bench_structured_light
//    times it per capture set).
//  - frame time per output at 1920x1080 with blending (alpha mask + weight table in the
//    final stage) for the homography, lookup and two-pass paths, CPU reference renderer
//    (and GLES 3 on the surfaceless EGL platform when built), and per frame of N outputs
//    drawn one after the other on the daemon's compute worker.
// Writes multi_projector_calibration.csv, multi_projector_frame.csv and, with gnuplot,
// multi_projector.png to --out DIR.
//
//   bench_multi_projector [--out DIR] [--runs N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "../unit/render/render_test_rig.hpp"  // test camera rigs and surfaces
#include "bench_timing.hpp"
#include "bench_warps.hpp"
#include "blend/rig_tiles.hpp"
#include "blend/tiled_blend.hpp"
#include "geometry/homography.hpp"
#include "geometry/plane_homography.hpp"
#include "render/cpu_renderer.hpp"
#include "structured_light/pattern_set.hpp"
#if PROCAM_BENCH_GLES
#include "egl/egl_context.hpp"
#include "gl/gl_renderer.hpp"
#endif

using namespace procam;
using bench::measure;
using bench::Timing;

namespace {

constexpr int kW = 1280, kH = 800;  // projector framebuffer
constexpr double kF = 1500;         // projector focal length, pixels
constexpr double kWallY = 3.0;      // the wall: y = 3, lit from y < 3
constexpr double kThrow = 2.0;      // projector to wall
constexpr double kCameraNoisePx = 0.1;

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Wall {
  std::vector<rig::RigProjector> projectors;
  geom::Plane plane{Vec3(0, 1, 0), -kWallY};
  double width = 0, height = 0;  // extent of the grid of images, metres
};

// cols x rows projectors, images overlapping by ~15 %, each turned up to 2 degrees.
Wall makeWall(int cols, int rows, std::mt19937& rng) {
  Wall w;
  std::uniform_real_distribution<double> turn(-2.0, 2.0);
  const double img_w = kW / kF * kThrow, img_h = kH / kF * kThrow;
  const double dx = 0.85 * img_w, dz = 0.85 * img_h;
  w.width = dx * (cols - 1) + img_w;
  w.height = dz * (rows - 1) + img_h;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      rig::RigProjector p;
      p.name = "p" + std::to_string(r) + "_" + std::to_string(c);
      p.width = kW;
      p.height = kH;
      p.K.fx = p.K.fy = kF;
      p.K.cx = 0.5 * (kW - 1);
      p.K.cy = 0.5 * (kH - 1);
      const Vec3 eye((c - 0.5 * (cols - 1)) * dx, kWallY - kThrow,
                     1.5 + (0.5 * (rows - 1) - r) * dz);
      const double deg = M_PI / 180;
      const Vec3 target = eye + Vec3(std::tan(turn(rng) * deg), 1, std::tan(turn(rng) * deg));
      const Vec3 up = Vec3(std::sin(turn(rng) * deg), 0, 1).normalized();
      p.pose = geom::Pose::lookAt(eye, target, up);
      w.projectors.push_back(p);
    }
  }
  return w;
}

// A camera at 4 m from the wall whose 1920x1200 image holds all of it.
geom::CameraModel wallCamera(const Wall& w) {
  geom::CameraModel cam;
  cam.width = 1920;
  cam.height = 1200;
  const double d = 4.0;
  const double f = 0.9 * std::min(cam.width / (w.width / d), cam.height / (w.height / d));
  cam.K.fx = cam.K.fy = f;
  cam.K.cx = 0.5 * (cam.width - 1);
  cam.K.cy = 0.5 * (cam.height - 1);
  cam.pose = geom::Pose::lookAt(Vec3(0, kWallY - d, 1.5), Vec3(0, kWallY, 1.5), Vec3::UnitZ());
  return cam;
}

struct Calibrated {
  std::vector<blend::DisplayTile> truth, estimated;
  double fit_s = 0, display_s = 0;
  double seam_rms = 0, seam_max = 0;
  long seam_points = 0;
  bool ok = false;
};

Calibrated calibrate(const Wall& w, const geom::CameraModel& cam, std::mt19937& rng) {
  Calibrated out;
  rig::RigSurface surface;
  surface.plane = w.plane;
  std::normal_distribution<double> noise(0, kCameraNoisePx);
  const auto t_fit = std::chrono::steady_clock::now();
  for (const auto& p : w.projectors) {
    auto truth = blend::displayTile(p, surface);
    if (!truth) return out;
    const geom::PlaneBasis& basis = truth->projector_to_plane.basis;
    auto cam_image = geom::planeToImage(cam.K, cam.pose, basis);
    if (!cam_image) return out;
    const Mat3 image_to_plane = cam_image->inverse();
    std::vector<Vec2> src, dst;
    for (int y = 4; y < kH; y += 8) {
      for (int x = 4; x < kW; x += 8) {
        const Vec2 wall = (truth->projector_to_plane.H * Vec3(x, y, 1)).hnormalized();
        const Vec2 seen =
            (*cam_image * wall.homogeneous()).hnormalized() + Vec2(noise(rng), noise(rng));
        src.push_back(Vec2(x, y));
        dst.push_back((image_to_plane * seen.homogeneous()).hnormalized());
      }
    }
    auto fit = geom::fitHomography(src, dst);
    if (!fit) return out;
    out.truth.push_back(*truth);
    out.estimated.push_back({geom::PlaneHomography{basis, fit->H}, kW, kH});
  }
  out.fit_s = seconds(t_fit);
  const auto t_display = std::chrono::steady_clock::now();
  auto made = blend::makeTiledBlend(out.estimated, {}, cv::Size(1920, 1080));
  out.display_s = seconds(t_display);
  if (!made) {
    std::printf("  display: %s\n", made.error().message.c_str());
    return out;
  }
  // Seams: content points (every 4 content px) inside two framebuffers; the TRUE walls
  // points of the two pixels, in projector pixels (one is ~throw / f on the wall).
  const double px_m = kThrow / kF;
  double sq = 0;
  for (int cy = 0; cy < 1080; cy += 4) {
    for (int cx = 0; cx < 1920; cx += 4) {
      std::vector<Vec3> on_wall;
      for (std::size_t t = 0; t < out.truth.size(); ++t) {
        const Vec2 fb = (made->display.content_to_framebuffer[t] * Vec3(cx, cy, 1)).hnormalized();
        if (fb.x() < 0 || fb.y() < 0 || fb.x() > kW - 1 || fb.y() > kH - 1) continue;
        const auto& ph = out.truth[t].projector_to_plane;
        on_wall.push_back(ph.basis.toWorld((ph.H * fb.homogeneous()).hnormalized()));
      }
      for (std::size_t i = 0; i < on_wall.size(); ++i) {
        for (std::size_t j = i + 1; j < on_wall.size(); ++j) {
          const double e = (on_wall[i] - on_wall[j]).norm() / px_m;
          sq += e * e;
          out.seam_max = std::max(out.seam_max, e);
          ++out.seam_points;
        }
      }
    }
  }
  out.seam_rms = out.seam_points ? std::sqrt(sq / out.seam_points) : 0;
  out.ok = true;
  return out;
}

struct FrameCase {
  std::string path;
  render::RenderSetup setup;
};

std::vector<FrameCase> frameCases(cv::Size size) {
  render::RenderSetup base;
  base.output_size = size;
  base.content_size = size;
  base.homography << 0.82, 0.06, 140, -0.04, 0.88, 70, 6e-5, -2.5e-5, 1;
  // Blending: a feathered alpha ramp over the left and right fifths, a gamma 2.4 table.
  cv::Mat alpha(size, CV_8UC1);
  for (int x = 0; x < size.width; ++x) {
    const double d =
        std::min({1.0, x / (0.2 * size.width), (size.width - 1 - x) / (0.2 * size.width)});
    alpha.col(x).setTo(cv::Scalar(std::lround(255 * d)));
  }
  base.final_stage.alpha = alpha;
  base.final_stage.weight_lut = *render::weightLutForGamma(2.4);
  std::vector<FrameCase> cases = {{"homography", base}};
  render::RenderSetup lookup = base;
  lookup.path = render::RenderPath::kLookupWarp;
  lookup.lookup = bench::lookupGrid(size);
  cases.push_back({"lookup", lookup});
  render::RenderSetup mesh = base;
  mesh.path = render::RenderPath::kTwoPassMesh;
  mesh.surface = test::domeMesh(Vec3(0, 0, 0), 2.0, 32, 96);
  mesh.projector = test::lookAtProjection(1560, 959.5, 539.5, Vec3(0.3, 0.2, 0.1),
                                          Vec3(0.3, 2, 0.5), Vec3::UnitZ());
  mesh.viewer = test::lookAtProjection(900, 959.5, 539.5, Vec3(-0.2, 0.1, -0.3), Vec3(0, 2, 0.2),
                                       Vec3::UnitZ());
  cases.push_back({"two_pass_mesh", mesh});
  return cases;
}

void plot(const std::filesystem::path& out) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) return;
  const std::string csv = (out / "multi_projector_calibration.csv").string();
  std::ofstream gp(out / "multi_projector.gp");
  gp << "set terminal pngcairo size 1300,520 noenhanced\n"
     << "set output '" << (out / "multi_projector.png").string() << "'\n"
     << "set datafile separator ','\n"
     << "set multiplot layout 1,2 title 'Planar walls of N 1280x800 projectors, route (b'') from "
        "one camera, 0.1 px noise'\n"
     << "set logscale x\nset xlabel 'projectors'\nset ylabel 'seam error (projector px)'\n"
     << "set key top left\n"
     << "plot '" << csv << "' skip 1 using 1:7 with linespoints title 'seam RMS', "
     << "'' skip 1 using 1:8 with linespoints title 'seam max'\n"
     << "set ylabel 'seconds / capture frames'\nset logscale y\n"
     << "plot '" << csv << "' skip 1 using 1:($4+$5) with linespoints title 'compute (s)', "
     << "'' skip 1 using 1:3 with linespoints axes x1y1 title 'capture frames'\n"
     << "unset multiplot\n";
  gp.close();
  const std::string cmd = "gnuplot '" + (out / "multi_projector.gp").string() + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = ".";
  int runs = 15;
  if (!bench::benchOptions(argc, argv, "bench_multi_projector", out, runs, 3)) return 2;
  cv::setNumThreads(static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));

  sl::PatternOptions pattern;
  pattern.width = kW;
  pattern.height = kH;
  pattern.mode = sl::Mode::kGrayPhase;  // the daemon's default
  auto set = sl::makePatternSet(pattern);
  if (!set) {
    std::fprintf(stderr, "bench_multi_projector: %s\n", set.error().message.c_str());
    return 1;
  }
  const int frames_per_projector = int(set->frames.size()) + 9;  // patterns + response ramp

  std::ofstream csv(out / "multi_projector_calibration.csv");
  csv << "projectors,layout,capture_frames,fit_s,display_s,seam_points,seam_rms_px,seam_max_px\n";
  std::printf(
      "Calibration, route (b') on synthetic planar walls (%d capture frames per projector, "
      "scanned one at a time)\n",
      frames_per_projector);
  std::mt19937 rng(15);
  for (const auto& [cols, rows] :
       std::vector<std::pair<int, int>>{{1, 1}, {2, 1}, {2, 2}, {3, 3}, {4, 4}}) {
    const Wall wall = makeWall(cols, rows, rng);
    const Calibrated c = calibrate(wall, wallCamera(wall), rng);
    const int n = cols * rows;
    if (!c.ok) {
      std::printf("  %2d projectors: failed\n", n);
      csv << n << ',' << cols << 'x' << rows << ",,,,,,\n";
      continue;
    }
    std::printf(
        "  %2d projectors (%dx%d): %4d frames, fits %.3f s, display %.3f s, seams over %ld "
        "points RMS %.4f px, max %.4f px\n",
        n, cols, rows, n * frames_per_projector, c.fit_s, c.display_s, c.seam_points, c.seam_rms,
        c.seam_max);
    csv << n << ',' << cols << 'x' << rows << ',' << n * frames_per_projector << ',' << c.fit_s
        << ',' << c.display_s << ',' << c.seam_points << ',' << c.seam_rms << ',' << c.seam_max
        << '\n';
  }
  csv.close();
  plot(out);

  // Frame time per output with blending.
  const cv::Size size(1920, 1080);
  cv::Mat content(size, CV_8UC4);
  cv::randu(content, cv::Scalar::all(0), cv::Scalar::all(256));
  std::ofstream fcsv(out / "multi_projector_frame.csv");
  fcsv << "path,renderer,output_ms,frame_ms_1,frame_ms_4,frame_ms_9,frame_ms_16\n";
  std::printf(
      "Frame time per 1920x1080 output with blending (median of %d), and per frame of N "
      "outputs drawn in turn\n",
      runs);
  uint64_t version = 0;
  auto report = [&](const std::string& path, const std::string& renderer, const Timing& t) {
    std::printf("  %-14s %-28s %7.2f ms per output; N = 4: %6.1f ms, N = 16: %6.1f ms\n",
                path.c_str(), renderer.c_str(), t.median_ms, 4 * t.median_ms, 16 * t.median_ms);
    fcsv << path << ",\"" << renderer << "\"," << t.median_ms << ',' << t.median_ms << ','
         << 4 * t.median_ms << ',' << 9 * t.median_ms << ',' << 16 * t.median_ms << '\n';
  };
  for (const FrameCase& c : frameCases(size)) {
    render::CpuRenderer cpu;
    if (auto ok = cpu.configure(c.setup); !ok) {
      std::printf("  %-14s CPU: %s\n", c.path.c_str(), ok.error().message.c_str());
      continue;
    }
    report(c.path, "CPU reference", measure(runs, [&] {
             (void)cpu.render({&content, nullptr, ++version});
           }));
  }
#if PROCAM_BENCH_GLES
  auto ctx = output::egl::EglContext::surfaceless();
  auto gl = ctx ? output::gl::GlRenderer::create(output::gl::GlTarget{true, 0})
                : decltype(output::gl::GlRenderer::create(output::gl::GlTarget{true, 0})){};
  if (!ctx || !gl) {
    std::printf("  GLES: unavailable\n");
  } else {
    const std::string name = "GLES " + (*ctx)->renderer();
    cv::Mat frame;
    for (const FrameCase& c : frameCases(size)) {
      if (auto ok = (*gl)->configure(c.setup); !ok) {
        std::printf("  %-14s GLES: %s\n", c.path.c_str(), ok.error().message.c_str());
        continue;
      }
      (void)(*gl)->render({&content, nullptr, ++version});
      (void)(*gl)->readFrame(frame);  // warm: shaders, allocation
      report(c.path, name, measure(runs, [&] {
               (void)(*gl)->render({&content, nullptr, ++version});
               glFinish();
             }));
    }
  }
#endif
  return 0;
}
