// Render bench: the CPU warp of a 1920x1080 RGBA frame against cv::warpPerspective and
// cv::remap on the same input in the same run, and against a plain copy of the same
// bytes (the bandwidth floor); the GLES 3 headless output's frames per second at 1080p
// (render + read-back) on whatever EGL provides (Mesa llvmpipe here). Writes
// render_cpu.csv and render_gles.csv to --out DIR.
//
//   bench_render [--out DIR] [--runs N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "render/packed_map.hpp"
#include "render/remap_rgba.hpp"
#include "render/warp_map.hpp"
#if PROCAM_BENCH_GLES
#include "headless/headless_output.hpp"
#endif

using namespace procam;

namespace {

struct Timing {
  double median_ms = 0, min_ms = 0;
};

Timing measure(int runs, const std::function<void()>& fn) {
  fn();  // warm caches, thread pool and lazy allocations
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms.front()};
}

cv::Mat content(cv::Size size) {
  cv::Mat img(size, CV_8UC4);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.0);
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = ".";
  int runs = 30;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (a == "--runs" && i + 1 < argc) {
      runs = std::max(3, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_render [--out DIR] [--runs N]\n");
      return 2;
    }
  }
  std::filesystem::create_directories(out);
  const cv::Size size(1920, 1080);
  const cv::Mat src = content(size);
  // A keystone pre-warp: the content shrunk into an oblique quadrilateral.
  Mat3 H;
  H << 0.82, 0.06, 140, -0.04, 0.88, 70, 6e-5, -2.5e-5, 1;
  cv::Mat Hcv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Hcv.at<double>(r, c) = H(r, c);

  auto map = render::homographyMap(H, size);
  auto packed = map ? render::packMap(*map, size) : tl::unexpected(map.error());
  if (!packed) {
    std::fprintf(stderr, "bench_render: %s\n", packed.error().message.c_str());
    return 1;
  }
  cv::Mat dst(size, CV_8UC4), copy(size, CV_8UC4), ocv(size, CV_8UC4);
  std::vector<cv::Mat> xy;
  cv::split(map->xy, xy);
  cv::Mat m1, m2;
  cv::convertMaps(xy[0], xy[1], m1, m2, CV_16SC2);

  struct Row {
    std::string name;
    Timing t;
  };
  std::vector<Row> rows;
  rows.push_back(
      {"memcpy", measure(runs, [&] { std::memcpy(copy.data, src.data, src.total() * 4); })});
  rows.push_back({"procam_remap_simd", measure(runs, [&] {
                    (void)render::remapRgba(src, *packed, dst, render::RemapKernel::kBest);
                  })});
  rows.push_back({"procam_remap_scalar", measure(runs, [&] {
                    (void)render::remapRgba(src, *packed, dst, render::RemapKernel::kScalar);
                  })});
  rows.push_back({"cv_warpPerspective", measure(runs, [&] {
                    cv::warpPerspective(src, ocv, Hcv, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
                  })});
  rows.push_back({"cv_remap_fixed_maps", measure(runs, [&] {
                    cv::remap(src, ocv, m1, m2, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
                  })});
  rows.push_back({"cv_remap_float_maps", measure(runs, [&] {
                    cv::remap(src, ocv, xy[0], xy[1], cv::INTER_LINEAR, cv::BORDER_CONSTANT);
                  })});
  rows.push_back({"procam_map_build", measure(std::max(3, runs / 5), [&] {
                    auto m = render::homographyMap(H, size);
                    if (m) (void)render::packMap(*m, size);
                  })});

  const double copy_ms = rows[0].t.median_ms, warp_ms = rows[3].t.median_ms;
  std::ofstream csv(out / "render_cpu.csv");
  csv << "case,median_ms,min_ms,x_memcpy,x_warpPerspective,threads\n";
  std::printf("CPU 1920x1080 RGBA, %d runs, %d threads\n", runs, cv::getNumThreads());
  for (const auto& r : rows) {
    csv << r.name << ',' << r.t.median_ms << ',' << r.t.min_ms << ',' << r.t.median_ms / copy_ms
        << ',' << r.t.median_ms / warp_ms << ',' << cv::getNumThreads() << '\n';
    std::printf("  %-22s median %7.3f ms  min %7.3f ms  %5.2fx copy  %5.2fx warpPerspective\n",
                r.name.c_str(), r.t.median_ms, r.t.min_ms, r.t.median_ms / copy_ms,
                r.t.median_ms / warp_ms);
  }

#if PROCAM_BENCH_GLES
  std::ofstream gcsv(out / "render_gles.csv");
  gcsv << "case,renderer,median_ms,min_ms,fps\n";
  auto headless = output::HeadlessOutput::create(size);
  if (!headless) {
    std::printf("GLES: %s\n", headless.error().message.c_str());
    gcsv << "unavailable,\"" << headless.error().message << "\",,,\n";
    return 0;
  }
  render::RenderSetup setup;
  setup.output_size = size;
  setup.content_size = size;
  setup.homography = H;
  if (!(*headless)->configure(setup)) return 1;
  uint64_t version = 0;
  const Timing g = measure(runs, [&] { (void)(*headless)->show({&src, nullptr, ++version}); });
  const std::string gl = (*headless)->glRenderer();
  gcsv << "homography_upload_render_readback,\"" << gl << "\"," << g.median_ms << ',' << g.min_ms
       << ',' << 1000.0 / g.median_ms << '\n';
  std::printf(
      "GLES 1080p homography (upload + render + read-back) on %s: median %.2f ms, %.1f fps\n",
      gl.c_str(), g.median_ms, 1000.0 / g.median_ms);
#endif
  return 0;
}
