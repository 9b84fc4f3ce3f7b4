// Frame time per output for a still keystoned 1920x1080 image, through the driver plugin
// ABI as procamd drives its outputs, on two back-ends in the same run: the virtual rig's
// mock output (CPU reference renderer) and the headless GLES output (EGL surfaceless: Mesa
// llvmpipe on a machine without a GPU, the GPU's driver where there is one).
//
//  before     the frame path procamd had before outputs rendered themselves, per frame: a
//             new CPU renderer (its warp map built again), the frame converted RGBA -> RGB,
//             its statistics, `show` (converted back to RGBA, uploaded and drawn 1:1);
//  unchanged  render setup and content unchanged: the output skips the frame (the cost
//             of asking);
//  geometry   the homography changes every frame (a handheld projector's keystone): the
//             setup is handed over, the content stays where it is (CPU: map rebuilt;
//             GLES: one quad, no upload);
//  content    new content every frame (video): uploaded every frame (GLES: through
//             pixel-buffer objects), geometry unchanged;
//  stats      `still` plus the frame statistics status reports (a read-back on GLES).
// Frames are issued back to back and timed over a batch (10 frames on the CPU, 50 on GLES)
// ended by one read-back with statistics (the pipeline drained), so a figure is the
// steady-state time per frame including 1/batch of that read-back.
// Writes output_frames.csv to --out DIR.
//
//   bench_output [--out DIR] [--runs N]
#include <procamd/procam_plugin.h>

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

#include "bench_timing.hpp"
#include "render/cpu_renderer.hpp"
#include "render/frame_stats.hpp"
#include "support/render_abi.hpp"

extern "C" const procam_plugin_table* procam_sim_plugin_entry(void);
#if PROCAM_BENCH_GLES
extern "C" const procam_plugin_table* procam_output_plugin_entry(void);
#endif

using namespace procam;

namespace {

struct OutputDevice {
  procam_device dev{};
  bool ok = false;
  ~OutputDevice() {
    if (ok && dev.destroy) dev.destroy(dev.self);
  }
};

bool create(const procam_plugin_table* table, const char* factory, const char* subsystem,
            std::vector<procam_kv> props, std::vector<procam_kv> options, OutputDevice& out) {
  for (size_t i = 0; i < table->n_factories; ++i) {
    const procam_driver_factory& f = table->factories[i];
    if (std::strcmp(f.name, factory) != 0) continue;
    procam_device_desc d{};
    d.family = PROCAM_FAMILY_OUTPUT;
    d.subsystem = subsystem;
    d.name = factory;
    d.properties = props.data();
    d.n_properties = props.size();
    const procam_config c{options.data(), options.size()};
    char err[512] = {};
    if (f.create(&d, &c, &out.dev, err, sizeof err - 1) != PROCAM_OK) {
      std::printf("  %s: %s\n", factory, err);
      return false;
    }
    out.ok = true;
    return true;
  }
  std::printf("  no driver %s\n", factory);
  return false;
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Median over `rounds` of the mean time per frame of `batch` frames, each batch closed by
// `drain` (untimed when null).
double perFrame(int rounds, int batch, const std::function<void(int)>& frame,
                const std::function<void()>& drain) {
  std::vector<double> ms;
  int n = 0;
  for (int r = 0; r < rounds; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < batch; ++i) frame(n++);
    if (drain) drain();
    ms.push_back(msSince(t0) / batch);
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

void benchOutput(const char* backend, OutputDevice& out, int rounds, int batch,
                 std::ofstream& csv) {
  const procam_output_ops& ops = *out.dev.ops.output;
  void* self = out.dev.self;
  uint32_t w = 0, h = 0;
  double hz = 0;
  ops.get_mode(self, &w, &h, &hz);
  const cv::Size size(static_cast<int>(w), static_cast<int>(h));
  cv::Mat images[2];
  for (int k = 0; k < 2; ++k) {
    images[k].create(size, CV_8UC4);
    cv::randu(images[k], cv::Scalar::all(0), cv::Scalar::all(256));
  }
  render::RenderSetup setups[2];
  for (int k = 0; k < 2; ++k) {
    setups[k].output_size = setups[k].content_size = size;
    setups[k].homography << 0.82, 0.06, 140 + k, -0.04, 0.88, 70, 6e-5, -2.5e-5, 1;
  }
  char err[512] = {};
  auto check = [&](int rc, const char* what) {
    if (rc != PROCAM_OK) std::printf("  %s %s: %s\n", backend, what, err);
  };
  auto configure = [&](int k) {
    const plugins::RenderSetupView v(setups[k]);
    check(ops.configure(self, &v.get(), err, sizeof err - 1), "configure");
  };
  uint64_t version = 1;
  auto render = [&](int k, bool stats) {
    const plugins::ContentView c(&images[k], nullptr, version);
    int drawn = 0;
    procam_frame_stats st{};
    check(ops.render(self, &c.get(), &drawn, stats ? &st : nullptr, err, sizeof err - 1), "render");
  };
  // Ends a batch: the statistics read the frame back, which waits for the GPU.
  auto drain = [&] { render(0, true); };

  // before: the daemon's old per-frame work, then `show` of an RGB frame.
  const double before = perFrame(
      rounds, batch,
      [&](int) {
        render::CpuRenderer cpu;
        (void)cpu.configure(setups[0]);
        (void)cpu.render({&images[0], nullptr, 1});
        cv::Mat rgb;
        cv::cvtColor(cpu.frame(), rgb, cv::COLOR_RGBA2RGB);
        (void)render::frameStats(rgb);
        const procam_image im{w,        h, static_cast<uint32_t>(rgb.step[0]), PROCAM_PIXEL_RGB8,
                              rgb.data, 0};
        check(ops.show(self, &im, err, sizeof err - 1), "show");
      },
      nullptr);

  configure(0);
  render(0, false);
  // unchanged: the same version and setup again; the output skips the frame.
  const double still = perFrame(
      rounds, batch, [&](int) { render(0, false); }, drain);
  const double geometry = perFrame(
      rounds, batch,
      [&](int i) {
        configure(i & 1);
        render(0, false);
      },
      drain);
  const double content = perFrame(
      rounds, batch,
      [&](int i) {
        ++version;
        render(i & 1, false);
      },
      drain);
  const double stats = perFrame(
      rounds, batch,
      [&](int i) {
        configure(i & 1);
        render(0, true);
      },
      nullptr);
  std::printf(
      "  %-8s before %8.3f ms   unchanged %8.4f ms   geometry %8.3f ms   content %8.3f ms"
      "   geometry+stats %8.3f ms   (before/geometry %.1fx)\n",
      backend, before, still, geometry, content, stats, before / geometry);
  csv << backend << ',' << before << ',' << still << ',' << geometry << ',' << content << ','
      << stats << '\n';
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = ".";
  int rounds = 7, batch = 10;
  if (!bench::benchOptions(argc, argv, "bench_output", out, rounds, 3)) return 2;
  std::ofstream csv(out / "output_frames.csv");
  csv << "backend,before_ms,unchanged_ms,geometry_ms,content_ms,geometry_stats_ms\n";
  std::printf("Output frame time, 1920x1080 RGBA, median of %d batches\n", rounds);
  {
    OutputDevice mock;
    if (create(procam_sim_plugin_entry(), "sim-output", "sim",
               {{"SIM_SCENE", "wall_oblique"}, {"SIM_DEVICE", "proj"}}, {}, mock)) {
      benchOutput("mock-cpu", mock, rounds, batch, csv);
    }
  }
#if PROCAM_BENCH_GLES
  {
    OutputDevice gl;
    if (create(procam_output_plugin_entry(), "headless", "headless", {},
               {{"width", "1920"}, {"height", "1080"}}, gl)) {
      // Long batches: the read-back closing each one (~4 ms) is spread thin.
      benchOutput("gles", gl, rounds, 5 * batch, csv);
    }
  }
#endif
  return 0;
}
