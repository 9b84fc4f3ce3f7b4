#include "shader_lamps/rig_lamps.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "blend/brightness_map.hpp"
#include "blend/rig_tiles.hpp"
#include "shader_lamps/lamp_gain.hpp"

namespace procam::lamps {

using nlohmann::json;

namespace {

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

json vec3Json(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

}  // namespace

Result<RigLamps> prepareRigLamps(const rig::RigModel& rig, const ObjectModel& object,
                                 const RigLampOptions& options) {
  RigLamps out;
  out.max_incidence_deg = options.max_incidence_deg;
  std::vector<const rig::RigProjector*> source;
  for (const rig::RigProjector& p : rig.projectors) {
    const bool asked = contains(options.projectors, p.name);
    if (!options.projectors.empty() && !asked) continue;
    if (!p.intrinsics_known || !p.pose_known) {
      if (asked) return fail(ErrorCode::kNotFound, "projector '" + p.name + "' has no pose");
      continue;
    }
    RigLamp lamp;
    lamp.name = p.name;
    lamp.output = p.output;
    lamp.model = p.model();
    lamp.on = !contains(options.off, p.name);
    out.lamps.push_back(std::move(lamp));
    source.push_back(&p);
  }
  for (const std::string& name : options.off) {
    if (std::none_of(out.lamps.begin(), out.lamps.end(),
                     [&](const RigLamp& l) { return l.name == name; }))
      return fail(ErrorCode::kNotFound, "no posed projector '" + name + "' to switch off");
  }
  if (out.lamps.empty()) return fail(ErrorCode::kNotFound, "no projector of the rig has a pose");
  for (RigLamp& l : out.lamps) {
    auto view = castLampView(l.model, object);
    if (!view) return tl::unexpected(view.error());
    l.view = std::move(*view);
  }
  std::vector<Lamp> set;
  for (const RigLamp& l : out.lamps) set.push_back({&l.model, &l.view, l.on});
  LampWeightOptions wopt;
  wopt.max_incidence_deg = options.max_incidence_deg;
  auto weights = lampWeights(set, wopt);
  if (!weights) return tl::unexpected(weights.error());
  out.weights = std::move(*weights);
  out.coverage = lampCoverage(set, out.weights, object);

  // Each projector's response and k·B: from its measured brightness across the frame
  // (grey, in its camera's units) when every projector that is on has one from the same
  // camera; taken equal for all when none has one; refused otherwise (gains in camera
  // units beside assumed ones, or two cameras' units, do not compare).
  std::vector<std::string> measured_by(out.lamps.size()), unmeasured;
  std::vector<std::optional<GainMeasurement>> gains(out.lamps.size());
  for (std::size_t i = 0; i < out.lamps.size(); ++i) {
    RigLamp& l = out.lamps[i];
    const auto response = blend::projectorResponse(*source[i]);
    if (response) {
      l.photometry.gamma = response->gamma;
      l.response_measured = true;
    }
    if (!response || !response->brightness) {
      if (l.on) unmeasured.push_back(l.name);
      continue;
    }
    const blend::BrightnessMap& map = *response->brightness;
    auto gain = gainFromBrightness(l.view, out.weights.reach[i],
                                   [&](const Vec2& px) { return blend::brightnessAt(map, px); });
    if (!gain) {
      if (l.on) unmeasured.push_back(l.name + " (" + gain.error().message + ")");
      continue;
    }
    gains[i] = *gain;
    measured_by[i] = response->camera;
  }
  for (std::size_t i = 0; i < out.lamps.size(); ++i) {
    if (!out.lamps[i].on || !gains[i]) continue;
    if (!unmeasured.empty()) {
      std::string names;
      for (const auto& n : unmeasured) names += (names.empty() ? "" : ", ") + n;
      return fail(ErrorCode::kInvalidInput,
                  "some projectors' brightness was measured and not that of " + names +
                      ": their gains do not compare (measure them all, or none)");
    }
    const std::string camera = "camera '" + measured_by[i] + "' units";
    if (!out.units.empty() && out.units != camera)
      return fail(ErrorCode::kInvalidInput,
                  "the projectors' brightness was measured by different cameras: their gains "
                  "do not compare");
    out.units = camera;
  }
  std::vector<LampFrameInput> inputs;
  for (std::size_t i = 0; i < out.lamps.size(); ++i) {
    RigLamp& l = out.lamps[i];
    if (!out.units.empty() && gains[i]) {
      l.photometry.gain_rgb = gains[i]->gain_rgb;
      l.gain_measured = true;
      l.gain_spread = gains[i]->spread;
    }
    if (l.on) inputs.push_back({&l.view, &out.weights.weight[i], l.photometry});
  }
  if (out.units.empty()) out.units = "relative (no brightness measured)";
  if (inputs.empty()) return fail(ErrorCode::kInvalidInput, "every projector is off");
  auto level = lampWhiteLevel(inputs);
  if (!level) return tl::unexpected(level.error());
  out.white = *level;
  return out;
}

Result<cv::Mat> rigLampFrame(const RigLamps& lamps, std::size_t i, const Material& material,
                             double white, const std::optional<Vec3>& eye, LampFrameStats* stats,
                             int bit_depth) {
  if (i >= lamps.lamps.size()) return fail(ErrorCode::kInvalidInput, "no such lamp");
  const RigLamp& l = lamps.lamps[i];
  if (!l.on) {
    if (bit_depth != 8 && bit_depth != 16)
      return fail(ErrorCode::kInvalidInput, "bit depth must be 8 or 16");
    if (stats) *stats = {};
    return cv::Mat(l.view.size, bit_depth == 8 ? CV_8UC3 : CV_16UC3, cv::Scalar::all(0));
  }
  const LampFrameInput input{&l.view, &lamps.weights.weight[i], l.photometry};
  return lampFrame(input, material, white > 0 ? white : lamps.white, eye, stats, bit_depth);
}

json describeDisplay(const RigLamps& lamps, double white) {
  return {{"surface", "object"},
          {"white", white > 0 ? white : lamps.white},
          {"units", lamps.units},
          {"max_incidence_deg", lamps.max_incidence_deg},
          {"coverage",
           {{"lit_m2", lamps.coverage.lit_m2},
            {"unlit_m2", lamps.coverage.unlit_m2},
            {"unlit_faces", lamps.coverage.unlit_faces.size()},
            {"never_lit_m2", lamps.coverage.never_lit_m2}}}};
}

json describeLamp(const RigLamp& l) {
  json p = {{"name", l.name},
            {"output", l.output},
            {"on", l.on},
            {"response_gamma", l.photometry.gamma},
            {"response", l.response_measured ? "measured" : "assumed gamma 2.2"},
            {"gain", vec3Json(l.photometry.gain_rgb)},
            {"gain_source", l.gain_measured ? "brightness map" : "assumed equal"}};
  if (l.gain_measured) p["gain_spread"] = l.gain_spread;
  return p;
}

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

}  // namespace procam::lamps
