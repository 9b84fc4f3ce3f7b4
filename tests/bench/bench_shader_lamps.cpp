// Shader lamps ([Raskar02] §5.2) on a 50k-triangle object (the vase of object_vase,
// tessellated finely: ball and neck) lit by three 1920x1080 projectors:
//  - once per rig or object change: each projector's view of the object (a ray per pixel
//    through the mesh's BVH), the weights of the three (depth edges, distance transforms,
//    the normalisation against the others' views) and the coverage report;
//  - per frame and projector: the radiance-corrected frame (eq. 5.4) for a textured
//    diffuse look and for a glossy one shaded for a tracked eye, against OpenCV's
//    cv::remap of a 1080p BGR texture through a float map (one bilinear look-up per
//    pixel: the least a textured frame costs) in the same run, as a ratio.
//  - per frame and projector with GLES 3 (the surfaceless EGL platform when built; Mesa
//    llvmpipe here, a GPU on a rig):
//    - the shading on the GPU (gl/gl_lamp_shader.hpp): the view's buffers uploaded once
//      per rig, then per frame the textured diffuse look and the glossy one for a tracked
//      eye shaded by the fragment program (glFinish), and with the frame read back; the
//      read-back frame against lampFrame's (largest difference in code values, share of
//      lit pixels that differ: float against double rounding);
//    - what procamd's outputs do with a frame shaded on the CPU: the RGBA frame uploaded
//      and drawn through the homography path with H = I, then glFinish, alone, and a
//      tracked eye's whole update (CPU shading, RGBA, shown), and that the frame read back
//      is the one shaded.
// Error beside the time: the largest departure of the weights' sum from one at the pixel
// centres of the first projector (exact by construction: it guards the normalisation),
// and the share of lit pixels whose intensity clipped.
// Writes shader_lamps.csv to --out DIR.
//
//   bench_shader_lamps [--out DIR] [--runs N]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "bench_timing.hpp"
#include "integration/object_meshes.hpp"
#include "shader_lamps/lamp_frame.hpp"
#include "shader_lamps/lamp_view.hpp"
#include "shader_lamps/lamp_weights.hpp"
#include "shader_lamps/object_model.hpp"
#include "unit/shader_lamps/lamp_rig.hpp"
#if PROCAM_BENCH_GLES
#include "egl/egl_context.hpp"
#include "gl/gl_lamp_shader.hpp"
#include "gl/gl_renderer.hpp"
#endif

using namespace procam;

namespace {

geom::CameraModel projector(const Vec3& at) {
  return lamps::test::projectorAt(at, Vec3(0, 1.5, 0.9), 1920, 1080, 3400);
}

#if PROCAM_BENCH_GLES
// The frames shaded by the GLES program, against lampFrame's.
void benchGlesShading(std::ofstream& csv, int runs, const lamps::LampFrameInput& lamp,
                      const lamps::Material& textured, const lamps::Material& glossy, double white,
                      double remap_ms) {
  auto shader = output::gl::GlLampShader::create();
  if (!shader) {
    std::printf("GLES shading: %s\n", shader.error().message.c_str());
    return;
  }
  output::gl::GlLampShader& gl = **shader;
  const Vec3 eye(0, 0.3, 1.4);
  const bench::Timing upload = bench::measure(runs, [&] {
    (void)gl.setView(lamp);
    glFinish();
  });
  (void)gl.setMaterial(glossy);
  cv::Mat frame;
  (void)gl.shade(white, eye);
  (void)gl.readFrame(frame);  // compile, allocate, warm the driver
  cv::Mat diff;
  cv::absdiff(frame, *lamps::lampFrame(lamp, glossy, white, eye), diff);
  const double largest = cv::norm(diff, cv::NORM_INF);
  cv::Mat any;
  cv::transform(diff, any, cv::Matx13f(1, 1, 1));
  const long differing = cv::countNonZero(any);
  const long lit = cv::countNonZero(*lamp.weight > 0);
  (void)gl.setMaterial(textured);
  const bench::Timing diffuse = bench::measure(runs, [&] {
    (void)gl.shade(white, std::nullopt);
    glFinish();
  });
  (void)gl.setMaterial(glossy);
  const bench::Timing tracked = bench::measure(runs, [&] {
    (void)gl.shade(white, eye);
    glFinish();
  });
  const bench::Timing read = bench::measure(runs, [&] {
    (void)gl.shade(white, eye);
    (void)gl.readFrame(frame);
  });
  std::printf(
      "GLES shading: view upload (once per rig) %.1f ms median; frame textured %.1f ms "
      "(%.2fx cv::remap), glossy for a tracked eye %.1f ms (%.2fx), with read-back %.1f "
      "ms; against lampFrame: largest difference %.0f code values, %ld of %ld lit "
      "pixels differ\n",
      upload.median_ms, diffuse.median_ms, diffuse.median_ms / remap_ms, tracked.median_ms,
      tracked.median_ms / remap_ms, read.median_ms, largest, differing, lit);
  csv << "gles_view_upload," << upload.median_ms << ',' << upload.min_ms << ",\n";
  csv << "gles_shade_textured," << diffuse.median_ms << ',' << diffuse.min_ms << ','
      << diffuse.median_ms / remap_ms << '\n';
  csv << "gles_shade_glossy," << tracked.median_ms << ',' << tracked.min_ms << ','
      << tracked.median_ms / remap_ms << '\n';
  csv << "gles_shade_glossy_readback," << read.median_ms << ',' << read.min_ms << ','
      << read.median_ms / remap_ms << '\n';
  csv << "# GLES shading against lampFrame: largest difference " << largest << " code values, "
      << differing << " of " << lit << " lit pixels differ\n";
}

// A shaded frame on the headless GLES output, as procamd shows it (H = I), and the
// shading on the GPU.
void benchGles(std::ofstream& csv, int runs, const lamps::LampFrameInput& lamp,
               const lamps::Material& textured, const lamps::Material& glossy, double white,
               double remap_ms) {
  auto ctx = output::egl::EglContext::surfaceless();
  if (!ctx) {
    std::printf("GLES: unavailable: %s\n", ctx.error().message.c_str());
    csv << "gles_unavailable,,,\n";
    return;
  }
  benchGlesShading(csv, runs, lamp, textured, glossy, white, remap_ms);
  auto gl = output::gl::GlRenderer::create(output::gl::GlTarget{true, 0});
  if (!gl) {
    std::printf("GLES: %s\n", gl.error().message.c_str());
    return;
  }
  render::RenderSetup setup;
  setup.output_size = lamp.view->size;
  setup.content_size = lamp.view->size;
  setup.homography = Mat3::Identity();
  if (auto ok = (*gl)->configure(setup); !ok) {
    std::printf("GLES: %s\n", ok.error().message.c_str());
    return;
  }
  const Vec3 eye(0, 0.3, 1.4);
  cv::Mat rgba, shown;
  cv::cvtColor(*lamps::lampFrame(lamp, glossy, white, eye), rgba, cv::COLOR_BGR2RGBA);
  uint64_t version = 0;
  (void)(*gl)->render({&rgba, nullptr, ++version});
  (void)(*gl)->readFrame(shown);  // compile shaders, allocate, warm the driver
  const double diff = cv::norm(rgba, shown, cv::NORM_INF);
  const bench::Timing show = bench::measure(runs, [&] {
    (void)(*gl)->render({&rgba, nullptr, ++version});  // a new frame each time
    glFinish();
  });
  const bench::Timing update = bench::measure(runs, [&] {
    cv::cvtColor(*lamps::lampFrame(lamp, glossy, white, eye), rgba, cv::COLOR_BGR2RGBA);
    (void)(*gl)->render({&rgba, nullptr, ++version});
    glFinish();
  });
  std::printf(
      "GLES (%s), the frame shown (H = I): %.1f ms median; a tracked eye's update "
      "(shade on the CPU + show) %.1f ms median (%.2fx cv::remap); shown frame off "
      "the shaded one by %.0f code values at most\n",
      (*ctx)->renderer().c_str(), show.median_ms, update.median_ms, update.median_ms / remap_ms,
      diff);
  csv << "gles_show," << show.median_ms << ',' << show.min_ms << ',' << show.median_ms / remap_ms
      << '\n';
  csv << "gles_glossy_update," << update.median_ms << ',' << update.min_ms << ','
      << update.median_ms / remap_ms << '\n';
  csv << "# GLES renderer " << (*ctx)->renderer() << "; shown frame off the shaded one by " << diff
      << " code values at most\n";
}
#endif

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = ".";
  int runs = 5;
  if (!bench::benchOptions(argc, argv, "bench_shader_lamps", out, runs)) return 2;
  const itest::ObjectMesh vase =
      itest::vaseMesh(Vec3(0, 1.5, 0.85), 0.1, Vec3(0, 1.5, 0.93), 0.045, 0.1, 216);
  auto object = lamps::ObjectModel::build(vase.mesh, vase.uv);
  if (!object) {
    std::fprintf(stderr, "%s\n", object.error().message.c_str());
    return 1;
  }
  const std::vector<geom::CameraModel> models = {projector(Vec3(-0.7, 0.5, 1.6)),
                                                 projector(Vec3(0.7, 0.5, 1.6)),
                                                 projector(Vec3(0.2, 2.7, 1.9))};
  std::printf("object: %zu triangles; 3 projectors at 1920x1080, %d runs\n",
              object->mesh().faces.size(), runs);
  std::vector<lamps::LampView> views(models.size());
  const bench::Timing view_time =
      bench::measure(runs, [&] { views[0] = *lamps::castLampView(models[0], *object); });
  for (std::size_t i = 1; i < models.size(); ++i)
    views[i] = *lamps::castLampView(models[i], *object);
  std::vector<lamps::Lamp> set;
  for (std::size_t i = 0; i < models.size(); ++i) set.push_back({&models[i], &views[i], true});
  lamps::LampWeights weights;
  const bench::Timing weight_time =
      bench::measure(runs, [&] { weights = *lamps::lampWeights(set); });
  const bench::Timing coverage_time = bench::measure(
      std::max(1, runs / 2), [&] { (void)lamps::lampCoverage(set, weights, *object); });

  // Per frame.
  lamps::Material textured;
  textured.texture = cv::Mat(1024, 1024, CV_32FC3);
  cv::randu(textured.texture, cv::Scalar::all(0.2), cv::Scalar::all(0.9));
  cv::GaussianBlur(textured.texture, textured.texture, cv::Size(0, 0), 8);
  lamps::Material glossy = textured;
  glossy.specular_rgb = Vec3::Constant(0.3);
  glossy.light_dir = Vec3(0.3, -0.6, 0.75);
  std::vector<lamps::LampFrameInput> inputs;
  for (std::size_t i = 0; i < models.size(); ++i)
    inputs.push_back({&views[i], &weights.weight[i], {2.2, Vec3(300, 290, 280)}});
  const double white = *lamps::lampWhiteLevel(inputs);
  lamps::LampFrameStats stats;
  // Baseline: cv::remap of a 1080p BGR image through a float map, bilinear.
  cv::Mat src(1080, 1920, CV_8UC3), map_x(1080, 1920, CV_32FC1), map_y(1080, 1920, CV_32FC1), dst;
  cv::randu(src, cv::Scalar::all(0), cv::Scalar::all(255));
  for (int y = 0; y < 1080; ++y)
    for (int x = 0; x < 1920; ++x) {
      map_x.at<float>(y, x) = 0.9f * x + 20 + 3 * std::sin(y * 0.01f);
      map_y.at<float>(y, x) = 0.9f * y + 20 + 3 * std::cos(x * 0.01f);
    }
  const std::vector<bench::Timing> frame = bench::measureInterleaved(
      runs, {[&] { (void)lamps::lampFrame(inputs[0], textured, white, std::nullopt, &stats); },
             [&] { (void)lamps::lampFrame(inputs[0], glossy, white, Vec3(0, 0.3, 1.4)); },
             [&] { cv::remap(src, dst, map_x, map_y, cv::INTER_LINEAR); }});

  // Error: the weights' sum at the first projector's pixel centres, the others' read
  // between their pixels (as their light reaches the point), and clipping.
  std::vector<double> off;
  for (int y = 0; y < 1080; y += 2) {
    for (int x = 0; x < 1920; x += 2) {
      const float w = weights.weight[0].at<float>(y, x);
      if (!(w > 0)) continue;
      const cv::Vec3f p = views[0].point.at<cv::Vec3f>(y, x);
      const cv::Vec3f n = views[0].normal.at<cv::Vec3f>(y, x);
      const auto seen = lamps::lampsSeeing(set, Vec3(p[0], p[1], p[2]), Vec3(n[0], n[1], n[2]));
      double sum = w;
      for (std::size_t j = 1; j < set.size(); ++j)
        if (seen[j]) sum += lamps::sampleBilinear(weights.weight[j], *seen[j]);
      off.push_back(std::abs(sum - 1));
    }
  }
  std::sort(off.begin(), off.end());
  const double off_p99 = off.empty() ? 0 : off[off.size() * 99 / 100];
  const double off_max = off.empty() ? 0 : off.back();
  std::printf("view (ray cast, once per rig)   %8.1f ms median, %8.1f min\n", view_time.median_ms,
              view_time.min_ms);
  std::printf("weights of 3 (once per rig)     %8.1f ms median, %8.1f min\n", weight_time.median_ms,
              weight_time.min_ms);
  std::printf("coverage report                 %8.1f ms median\n", coverage_time.median_ms);
  std::printf("frame, textured diffuse         %8.1f ms median (%.2fx cv::remap)\n",
              frame[0].median_ms, frame[0].median_ms / frame[2].median_ms);
  std::printf("frame, glossy for a tracked eye %8.1f ms median (%.2fx cv::remap)\n",
              frame[1].median_ms, frame[1].median_ms / frame[2].median_ms);
  std::printf("cv::remap 1080p BGR (baseline)  %8.1f ms median\n", frame[2].median_ms);
  std::printf(
      "lit pixels %ld, clipped %ld; weights' sum off one by %.2g (99th percentile), "
      "%.2g (largest, at the edges where a frame's weights end within a pixel)\n",
      stats.lit_pixels, stats.clipped_pixels, off_p99, off_max);
  std::ofstream csv(out / "shader_lamps.csv");
  csv << "step,median_ms,min_ms,ratio_to_remap\n";
  csv << "view," << view_time.median_ms << ',' << view_time.min_ms << ",\n";
  csv << "weights," << weight_time.median_ms << ',' << weight_time.min_ms << ",\n";
  csv << "coverage," << coverage_time.median_ms << ',' << coverage_time.min_ms << ",\n";
  csv << "frame_textured," << frame[0].median_ms << ',' << frame[0].min_ms << ','
      << frame[0].median_ms / frame[2].median_ms << '\n';
  csv << "frame_glossy," << frame[1].median_ms << ',' << frame[1].min_ms << ','
      << frame[1].median_ms / frame[2].median_ms << '\n';
  csv << "remap," << frame[2].median_ms << ',' << frame[2].min_ms << ",1\n";
  csv << "# weights' sum off one: 99th percentile " << off_p99 << ", largest " << off_max << '\n';
#if PROCAM_BENCH_GLES
  benchGles(csv, runs, inputs[0], textured, glossy, white, frame[2].median_ms);
#endif
  return 0;
}
