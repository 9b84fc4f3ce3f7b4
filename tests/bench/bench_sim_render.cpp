// Virtual-rig render bench: time to render wall_oblique's 1280x960 camera while its
// 1920x1080 projector shows a checkerboard, on one core, split into framebuffer
// preparation (gamma LUT + footprint blur), ray casting/shading and the sensor
// model, and for a still scene the light paths' trace and the radiance lit from
// them (what every capture after the second costs while nothing moves). Baseline in the same run:
// cv::warpPerspective of the framebuffer into the camera image through the wall homography (the
// cheapest possible "rendering" of a plane, no distortion, photometry, shadows or noise).
//
//   bench_sim_render [--out DIR] [--runs N]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "bench_timing.hpp"
#include "sim/projector_image.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"

using namespace procam;
using namespace procam::sim;
using procam::bench::measure;
using procam::bench::Timing;

namespace {

cv::Mat checkerboard(int width, int height, int square) {
  cv::Mat fb(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      fb.at<cv::Vec3b>(y, x) =
          ((x / square + y / square) % 2) ? cv::Vec3b(255, 255, 255) : cv::Vec3b(0, 0, 0);
  return fb;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = ".";
  int runs = 5;
  if (!bench::benchOptions(argc, argv, "bench_sim_render", out, runs, 1)) return 2;
  cv::setNumThreads(1);  // single core, OpenCV's own filters included

  auto scene = resolveScene("wall_oblique");
  if (!scene) {
    std::fprintf(stderr, "bench_sim_render: %s\n", scene.error().message.c_str());
    return 1;
  }
  const SceneState state = scene->at(0);
  const ProjectorState& proj = state.projectors.at(0);
  const CameraState& cam = state.cameras.at(0);
  const cv::Mat fb = checkerboard(proj.model.width, proj.model.height, 60);

  RenderOptions options;
  options.threads = 1;
  options.seed = 3;
  cv::Mat image;
  const Timing full = measure(runs, [&] {
    auto r = Renderer::create(*scene, state, {{"proj", fb}});
    image = *r->renderCamera(cam.spec.name, options);
  });
  const Timing prepare = measure(runs, [&] { (void)ProjectorImage::create(fb, proj.spec); });
  auto renderer = Renderer::create(*scene, state, {{"proj", fb}});
  const Timing radiance = measure(runs, [&] { (void)renderer->cameraRadiance(cam.spec.name, 1); });
  const Timing camera =
      measure(runs, [&] { (void)renderer->renderCamera(cam.spec.name, options); });
  // A still scene: its light paths traced once, then every capture lit from them.
  std::optional<LightPaths> paths;
  const Timing trace =
      measure(runs, [&] { paths = std::move(*renderer->cameraLightPaths(cam.spec.name, 1)); });
  const Timing relight =
      measure(runs, [&] { (void)renderer->cameraRadiance(cam.spec.name, *paths, 1); });

  // Baseline: framebuffer -> camera through the wall homography (plane y = 3).
  const Mat34 Pp = proj.model.projectionMatrix(), Pc = cam.model.projectionMatrix();
  Mat3 Hp, Hc;  // wall point (x, z, 1) -> image
  Hp << Pp.col(0), Pp.col(2), Pp.col(1) * 3.0 + Pp.col(3);
  Hc << Pc.col(0), Pc.col(2), Pc.col(1) * 3.0 + Pc.col(3);
  const Mat3 H = Hc * Hp.inverse();
  cv::Mat Hcv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Hcv.at<double>(r, c) = H(r, c);
  cv::Mat warped;
  const Timing warp = measure(runs, [&] {
    cv::warpPerspective(fb, warped, Hcv, cv::Size(cam.model.width, cam.model.height),
                        cv::INTER_LINEAR);
  });

  const double samples = double(cam.model.width) * cam.model.height * cam.spec.supersamples;
  std::ofstream csv(out / "bench_sim_render.csv");
  csv << "case,camera,projector,supersamples,threads,median_ms,min_ms,ns_per_sample,"
         "x_warpPerspective\n";
  auto row = [&](const char* name, const Timing& t) {
    csv << name << ',' << cam.model.width << 'x' << cam.model.height << ',' << proj.model.width
        << 'x' << proj.model.height << ',' << cam.spec.supersamples << ",1," << t.median_ms << ','
        << t.min_ms << ',' << t.median_ms * 1e6 / samples << ',' << t.median_ms / warp.median_ms
        << '\n';
    std::printf("%-34s median %9.2f ms  min %9.2f ms  %7.1f ns/sample  %7.1fx warpPerspective\n",
                name, t.median_ms, t.min_ms, t.median_ms * 1e6 / samples,
                t.median_ms / warp.median_ms);
  };
  row("sim_render_total", full);
  row("sim_prepare_framebuffer", prepare);
  row("sim_camera_radiance", radiance);
  row("sim_render_camera", camera);
  row("sim_trace_light_paths", trace);
  row("sim_radiance_from_light_paths", relight);
  row("baseline_cv_warpPerspective", warp);
  std::printf("wrote %s\n", (out / "bench_sim_render.csv").c_str());
  return 0;
}
