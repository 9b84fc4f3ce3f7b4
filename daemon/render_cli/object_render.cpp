#include "object_render.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "blend/brightness_map.hpp"
#include "blend/mpcdi.hpp"
#include "blend/rig_tiles.hpp"
#include "content/mesh_content.hpp"
#include "json_matrix.hpp"
#include "replace_file.hpp"
#include "shader_lamps/lamp_frame.hpp"
#include "shader_lamps/lamp_gain.hpp"
#include "shader_lamps/lamp_view.hpp"
#include "shader_lamps/lamp_weights.hpp"
#include "shader_lamps/object_model.hpp"

namespace procam::render_cli {

namespace fs = std::filesystem;
using nlohmann::json;

cv::Mat linearTexture(const cv::Mat& image) {
  cv::Mat rgb;
  if (image.channels() == 1)
    cv::cvtColor(image, rgb, cv::COLOR_GRAY2RGB);
  else if (image.channels() == 4)
    cv::cvtColor(image, rgb, cv::COLOR_BGRA2RGB);
  else
    cv::cvtColor(image, rgb, cv::COLOR_BGR2RGB);
  cv::Mat out;
  rgb.convertTo(out, CV_32FC3, image.depth() == CV_16U ? 1.0 / 65535 : 1.0 / 255);
  // The sRGB transfer function, inverted.
  out.forEach<cv::Vec3f>([](cv::Vec3f& c, const int*) {
    for (int k = 0; k < 3; ++k)
      c[k] = c[k] <= 0.04045f ? c[k] / 12.92f : std::pow((c[k] + 0.055f) / 1.055f, 2.4f);
  });
  return out;
}

Result<json> renderObject(const ObjectRenderInput& in) {
  auto loaded = content::loadMeshContent(in.object);
  if (!loaded) return tl::unexpected(loaded.error());
  std::vector<Vec2> uv = loaded->mesh.texcoord;
  if (!in.texture.empty() && uv.empty())
    return fail(
        ErrorCode::kInvalidInput,
        in.object.string() + " has no texture coordinates (OBJ vt, PLY s t) for the texture");
  const bool textured = !uv.empty() && !in.texture.empty();
  auto object = lamps::ObjectModel::build(loaded->mesh, textured ? uv : std::vector<Vec2>{});
  if (!object) return tl::unexpected(object.error());

  struct Chosen {
    const rig::RigProjector* p;
    geom::CameraModel model;
    lamps::LampView view;
    bool on;
  };
  std::vector<Chosen> chosen;
  for (const rig::RigProjector& p : in.rig->projectors) {
    const bool asked =
        std::find(in.projectors.begin(), in.projectors.end(), p.name) != in.projectors.end();
    if (!in.projectors.empty() && !asked) continue;
    if (!p.intrinsics_known || !p.pose_known) {
      if (asked) return fail(ErrorCode::kNotFound, "projector '" + p.name + "' has no pose");
      continue;
    }
    if (!blend::isSafeRegionId(p.name))
      return fail(
          ErrorCode::kInvalidInput,
          "projector name '" + p.name + "' cannot name a file (1-128 of A-Z a-z 0-9 . _ -)");
    const bool off = std::find(in.off.begin(), in.off.end(), p.name) != in.off.end();
    chosen.push_back({&p, p.model(), {}, !off});
  }
  for (const std::string& name : in.off)
    if (std::none_of(chosen.begin(), chosen.end(),
                     [&](const Chosen& c) { return c.p->name == name; }))
      return fail(ErrorCode::kNotFound, "--off: no posed projector '" + name + "'");
  if (chosen.empty()) return fail(ErrorCode::kNotFound, "no projector of the rig has a pose");
  for (Chosen& c : chosen) {
    auto view = lamps::castLampView(c.model, *object);
    if (!view) return tl::unexpected(view.error());
    c.view = std::move(*view);
  }
  std::vector<lamps::Lamp> set;
  for (const Chosen& c : chosen) set.push_back({&c.model, &c.view, c.on});
  lamps::LampWeightOptions wopt;
  wopt.max_incidence_deg = in.max_incidence_deg;
  auto weights = lamps::lampWeights(set, wopt);
  if (!weights) return tl::unexpected(weights.error());
  const lamps::Coverage coverage = lamps::lampCoverage(set, *weights, *object);

  // Each projector's response and k·B: from its measured brightness across the frame
  // (grey, in its camera's units) when every projector that is on has one from the same
  // camera; taken equal for all when none has one; refused otherwise (gains in camera
  // units beside assumed ones, or two cameras' units, do not compare).
  std::vector<lamps::LampFrameInput> inputs;
  json projectors = json::array();
  std::vector<std::optional<lamps::GainMeasurement>> gains(chosen.size());
  std::vector<std::string> measured_by(chosen.size()), unmeasured;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    const auto response = blend::projectorResponse(*chosen[i].p);
    if (!response || !response->brightness) {
      if (chosen[i].on) unmeasured.push_back(chosen[i].p->name);
      continue;
    }
    const blend::BrightnessMap& map = *response->brightness;
    auto gain = lamps::gainFromBrightness(chosen[i].view, weights->reach[i], [&](const Vec2& px) {
      return blend::brightnessAt(map, px);
    });
    if (!gain) {
      if (chosen[i].on) unmeasured.push_back(chosen[i].p->name + " (" + gain.error().message + ")");
      continue;
    }
    gains[i] = *gain;
    measured_by[i] = response->camera;
  }
  std::string units;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    if (!chosen[i].on || !gains[i]) continue;
    if (!unmeasured.empty()) {
      std::string names;
      for (const auto& n : unmeasured) names += (names.empty() ? "" : ", ") + n;
      return fail(ErrorCode::kInvalidInput,
                  "some projectors' brightness was measured and not that of " + names +
                      ": their gains do not compare (measure them all, or none)");
    }
    const std::string camera = "camera '" + measured_by[i] + "' units";
    if (!units.empty() && units != camera)
      return fail(ErrorCode::kInvalidInput,
                  "the projectors' brightness was measured by different cameras: their gains "
                  "do not compare");
    units = camera;
  }
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    lamps::LampFrameInput input{&chosen[i].view, &weights->weight[i], {}};
    const auto response = blend::projectorResponse(*chosen[i].p);
    if (response) input.photometry.gamma = response->gamma;
    const bool measured = !units.empty() && gains[i];
    if (measured) input.photometry.gain_rgb = gains[i]->gain_rgb;
    json p = {{"name", chosen[i].p->name},
              {"output", chosen[i].p->output},
              {"on", chosen[i].on},
              {"response_gamma", input.photometry.gamma},
              {"response", response ? "measured" : "assumed gamma 2.2"},
              {"gain", daemon::vectorJson(input.photometry.gain_rgb)},
              {"gain_source", measured ? "brightness map" : "assumed equal"}};
    if (measured) p["gain_spread"] = gains[i]->spread;
    projectors.push_back(p);
    if (chosen[i].on) inputs.push_back(input);
  }
  if (inputs.empty()) return fail(ErrorCode::kInvalidInput, "every projector is off");
  double white = 0;
  if (in.white) {
    if (!(*in.white > 0) || !std::isfinite(*in.white))
      return fail(ErrorCode::kInvalidInput, "--white must be positive");
    white = *in.white;
  } else {
    auto level = lamps::lampWhiteLevel(inputs);
    if (!level) return tl::unexpected(level.error());
    white = *level;
  }

  lamps::Material material;
  if (textured) material.texture = linearTexture(in.texture);
  material.light_dir = in.light;
  material.specular_rgb = Vec3::Constant(in.specular);
  material.shininess = in.shininess;
  if (auto ok = lamps::checkMaterial(material); !ok) return tl::unexpected(ok.error());

  std::error_code ec;
  if (!in.out.empty()) {
    fs::create_directories(in.out, ec);
    if (ec) return fail(ErrorCode::kIo, "cannot create " + in.out.string() + ": " + ec.message());
  }
  std::size_t k = 0;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    const std::string file = chosen[i].p->name + ".png";
    json& p = projectors[i];
    p["file"] = file;
    cv::Mat frame;
    if (chosen[i].on) {
      lamps::LampFrameStats stats;
      auto drawn = lamps::lampFrame(inputs[k++], material, white, in.viewer, &stats, in.bit_depth);
      if (!drawn) return tl::unexpected(drawn.error());
      frame = *drawn;
      p["lit_pixels"] = stats.lit_pixels;
      p["clipped_pixels"] = stats.clipped_pixels;
    } else {
      frame =
          cv::Mat(chosen[i].view.size, in.bit_depth == 8 ? CV_8UC3 : CV_16UC3, cv::Scalar::all(0));
      p["lit_pixels"] = 0;
    }
    if (!in.out.empty()) {
      std::vector<uint8_t> png;
      if (!cv::imencode(".png", frame, png))
        return fail(ErrorCode::kIo, "cannot encode " + chosen[i].p->name + "'s frame");
      if (auto ok = replaceFileWith(in.out / file, std::string(png.begin(), png.end())); !ok)
        return tl::unexpected(ok.error());
    }
  }
  json doc = {{"object",
               {{"path", in.object.string()},
                {"faces", object->mesh().faces.size()},
                {"textured", textured}}},
              {"display",
               {{"surface", "object"},
                {"white", white},
                {"white_source", in.white ? "given" : "brightest all give"},
                {"units", units.empty() ? "relative (no brightness measured)" : units},
                {"max_incidence_deg", in.max_incidence_deg},
                {"coverage",
                 {{"lit_m2", coverage.lit_m2},
                  {"unlit_m2", coverage.unlit_m2},
                  {"unlit_faces", coverage.unlit_faces.size()},
                  {"never_lit_m2", coverage.never_lit_m2}}}}},
              {"projectors", projectors}};
  if (in.viewer) doc["display"]["viewer"] = daemon::vectorJson(*in.viewer);
  return doc;
}

}  // namespace procam::render_cli
