#include "shader_lamps/lamp_gain.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace procam::lamps {

namespace {

// Far enough inside the projector's reach that its pixels' spread and the rig's
// calibration error do not reach past the lit part: three pixels.
constexpr double kInsidePx = 3;
constexpr long kMinSamples = 50;

Vec3 codesAt(const cv::Mat& m, int x, int y) {
  const auto value = [&](int c) -> double {
    return m.depth() == CV_8U ? m.ptr<std::uint8_t>(y)[x * m.channels() + c]
                              : m.ptr<std::uint16_t>(y)[x * m.channels() + c];
  };
  if (m.channels() == 1) return Vec3::Constant(value(0));
  return {value(2), value(1), value(0)};  // B, G, R -> R, G, B
}

double median(std::vector<double>& v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

Result<GainMeasurement> measureLampGain(std::span<const Lamp> lamps, const LampWeights& weights,
                                        std::size_t index, const ObjectModel& object,
                                        const GainCapture& cap) {
  if (index >= lamps.size() || weights.reach.size() != lamps.size() || !lamps[index].model ||
      !lamps[index].view || weights.reach[index].size() != lamps[index].view->size)
    return fail(ErrorCode::kInvalidInput, "no such projector in the set");
  if (!cap.camera) return fail(ErrorCode::kInvalidInput, "no camera");
  const cv::Size size(cap.camera->width, cap.camera->height);
  const auto good = [&](const cv::Mat& m) {
    return m.size() == size && (m.depth() == CV_8U || m.depth() == CV_16U) &&
           (m.channels() == 1 || m.channels() == 3);
  };
  if (!good(cap.white) || !good(cap.black) || cap.white.type() != cap.black.type())
    return fail(ErrorCode::kInvalidInput,
                "white and black captures must be 8- or 16-bit, grey or BGR, the camera's size");
  if (cap.step < 1 || cap.step > 64) return fail(ErrorCode::kInvalidInput, "step out of range");
  if (!(cap.saturation > 0)) return fail(ErrorCode::kInvalidInput, "saturation must be positive");
  const Vec3 centre = lamps[index].model->pose.center();
  const cv::Mat& reach = weights.reach[index];
  std::vector<double> r, g, b;
  for (int y = 0; y < size.height; y += cap.step) {
    for (int x = 0; x < size.width; x += cap.step) {
      const Vec3 white = codesAt(cap.white, x, y);
      if (white.maxCoeff() >= cap.saturation) continue;
      const Vec3 signal = white - codesAt(cap.black, x, y);
      if (signal.minCoeff() < 0.02 * cap.saturation) continue;
      const auto ray = cap.camera->backproject(Vec2(x, y));
      if (!ray) continue;
      const auto s = object.intersect(*ray);
      if (!s) continue;
      const auto seen = lampsSeeing(lamps.subspan(index, 1), s->point, s->normal);
      if (!seen[0]) continue;
      const int px = std::clamp(static_cast<int>(std::lround(seen[0]->x())), 0, reach.cols - 1);
      const int py = std::clamp(static_cast<int>(std::lround(seen[0]->y())), 0, reach.rows - 1);
      if (reach.at<float>(py, px) < kInsidePx) continue;
      const Vec3 to_lamp = centre - s->point;
      const double d2 = to_lamp.squaredNorm();
      const double cos_theta = s->normal.dot(to_lamp) / std::sqrt(d2);
      const Vec3 gain = signal * d2 / cos_theta;  // eq. 5.3 solved for k·B
      r.push_back(gain.x());
      g.push_back(gain.y());
      b.push_back(gain.z());
    }
  }
  if (static_cast<long>(g.size()) < kMinSamples)
    return fail(ErrorCode::kTooFewPoints,
                "the camera sees the projector's light on the object at only " +
                    std::to_string(g.size()) + " usable pixels");
  GainMeasurement out;
  out.samples = static_cast<long>(g.size());
  out.gain_rgb = Vec3(median(r), median(g), median(b));
  std::vector<double> deviation;
  for (double v : g) deviation.push_back(std::abs(v - out.gain_rgb.y()));
  out.spread = median(deviation) / out.gain_rgb.y();
  return out;
}

Result<GainMeasurement> gainFromBrightness(const LampView& view, const cv::Mat& reach,
                                           const std::function<double(const Vec2&)>& brightness,
                                           double inside_px) {
  if (reach.size() != view.size || reach.type() != CV_32FC1)
    return fail(ErrorCode::kInvalidInput, "the reach does not match the projector's view");
  std::vector<double> gains;
  // Every other pixel: the map's nodes are tens of pixels apart.
  for (int y = 0; y < view.size.height; y += 2) {
    for (int x = 0; x < view.size.width; x += 2) {
      if (reach.at<float>(y, x) < inside_px) continue;
      const double d = view.distance.at<float>(y, x), c = view.cosine.at<float>(y, x);
      const double b = brightness(Vec2(x, y));
      if (!(c > 0) || !(b > 0) || !std::isfinite(b)) continue;
      gains.push_back(b * d * d / c);
    }
  }
  if (static_cast<long>(gains.size()) < kMinSamples)
    return fail(ErrorCode::kTooFewPoints, "the projector lights the object at only " +
                                              std::to_string(gains.size()) +
                                              " pixels with a brightness");
  GainMeasurement out;
  out.samples = static_cast<long>(gains.size());
  const double g = median(gains);
  out.gain_rgb = Vec3::Constant(g);
  for (double& v : gains) v = std::abs(v - g);
  out.spread = median(gains) / g;
  return out;
}

}  // namespace procam::lamps
