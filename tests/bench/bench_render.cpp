// Render bench at 1920x1080 RGBA8, every case on the same input in the same run:
//  - CPU homography pre-warp: procamd's packed-map remap (each kernel) against
//    cv::warpPerspective (INTER_LINEAR, BORDER_CONSTANT) and cv::remap of the same map
//    (CV_16SC2 fixed-point maps, OpenCV's fastest, and float maps);
//  - CPU lookup-table path (a dense post-render/lookup warp grid): procamd against
//    cv::remap with CV_16SC2 maps;
//  - the bandwidth floor: a copy of the same 8 MB into a distinct buffer, on one core
//    (memcpy) and on all cores (row stripes on OpenCV's pool, as the warps run).
// All CPU cases use the same thread count (cv::setNumThreads = hardware threads) and run
// twice: "warm" (the same buffers again and again, resident in the last-level cache when it
// holds them) and "cold" (before each timed call, untimed, a buffer of 4x the last-level
// cache is written, so source, map and destination come from memory as in a daemon whose
// frames arrive from elsewhere). Each warp's error is measured against the
// double-precision bilinear reference over the pixels whose sample lies at least half a
// pixel inside the source, where every implementation reads real texels.
//  - GLES 3 on the surfaceless EGL platform (Mesa llvmpipe here), per render path: frames
//    per second with content upload + draw + glFinish ("render"), and the same plus
//    glReadPixels of the frame ("render + read-back"); and the CPU renderer's planar 3D path
//    on the same triangles, on one thread and on all.
// Writes render_cpu.csv and render_gles.csv to --out DIR.
//
//   bench_render [--out DIR] [--runs N]
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <thread>
#include <vector>

#include "bench_timing.hpp"
#include "bench_warps.hpp"
#include "render/bilinear.hpp"
#include "render/cpu_renderer.hpp"
#include "render/packed_map.hpp"
#include "render/remap_rgba.hpp"
#include "render/warp_map.hpp"
#if PROCAM_BENCH_GLES
#include "../unit/render/render_test_rig.hpp"  // test camera rigs
#include "egl/egl_context.hpp"
#include "gl/gl_renderer.hpp"
#endif

using namespace procam;
using bench::measure;
using bench::Timing;

namespace {

cv::Mat content(cv::Size size) {
  cv::Mat img(size, CV_8UC4);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.0);
  return img;
}

// Touching this evicts every earlier buffer from the caches. Plain read-modify-write of
// each cache line: a large memset would use non-temporal stores that bypass the caches.
class CacheScrub {
 public:
  CacheScrub() {
    const long l3 = std::clamp<long>(sysconf(_SC_LEVEL3_CACHE_SIZE), 8L << 20, 64L << 20);
    lines_.resize(4 * static_cast<size_t>(l3));
  }
  void operator()() {
    for (size_t i = 0; i < lines_.size(); i += 64) lines_[i] = static_cast<uint8_t>(lines_[i] + 1);
    sink_ = lines_[lines_.size() / 2];
  }
  size_t size() const { return lines_.size(); }

 private:
  std::vector<uint8_t> lines_;
  volatile uint8_t sink_ = 0;
};

// Every output pixel's exact source coordinate (double) for the error reference.
using SourceOf = std::function<bool(int x, int y, double& sx, double& sy)>;

struct Error {
  double mean_abs = 0, max_abs = 0;
  long pixels = 0;
};

Error errorAgainstReference(const cv::Mat& src, const cv::Mat& out, const SourceOf& source_of) {
  Error e;
  double sum = 0;
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      double sx = 0, sy = 0;
      if (!source_of(x, y, sx, sy)) continue;
      if (!(sx >= 0 && sy >= 0 && sx <= src.cols - 1 && sy <= src.rows - 1)) continue;
      const cv::Vec4d ref = render::sampleBilinear(src, sx, sy);
      const cv::Vec4b v = out.at<cv::Vec4b>(y, x);
      for (int c = 0; c < 4; ++c) {
        const double d = std::abs(v[c] - ref[c]);
        sum += d;
        e.max_abs = std::max(e.max_abs, d);
      }
      ++e.pixels;
    }
  }
  e.mean_abs = e.pixels ? sum / (4.0 * e.pixels) : 0;
  return e;
}

struct Row {
  std::string path, name;
  Timing warm, cold;
  Error error;
  bool has_error = false;
};

cv::Mat toCv(const Mat3& m) {
  cv::Mat out(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.at<double>(r, c) = m(r, c);
  return out;
}

void printCpu(const Row& r, double copy_warm, double copy_cold, double ref_warm, double ref_cold) {
  std::printf(
      "  %-9s %-24s warm %7.3f ms (%5.2fx copy %5.2fx cv)  cold %7.3f ms (%5.2fx copy %5.2fx cv)",
      r.path.c_str(), r.name.c_str(), r.warm.median_ms, r.warm.median_ms / copy_warm,
      r.warm.median_ms / ref_warm, r.cold.median_ms, r.cold.median_ms / copy_cold,
      r.cold.median_ms / ref_cold);
  if (r.has_error) {
    std::printf("  err mean %.3f max %.1f", r.error.mean_abs, r.error.max_abs);
  }
  std::printf("\n");
}

#if PROCAM_BENCH_GLES
// A grid of coloured triangles covering the frame at depth 0 (pixel coordinates map
// straight to projector pixels: planar3d = identity).
render::ColoredMesh coloredGrid(cv::Size size, int n) {
  const Vec2 half(size.width / 2.0, size.height / 2.0);
  const render::SurfaceMesh grid = test::planeMesh(Vec3(half.x(), half.y(), 0), Vec3::UnitX(),
                                                   Vec3::UnitY(), half.x(), half.y(), n);
  render::ColoredMesh m{grid.vertices, {}, grid.triangles};
  for (const Vec3& v : grid.vertices) {
    m.colors.push_back(cv::Vec4b(uint8_t(40 + 200 * v.x() / size.width),
                                 uint8_t(40 + 200 * v.y() / size.height), 128, 255));
  }
  return m;
}

void benchGles(const std::filesystem::path& out, cv::Size size, const cv::Mat& src, const Mat3& H,
               int runs) {
  std::ofstream csv(out / "render_gles.csv");
  csv << "path,renderer,render_ms,render_fps,render_readback_ms,render_readback_fps\n";
  auto ctx = output::egl::EglContext::surfaceless();
  if (!ctx) {
    std::printf("GLES: unavailable: %s\n", ctx.error().message.c_str());
    csv << "unavailable,\"" << ctx.error().message << "\",,,,\n";
    return;
  }
  auto gl = output::gl::GlRenderer::create(output::gl::GlTarget{true, 0});
  if (!gl) {
    std::printf("GLES: %s\n", gl.error().message.c_str());
    return;
  }
  const std::string name = (*ctx)->renderer();
  std::printf("GLES 3 at %dx%d on %s, %d runs (content upload included in every frame)\n",
              size.width, size.height, name.c_str(), runs);

  struct Case {
    const char* path;
    render::RenderSetup setup;
  };
  std::vector<Case> cases;
  render::RenderSetup base;
  base.output_size = size;
  base.content_size = size;
  base.homography = H;
  cases.push_back({"homography", base});
  render::RenderSetup lookup = base;
  lookup.path = render::RenderPath::kLookupWarp;
  lookup.lookup = bench::lookupGrid(size);
  cases.push_back({"lookup", lookup});
  render::RenderSetup post = base;
  post.post_warp = bench::lookupGrid(size);
  cases.push_back({"homography+post_warp", post});
  render::RenderSetup mesh = base;
  mesh.path = render::RenderPath::kTwoPassMesh;
  mesh.surface = test::domeMesh(Vec3(0, 0, 0), 2.0, 32, 96);
  mesh.projector = test::lookAtProjection(1560, 959.5, 539.5, Vec3(0.3, 0.2, 0.1),
                                          Vec3(0.3, 2, 0.5), Vec3::UnitZ());
  mesh.viewer = test::lookAtProjection(900, 959.5, 539.5, Vec3(-0.2, 0.1, -0.3), Vec3(0, 2, 0.2),
                                       Vec3::UnitZ());
  cases.push_back({"two_pass_mesh", mesh});
  render::RenderSetup planar = base;
  planar.path = render::RenderPath::kPlanar3d;
  planar.planar3d = Mat4::Identity();
  cases.push_back({"planar3d", planar});
  const render::ColoredMesh triangles = coloredGrid(size, 64);

  cv::Mat frame;
  uint64_t version = 0;
  for (const Case& c : cases) {
    if (auto ok = (*gl)->configure(c.setup); !ok) {
      std::printf("  %-22s %s\n", c.path, ok.error().message.c_str());
      continue;
    }
    const bool is3d = c.setup.path == render::RenderPath::kPlanar3d;
    const render::Content content =
        is3d ? render::Content{nullptr, &triangles, 0} : render::Content{&src, nullptr, 0};
    auto draw = [&] {
      render::Content next = content;
      next.version = ++version;  // a new frame each time: nothing is skipped
      (void)(*gl)->render(next);
    };
    draw();
    (void)(*gl)->readFrame(frame);  // compile shaders, allocate, warm the driver
    const Timing render = measure(runs, [&] {
      draw();
      glFinish();
    });
    const Timing readback = measure(runs, [&] {
      draw();
      (void)(*gl)->readFrame(frame);
    });
    csv << c.path << ",\"" << name << "\"," << render.median_ms << ',' << 1000 / render.median_ms
        << ',' << readback.median_ms << ',' << 1000 / readback.median_ms << '\n';
    std::printf("  %-22s render %7.2f ms %6.1f fps   render + read-back %7.2f ms %6.1f fps\n",
                c.path, render.median_ms, 1000 / render.median_ms, readback.median_ms,
                1000 / readback.median_ms);
  }
  // The CPU back-end's planar 3D path on the same triangles, one thread and all.
  const int threads = cv::getNumThreads();
  for (int n : {1, threads}) {
    cv::setNumThreads(n);
    render::CpuRenderer cpu;
    if (!cpu.configure(cases.back().setup)) continue;
    const Timing t = measure(runs, [&] { (void)cpu.render({nullptr, &triangles, ++version}); });
    std::printf("  CPU planar3d, %d thread(s): %7.2f ms %6.1f fps\n", n, t.median_ms,
                1000 / t.median_ms);
  }
  cv::setNumThreads(threads);
}
#endif

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = ".";
  int runs = 30;
  if (!bench::benchOptions(argc, argv, "bench_render", out, runs, 3)) return 2;
  const int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  cv::setNumThreads(threads);
  const cv::Size size(1920, 1080);
  const cv::Mat src = content(size);
  // A keystone pre-warp: the content shrunk into an oblique quadrilateral.
  Mat3 H;
  H << 0.82, 0.06, 140, -0.04, 0.88, 70, 6e-5, -2.5e-5, 1;
  const Mat3 Hinv = H.inverse();

  auto hmap = render::homographyMap(H, size);
  auto lmap = render::gridMap(bench::lookupGrid(size), size);
  if (!hmap || !lmap) {
    std::fprintf(stderr, "bench_render: cannot build the maps\n");
    return 1;
  }
  auto hpacked = render::packMap(*hmap, size);
  auto lpacked = render::packMap(*lmap, size);
  if (!hpacked || !lpacked) {
    std::fprintf(stderr, "bench_render: cannot pack the maps\n");
    return 1;
  }
  auto fixedMaps = [](const render::WarpMap& m, cv::Mat& m1, cv::Mat& m2, cv::Mat& fx,
                      cv::Mat& fy) {
    std::vector<cv::Mat> xy;
    cv::split(m.xy, xy);
    fx = xy[0];
    fy = xy[1];
    cv::convertMaps(fx, fy, m1, m2, CV_16SC2);
  };
  cv::Mat h1, h2, hfx, hfy, l1, l2, lfx, lfy;
  fixedMaps(*hmap, h1, h2, hfx, hfy);
  fixedMaps(*lmap, l1, l2, lfx, lfy);

  const SourceOf homography_source = [&](int x, int y, double& sx, double& sy) {
    const Vec3 p = Hinv * Vec3(x, y, 1);
    if (p.z() <= 0) return false;
    sx = p.x() / p.z();
    sy = p.y() / p.z();
    return true;
  };
  // The lookup map is defined by its float entries (gridMap evaluates the grid in double).
  const SourceOf lookup_source = [&](int x, int y, double& sx, double& sy) {
    const cv::Vec2f v = lmap->xy.at<cv::Vec2f>(y, x);
    if (v[0] == render::kOutside) return false;
    sx = v[0];
    sy = v[1];
    return true;
  };

  CacheScrub scrub;
  cv::Mat copy(size, CV_8UC4), dst(size, CV_8UC4);
  const size_t bytes = src.total() * src.elemSize();
  std::vector<Row> rows;
  struct Case {
    std::string path, name;
    std::function<void()> body;
    const SourceOf* source_of;  // null: no error to measure
  };
  std::vector<Case> cases;
  auto run = [&](const char* path, const char* name, std::function<void()> body,
                 const SourceOf* source_of) {
    cases.push_back({path, name, std::move(body), source_of});
  };
  using render::RemapKernel;
  run(
      "copy", "memcpy_1_thread", [&] { std::memcpy(copy.data, src.data, bytes); }, nullptr);
  run(
      "copy", "copy_all_threads",
      [&] {
        cv::parallel_for_(
            cv::Range(0, size.height),
            [&](const cv::Range& r) {
              std::memcpy(copy.ptr(r.start), src.ptr(r.start), (r.end - r.start) * src.step);
            },
            threads);
      },
      nullptr);
  const struct {
    RemapKernel kernel;
    const char* name;
  } kernels[] = {{RemapKernel::kBest, "procam_map_best"},
                 {RemapKernel::kSse2, "procam_map_sse2"},
                 {RemapKernel::kScalar, "procam_map_scalar"}};
  for (const auto& k : kernels) {
    run(
        "homography", k.name, [&] { (void)render::remapRgba(src, *hpacked, dst, k.kernel); },
        &homography_source);
  }
  const cv::Mat Hcv = toCv(H);
  run(
      "homography", "cv_warpPerspective",
      [&] { cv::warpPerspective(src, dst, Hcv, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT); },
      &homography_source);
  run(
      "homography", "cv_remap_16SC2",
      [&] { cv::remap(src, dst, h1, h2, cv::INTER_LINEAR, cv::BORDER_CONSTANT); },
      &homography_source);
  run(
      "homography", "cv_remap_32F",
      [&] { cv::remap(src, dst, hfx, hfy, cv::INTER_LINEAR, cv::BORDER_CONSTANT); },
      &homography_source);
  run(
      "lookup", "procam_map_best",
      [&] { (void)render::remapRgba(src, *lpacked, dst, RemapKernel::kBest); }, &lookup_source);
  run(
      "lookup", "cv_remap_16SC2",
      [&] { cv::remap(src, dst, l1, l2, cv::INTER_LINEAR, cv::BORDER_CONSTANT); }, &lookup_source);
  run(
      "map_build", "homography_map_and_pack",
      [&] {
        auto m = render::homographyMap(H, size);
        if (m) (void)render::packMap(*m, size);
      },
      nullptr);

  // Every case timed in turn, round after round, so that a load coming and going on this
  // shared machine falls on all of them alike; the first call warms the thread pool and
  // lazy allocations.
  std::vector<std::function<void()>> bodies;
  for (const Case& c : cases) {
    c.body();
    bodies.push_back(c.body);
  }
  const std::vector<Timing> warm = bench::measureInterleaved(runs, bodies);
  const std::vector<Timing> cold = bench::measureInterleaved(runs, bodies, [&] { scrub(); });
  for (size_t i = 0; i < cases.size(); ++i) {
    Row r{cases[i].path, cases[i].name, warm[i], cold[i], {}, false};
    if (cases[i].source_of) {
      dst.setTo(cv::Scalar::all(0));
      cases[i].body();
      r.error = errorAgainstReference(src, dst, *cases[i].source_of);
      r.has_error = true;
    }
    rows.push_back(r);
  }

  auto find = [&](const char* path, const char* name) -> const Row& {
    for (const Row& r : rows)
      if (r.path == path && r.name == name) return r;
    return rows.front();
  };
  const Row& copy_row = find("copy", "copy_all_threads");
  std::ofstream csv(out / "render_cpu.csv");
  csv << "path,case,threads,warm_median_ms,warm_min_ms,cold_median_ms,cold_min_ms,"
         "warm_x_copy,cold_x_copy,warm_x_opencv,cold_x_opencv,err_mean_abs,err_max_abs,"
         "err_pixels\n";
  std::printf(
      "CPU %dx%d RGBA8 (%.1f MB), %d runs, %d threads; cold = caches evicted (%zu MB "
      "written) before each run; copy = copy_all_threads; cv = the OpenCV reference of "
      "the path; err in code values vs the double-precision bilinear reference\n",
      size.width, size.height, bytes / 1e6, runs, threads, scrub.size() >> 20);
  for (const Row& r : rows) {
    const Row& ref = r.path == "lookup" ? find("lookup", "cv_remap_16SC2")
                                        : find("homography", "cv_warpPerspective");
    csv << r.path << ',' << r.name << ',' << threads << ',' << r.warm.median_ms << ','
        << r.warm.min_ms << ',' << r.cold.median_ms << ',' << r.cold.min_ms << ','
        << r.warm.median_ms / copy_row.warm.median_ms << ','
        << r.cold.median_ms / copy_row.cold.median_ms << ','
        << r.warm.median_ms / ref.warm.median_ms << ',' << r.cold.median_ms / ref.cold.median_ms
        << ',';
    if (r.has_error)
      csv << r.error.mean_abs << ',' << r.error.max_abs << ',' << r.error.pixels;
    else
      csv << ",,";
    csv << '\n';
    printCpu(r, copy_row.warm.median_ms, copy_row.cold.median_ms, ref.warm.median_ms,
             ref.cold.median_ms);
  }

#if PROCAM_BENCH_GLES
  benchGles(out, size, src, H, std::max(5, runs / 3));
#endif
  return 0;
}
