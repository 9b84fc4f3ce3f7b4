// Multi-projector planar walls against projector count (1, 2, 4, 9, 16 projectors of
// 1280x800 in a grid with ~15 % overlaps, each turned a few degrees off axis):
//  - calibration, route (b′) ([Raskar02] §4.2.1, §4.2.4), two ways: from one calibrated
//    camera that sees the whole wall (each projector's collineation fitted on its own,
//    geom::fitHomography), and from cameras at several positions that each see a 2x2
//    block, the first one calibrated (the homography tree of [Chen02] with its global
//    refinement, geom::solveHomographyTree; the chain alone is reported beside it). The
//    projector nodes (every 8 px) the decoder would give, seen with 0.1 px of noise (a
//    node's scatter under the reference capture conditions). Then the display,
//    feathering weights and weight tables (blend::makeTiledBlend), and the same display
//    matched per pixel ([Majumder05]) for projectors of known brightness across their
//    frames (a bowl, peaks 9-13). Compute time of the fits and of the display (both); capture
//    frames of the scans (Gray + phase pattern set and the 9-level response ramp), one projector at
//    a time and batched (a coarse pass, then projectors whose footprints do not meet together); the
//    seam error: content points shown by two projectors, where the TRUE projectors put them on the
//    wall, apart in projector pixels (RMS, max). Decoding is not included (bench_structured_light
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

#include "../unit/geometry/synthetic_wall.hpp"  // synthetic walls and camera views
#include "../unit/render/render_test_rig.hpp"   // test camera rigs and surfaces
#include "bench_timing.hpp"
#include "bench_warps.hpp"
#include "blend/brightness_map.hpp"
#include "blend/rig_tiles.hpp"
#include "blend/tiled_blend.hpp"
#include "geometry/homography.hpp"
#include "geometry/homography_tree.hpp"
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
constexpr double kCameraNoisePx = 0.1;

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The wall's projectors as the rig model holds them.
std::vector<rig::RigProjector> rigProjectors(const testing::SyntheticWall& w) {
  std::vector<rig::RigProjector> out;
  for (std::size_t i = 0; i < w.projectors.size(); ++i) {
    const geom::CameraModel& m = w.projectors[i];
    rig::RigProjector p;
    p.name = "p" + std::to_string(i / w.cols) + "_" + std::to_string(i % w.cols);
    p.width = m.width;
    p.height = m.height;
    p.K = m.K;
    p.pose = m.pose;
    out.push_back(p);
  }
  return out;
}

// A camera at 4 m from the wall whose 1920x1200 image holds all of it.
geom::CameraModel wallCamera(const testing::SyntheticWall& w) {
  geom::CameraModel cam;
  cam.width = 1920;
  cam.height = 1200;
  const double d = 4.0;
  const double width = (w.cols - 1) * w.pitch_x + w.image_w;
  const double height = (w.rows - 1) * w.pitch_z + w.image_h;
  const double f = 0.9 * std::min(cam.width / (width / d), cam.height / (height / d));
  cam.K.fx = cam.K.fy = f;
  cam.K.cx = 0.5 * (cam.width - 1);
  cam.K.cy = 0.5 * (cam.height - 1);
  cam.pose = geom::Pose::lookAt(Vec3(0, 3.0 - d, 1.5), Vec3(0, 3.0, 1.5), Vec3::UnitZ());
  return cam;
}

// Scan batches: projectors whose footprints meet (a node every 32 px of one inside the
// other) never share one; greedy colouring in grid order.
int scanBatches(const testing::SyntheticWall& w) {
  const std::size_t n = w.projectors.size();
  std::vector<Mat3> to_wall(n), to_pixel(n);
  for (std::size_t p = 0; p < n; ++p) {
    to_wall[p] = w.projectorToWall(p);
    to_pixel[p] = to_wall[p].inverse();
  }
  auto overlap = [&](std::size_t a, std::size_t b) {
    for (int y = 0; y < w.projectors[a].height; y += 32) {
      for (int x = 0; x < w.projectors[a].width; x += 32) {
        const Vec2 q = (to_pixel[b] * (to_wall[a] * Vec3(x, y, 1))).hnormalized();
        if (q.x() >= 0 && q.y() >= 0 && q.x() < w.projectors[b].width &&
            q.y() < w.projectors[b].height)
          return true;
      }
    }
    return false;
  };
  std::vector<int> colour(n, -1);
  int batches = 0;
  for (std::size_t p = 0; p < n; ++p) {
    for (int c = 0; colour[p] < 0; ++c) {
      bool free = true;
      for (std::size_t q = 0; q < p && free; ++q) free = !(colour[q] == c && overlap(p, q));
      if (free) colour[p] = c;
    }
    batches = std::max(batches, colour[p] + 1);
  }
  return batches;
}

struct Calibrated {
  std::vector<blend::DisplayTile> truth, estimated;
  double fit_s = 0, display_s = 0;
  double matched_display_s = 0;  // the same display matched per pixel ([Majumder05])
  double uniformity_before = 0, uniformity_after = 0;
  double seam_rms = 0, seam_max = 0;
  long seam_points = 0;
  // Several camera positions: the tree's chain (before the refinement) and its depth.
  double chain_seam_rms = 0, chain_seam_max = 0;
  int views = 1, deepest_chain = 1;
  bool ok = false;
};

// Each projector's collineation with the wall, in its true tile's (upright) basis, from
// one camera that sees the whole wall: the nodes it sees, taken back to the wall through
// the camera's collineation.
bool oneCamera(const testing::SyntheticWall& w, Calibrated& out, std::mt19937& rng) {
  const geom::CameraModel cam = wallCamera(w);
  std::normal_distribution<double> noise(0, kCameraNoisePx);
  const auto t_fit = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < w.projectors.size(); ++i) {
    const geom::PlaneBasis& basis = out.truth[i].projector_to_plane.basis;
    auto cam_image = geom::planeToImage(cam.K, cam.pose, basis);
    if (!cam_image) return false;
    const Mat3 image_to_plane = cam_image->inverse();
    const Mat3 truth_H = out.truth[i].projector_to_plane.H;
    std::vector<Vec2> src, dst;
    for (int y = 4; y < kH; y += 8) {
      for (int x = 4; x < kW; x += 8) {
        const Vec2 wall = (truth_H * Vec3(x, y, 1)).hnormalized();
        const Vec2 seen =
            (*cam_image * wall.homogeneous()).hnormalized() + Vec2(noise(rng), noise(rng));
        src.push_back(Vec2(x, y));
        dst.push_back((image_to_plane * seen.homogeneous()).hnormalized());
      }
    }
    auto fit = geom::fitHomography(src, dst);
    if (!fit) return false;
    out.estimated.push_back({geom::PlaneHomography{basis, fit->H}, kW, kH});
  }
  out.fit_s = seconds(t_fit);
  return true;
}

// Cameras at several positions, each seeing a 2x2 block ([Chen02]'s homography tree,
// geom::solveHomographyTree); the first is the calibrated one whose collineation with
// the wall is known. `chain` gets the tree's chained collineations alone.
bool cameraPositions(const testing::SyntheticWall& w, Calibrated& out,
                     std::vector<blend::DisplayTile>& chain, std::mt19937& rng) {
  const auto views = testing::blockViews(w, 2, rng);
  const auto matches = testing::viewMatches(w, views, 8, kCameraNoisePx, rng);
  const auto t_fit = std::chrono::steady_clock::now();
  auto tree = geom::solveHomographyTree(matches, views.size(), w.projectors.size());
  out.fit_s = seconds(t_fit);
  auto chained =
      geom::solveHomographyTree(matches, views.size(), w.projectors.size(), {.refine = false});
  if (!tree || !chained) {
    std::printf("  tree: %s\n", (tree ? chained : tree).error().message.c_str());
    return false;
  }
  out.views = int(views.size());
  for (int d : tree->chain_views) out.deepest_chain = std::max(out.deepest_chain, d);
  const Mat3 image_to_wall = testing::wallToImage(w, views[0]).inverse();
  for (std::size_t i = 0; i < w.projectors.size(); ++i) {
    const geom::PlaneBasis& basis = out.truth[i].projector_to_plane.basis;
    auto to_tile = geom::changeOfBasis(w.basis, basis);
    if (!to_tile) return false;
    const Mat3 to_plane = *to_tile * image_to_wall;
    out.estimated.push_back(
        {geom::PlaneHomography{basis, to_plane * tree->projector_to_reference[i]}, kW, kH});
    chain.push_back(
        {geom::PlaneHomography{basis, to_plane * chained->projector_to_reference[i]}, kW, kH});
  }
  return true;
}

struct Seams {
  double rms = 0, max = 0;
  long points = 0;
};

// Seams: content points (every 4 content px) inside two framebuffers; the TRUE wall
// points of the two pixels, in projector pixels (one is ~throw / f on the wall).
Seams seams(const blend::TiledBlend& made, const std::vector<blend::DisplayTile>& truth,
            double px_m) {
  Seams s;
  double sq = 0;
  for (int cy = 0; cy < 1080; cy += 4) {
    for (int cx = 0; cx < 1920; cx += 4) {
      std::vector<Vec3> on_wall;
      for (std::size_t t = 0; t < truth.size(); ++t) {
        const Vec2 fb = (made.display.content_to_framebuffer[t] * Vec3(cx, cy, 1)).hnormalized();
        if (fb.x() < 0 || fb.y() < 0 || fb.x() > kW - 1 || fb.y() > kH - 1) continue;
        const auto& ph = truth[t].projector_to_plane;
        on_wall.push_back(ph.basis.toWorld((ph.H * fb.homogeneous()).hnormalized()));
      }
      for (std::size_t i = 0; i < on_wall.size(); ++i) {
        for (std::size_t j = i + 1; j < on_wall.size(); ++j) {
          const double e = (on_wall[i] - on_wall[j]).norm() / px_m;
          sq += e * e;
          s.max = std::max(s.max, e);
          ++s.points;
        }
      }
    }
  }
  s.rms = s.points ? std::sqrt(sq / double(s.points)) : 0;
  return s;
}

Calibrated calibrate(const testing::SyntheticWall& w, bool several_views, std::mt19937& rng) {
  Calibrated out;
  rig::RigSurface surface;
  surface.plane = geom::Plane{Vec3(0, 1, 0), -3.0};
  for (const auto& p : rigProjectors(w)) {
    auto truth = blend::displayTile(p, surface);
    if (!truth) return out;
    out.truth.push_back(*truth);
  }
  std::vector<blend::DisplayTile> chain;
  if (!(several_views ? cameraPositions(w, out, chain, rng) : oneCamera(w, out, rng))) return out;
  const auto t_display = std::chrono::steady_clock::now();
  auto made = blend::makeTiledBlend(out.estimated, {}, cv::Size(1920, 1080));
  out.display_s = seconds(t_display);
  if (!made) {
    std::printf("  display: %s\n", made.error().message.c_str());
    return out;
  }
  // The same display with every projector's response and brightness across its frame
  // known (a cos^3-like bowl, peaks 9-13 as on tiled_wall): matched per pixel.
  std::vector<std::optional<blend::ProjectorResponse>> responses;
  for (std::size_t t = 0; t < out.estimated.size(); ++t) {
    blend::ProjectorResponse r;
    r.gamma = 2.2;
    r.white = 9.0 + 4.0 * double(t % 5) / 4;
    blend::BrightnessMap map;
    map.width = out.estimated[t].width;
    map.height = out.estimated[t].height;
    map.white = cv::Mat(blend::brightnessNodes(map.height, map.step),
                        blend::brightnessNodes(map.width, map.step), CV_32FC1);
    for (int j = 0; j < map.white.rows; ++j) {
      for (int i = 0; i < map.white.cols; ++i) {
        const double dx = (i * map.step - 0.5 * map.width) / map.width;
        const double dy = (j * map.step - 0.5 * map.height) / map.width;
        map.white.at<float>(j, i) = static_cast<float>(r.white * (1 - 0.4 * (dx * dx + dy * dy)));
      }
    }
    r.brightness = std::move(map);
    responses.push_back(std::move(r));
  }
  const auto t_matched = std::chrono::steady_clock::now();
  auto matched = blend::makeTiledBlend(out.estimated, responses, cv::Size(1920, 1080));
  out.matched_display_s = seconds(t_matched);
  if (matched && matched->matched) {
    out.uniformity_before = matched->matched->before_min / matched->matched->before_max;
    out.uniformity_after = matched->matched->after_min / matched->matched->after_max;
  }
  const Seams s = seams(*made, out.truth, w.pixel_m);
  out.seam_rms = s.rms;
  out.seam_max = s.max;
  out.seam_points = s.points;
  if (several_views) {
    auto chained = blend::makeTiledBlend(chain, {}, cv::Size(1920, 1080));
    if (!chained) return out;
    const Seams c = seams(*chained, out.truth, w.pixel_m);
    out.chain_seam_rms = c.rms;
    out.chain_seam_max = c.max;
  }
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
     << "set multiplot layout 1,2 title 'Planar walls of N 1280x800 projectors, route (b'') "
        "from one camera or from cameras at several positions (homography tree), 0.1 px "
        "noise'\n"
     << "set logscale x\nset xlabel 'projectors'\nset ylabel 'seam error (projector px)'\n"
     << "set key top left\n"
     << "one(c) = strcol(3) eq 'one' ? column(c) : 1/0\n"
     << "views(c) = strcol(3) eq 'views_2x2' ? column(c) : 1/0\n"
     << "onev(x) = strcol(3) eq 'one' ? x : 1/0\n"
     << "viewsv(x) = strcol(3) eq 'views_2x2' ? x : 1/0\n"
     << "plot '" << csv << "' skip 1 using 1:(one(9)) with linespoints title 'one camera: RMS', "
     << "'' skip 1 using 1:(one(10)) with linespoints title 'one camera: max', "
     << "'' skip 1 using 1:(views(9)) with linespoints title '2x2 views, refined: RMS', "
     << "'' skip 1 using 1:(views(10)) with linespoints title '2x2 views, refined: max', "
     << "'' skip 1 using 1:(views(12)) with linespoints title '2x2 views, chain: RMS'\n"
     << "set ylabel 'seconds / capture frames'\nset logscale y\n"
     << "plot '" << csv
     << "' skip 1 using 1:(onev($6+$7)) with linespoints title 'one camera: "
        "compute (s)', "
     << "'' skip 1 using 1:(viewsv($6+$7)) with linespoints title '2x2 views: compute (s)', "
     << "'' skip 1 using 1:(one(4)) with linespoints title 'capture frames', "
     << "'' skip 1 using 1:(one(5)) with linespoints title 'capture frames, batched'\n"
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
  csv << "projectors,layout,cameras,capture_frames,capture_frames_batched,fit_s,display_s,"
         "seam_points,seam_rms_px,seam_max_px,chain_views,chain_seam_rms_px,chain_seam_max_px,"
         "matched_display_s,uniformity_before,uniformity_after\n";
  std::printf(
      "Calibration on synthetic planar walls (%d capture frames per projector scan; batched: "
      "a coarse pass of N + 1 frames, then projectors whose footprints do not meet scanned "
      "together)\n",
      frames_per_projector);
  std::mt19937 rng(15);
  for (const auto& [cols, rows] :
       std::vector<std::pair<int, int>>{{1, 1}, {2, 1}, {2, 2}, {3, 3}, {4, 4}}) {
    const testing::SyntheticWall wall = testing::syntheticWall(cols, rows, rng);
    const int n = cols * rows;
    const int batched = (n > 1 ? n + 1 : 0) + scanBatches(wall) * frames_per_projector;
    for (bool several : {false, true}) {
      const Calibrated c = calibrate(wall, several, rng);
      const char* cameras = several ? "views_2x2" : "one";
      if (!c.ok) {
        std::printf("  %2d projectors, %s: failed\n", n, cameras);
        csv << n << ',' << cols << 'x' << rows << ',' << cameras << ",,,,,,,,,,,,,\n";
        continue;
      }
      std::printf(
          "  %2d projectors (%dx%d), %-9s: %4d frames (batched %4d), fits %.3f s, display "
          "%.3f s, seams over %ld points RMS %.4f px, max %.4f px",
          n, cols, rows, several ? "2x2 views" : "one view", n * frames_per_projector, batched,
          c.fit_s, c.display_s, c.seam_points, c.seam_rms, c.seam_max);
      if (several) {
        std::printf("; %d views, chains of up to %d, chained alone RMS %.4f max %.4f", c.views,
                    c.deepest_chain, c.chain_seam_rms, c.chain_seam_max);
      }
      std::printf("; matched per pixel %.3f s (uniformity %.3f -> %.3f)\n", c.matched_display_s,
                  c.uniformity_before, c.uniformity_after);
      csv << n << ',' << cols << 'x' << rows << ',' << cameras << ',' << n * frames_per_projector
          << ',' << batched << ',' << c.fit_s << ',' << c.display_s << ',' << c.seam_points << ','
          << c.seam_rms << ',' << c.seam_max << ',' << c.deepest_chain << ','
          << (several ? c.chain_seam_rms : c.seam_rms) << ','
          << (several ? c.chain_seam_max : c.seam_max) << ',' << c.matched_display_s << ','
          << c.uniformity_before << ',' << c.uniformity_after << '\n';
    }
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
