#include "blend/response.hpp"

#include <algorithm>
#include <cmath>

namespace procam::blend {

Result<ProjectorResponse> fitResponse(std::span<const RampSample> ramp) {
  ProjectorResponse r;
  bool has_black = false, has_white = false;
  for (const RampSample& s : ramp) {
    if (s.level < 0 || s.level > 255 || !std::isfinite(s.mean) || s.mean < 0)
      return fail(ErrorCode::kInvalidInput, "ramp: level or mean out of range");
    if (s.level == 0) {
      r.black = s.mean;
      has_black = true;
    }
    if (s.level == 255) {
      r.white = s.mean;
      has_white = true;
    }
  }
  if (!has_black || !has_white)
    return fail(ErrorCode::kTooFewPoints, "ramp: levels 0 and 255 are both needed");
  const double span = r.white - r.black;
  if (!(span >= 5))
    return fail(ErrorCode::kDegenerate,
                "ramp: white is not brighter than black (" + std::to_string(span) +
                    " camera units): the camera does not see the projector");
  double sxx = 0, sxy = 0;
  int n = 0;
  for (const RampSample& s : ramp) {
    if (s.level == 0 || s.level == 255) continue;
    const double y = (s.mean - r.black) / span;
    if (y < 0.02) continue;  // near black the camera's noise and offset dominate
    const double lx = std::log(s.level / 255.0), ly = std::log(y);
    sxx += lx * lx;
    sxy += lx * ly;
    ++n;
  }
  if (n < 3) return fail(ErrorCode::kTooFewPoints, "ramp: fewer than three levels above black");
  // Through the origin of log-log (level 255 is 1 by definition): gamma = sum xy / sum xx.
  r.gamma = sxy / sxx;
  r.levels = n;
  if (!std::isfinite(r.gamma) || r.gamma < 1 || r.gamma > 4)
    return fail(ErrorCode::kDegenerate,
                "ramp: fitted gamma " + std::to_string(r.gamma) + " outside [1, 4]");
  double sq = 0;
  for (const RampSample& s : ramp) {
    if (s.level == 0 || s.level == 255) continue;
    const double y = (s.mean - r.black) / span;
    if (y < 0.02) continue;
    const double e = y - std::pow(s.level / 255.0, r.gamma);
    sq += e * e;
  }
  r.rms = std::sqrt(sq / n);
  return r;
}

std::vector<double> matchedGains(std::span<const ProjectorResponse> responses) {
  double dimmest = 0;
  for (const auto& r : responses) {
    const double w = r.white - r.black;
    if (w > 0 && (dimmest == 0 || w < dimmest)) dimmest = w;
  }
  std::vector<double> gains;
  for (const auto& r : responses) {
    const double w = r.white - r.black;
    gains.push_back(w > 0 && dimmest > 0 ? std::min(1.0, dimmest / w) : 1.0);
  }
  return gains;
}

Result<render::Lut> weightLut(double gamma, double gain) {
  if (!std::isfinite(gamma) || gamma <= 0 || !std::isfinite(gain) || gain <= 0 || gain > 1)
    return fail(ErrorCode::kInvalidInput, "weight table: gamma > 0 and gain in (0, 1] needed");
  render::Lut lut{};
  for (int a = 0; a < 256; ++a) {
    const double v = 255.0 * std::pow(gain * a / 255.0, 1.0 / gamma);
    lut[static_cast<std::size_t>(a)] = static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L));
  }
  return lut;
}

}  // namespace procam::blend
