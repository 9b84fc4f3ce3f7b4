#pragma once
// A projector's response and brightness from a grey ramp seen by a linear camera
// ([Raskar02] §4.1.2: blending weights pass through a lookup table that corrects the
// projector's non-linearity, or overlaps sum in code values, not light). The camera's
// mean over the projector's image at each grey level g is modelled as
//   m(g) = black + (white - black) (g / 255)^gamma,
// gamma fitted by least squares on log((m - black) / (white - black)) against
// log(g / 255) over the levels well above black. Brightness matching scales every
// projector to the dimmest one's white, in linear light, so that no projector's region
// is brighter than its neighbours' (a global form of Majumder's per-pixel attenuation).
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "blend/brightness_map.hpp"
#include "core/error.hpp"
#include "render/final_stage.hpp"

namespace procam::blend {

struct RampSample {
  int level = 0;    // grey code shown, 0..255
  double mean = 0;  // the camera's mean over the projector's image (camera units)
};

struct ProjectorResponse {
  double gamma = 2.2;
  double black = 0, white = 0;  // camera units at levels 0 and 255
  double rms = 0;               // of the fit, relative to white - black
  int levels = 0;               // used by the fit
  // Its white across the frame, in the same camera's units (per-pixel matching,
  // luminance_match.hpp), when measured.
  std::optional<BrightnessMap> brightness;
  // The camera that measured it: brightness compares only within one camera's exposure.
  std::string camera;
};

// kTooFewPoints without levels 0 and 255 and three levels between them whose
// signal is at least 2 % of white - black; kInvalidInput for non-finite or out-of-range
// samples; kDegenerate when white does not exceed black by 5 camera units or the
// fitted gamma lies outside [1, 4].
Result<ProjectorResponse> fitResponse(std::span<const RampSample> ramp);

// Per projector, the gain in linear light that brings its white to the dimmest one's.
std::vector<double> matchedGains(std::span<const ProjectorResponse> responses);

// Weight code -> code for a projector of `gamma` whose light is scaled by `gain`
// (0, 1]: weight a maps to 255 (gain a / 255)^(1 / gamma). kInvalidInput otherwise.
Result<render::Lut> weightLut(double gamma, double gain);

}  // namespace procam::blend
