#include "blend/brightness_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "blend/node_grid.hpp"

namespace procam::blend {
namespace {

constexpr int kMaxFramebuffer = 16384;

int nearestNode(double x, int step, int nodes) {
  return std::clamp(static_cast<int>(std::lround(x / step)), 0, nodes - 1);
}

}  // namespace

int brightnessNodes(int pixels, int step) {
  return (pixels - 2) / step + 2;
}

Result<BrightnessMap> measureBrightness(const cv::Mat& white, const cv::Mat& black,
                                        const cv::Mat& u, const cv::Mat& v, const cv::Mat& mask,
                                        cv::Size framebuffer, int step) {
  const bool grey =
      (white.type() == CV_8UC1 || white.type() == CV_16UC1) && black.type() == white.type();
  if (!grey || u.type() != CV_32FC1 || v.type() != CV_32FC1 || mask.type() != CV_8UC1 ||
      white.empty() || black.size() != white.size() || u.size() != white.size() ||
      v.size() != white.size() || mask.size() != white.size()) {
    return fail(ErrorCode::kInvalidInput,
                "brightness: white and black grey captures, CV_32F u and v and an 8-bit "
                "mask, all of one size, are needed");
  }
  if (framebuffer.width < 2 || framebuffer.height < 2 || framebuffer.width > kMaxFramebuffer ||
      framebuffer.height > kMaxFramebuffer || step < 4 || step > 256) {
    return fail(ErrorCode::kInvalidInput, "brightness: framebuffer or node step out of range");
  }
  BrightnessMap out;
  out.step = step;
  out.width = framebuffer.width;
  out.height = framebuffer.height;
  const int cols = brightnessNodes(out.width, step), rows = brightnessNodes(out.height, step);
  cv::Mat sum(rows, cols, CV_64FC1, cv::Scalar(0)), count(rows, cols, CV_32SC1, cv::Scalar(0));
  cv::Mat w, b;
  white.convertTo(w, CV_32F);
  black.convertTo(b, CV_32F);
  for (int y = 0; y < white.rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    const float *pu = u.ptr<float>(y), *pv = v.ptr<float>(y);
    const float *pw = w.ptr<float>(y), *pb = b.ptr<float>(y);
    for (int x = 0; x < white.cols; ++x) {
      if (!m[x] || !std::isfinite(pu[x]) || !std::isfinite(pv[x])) continue;
      if (pu[x] < 0 || pv[x] < 0 || pu[x] > out.width - 1 || pv[x] > out.height - 1) continue;
      const int i = nearestNode(pu[x], step, cols);
      const int j = nearestNode(pv[x], step, rows);
      sum.at<double>(j, i) += pw[x] - pb[x];
      ++count.at<int>(j, i);
    }
  }
  out.white = cv::Mat(rows, cols, CV_32FC1, cv::Scalar(0));
  cv::Mat seen(rows, cols, CV_8UC1, cv::Scalar(0));
  int seen_nodes = 0;
  double brightest = 0;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const int n = count.at<int>(j, i);
      if (n == 0) continue;
      const double mean = sum.at<double>(j, i) / n;
      out.white.at<float>(j, i) = static_cast<float>(mean);
      seen.at<uint8_t>(j, i) = 1;
      brightest = std::max(brightest, mean);
      ++seen_nodes;
    }
  }
  if (seen_nodes < 4 || !(brightest > 0)) {
    return fail(ErrorCode::kTooFewPoints, "brightness: the camera saw " +
                                              std::to_string(seen_nodes) +
                                              " of the projector's nodes lit (4 needed)");
  }
  cv::Mat_<float> nodes = out.white;
  cv::Mat_<uchar> known = seen;
  fillFromKnownNeighbours(nodes, known);
  // A node at the image's blurred edge or lost in the camera's noise reads near zero or
  // below; the matching divides by it, so it is held to a thousandth of the brightest.
  cv::max(out.white, 1e-3 * brightest, out.white);
  return out;
}

double brightnessAt(const BrightnessMap& map, const Vec2& pixel) {
  return sampleNodes(cv::Mat_<float>(map.white),
                     std::clamp(pixel.x(), 0.0, map.width - 1.0) / map.step,
                     std::clamp(pixel.y(), 0.0, map.height - 1.0) / map.step);
}

nlohmann::json brightnessToJson(const BrightnessMap& map) {
  nlohmann::json values = nlohmann::json::array();
  for (int j = 0; j < map.white.rows; ++j) {
    for (int i = 0; i < map.white.cols; ++i) values.push_back(map.white.at<float>(j, i));
  }
  return {{"step", map.step},       {"width", map.width},     {"height", map.height},
          {"cols", map.white.cols}, {"rows", map.white.rows}, {"white", std::move(values)}};
}

Result<BrightnessMap> brightnessFromJson(const nlohmann::json& j) {
  const auto bad = [](const std::string& why) {
    return fail(ErrorCode::kInvalidInput, "photometric brightness: " + why);
  };
  if (!j.is_object()) return bad("not an object");
  const auto integer = [&](const char* key, int lo, int hi) -> std::optional<int> {
    const auto it = j.find(key);
    if (it == j.end() || !it->is_number_integer()) return std::nullopt;
    const auto n = it->get<long long>();
    if (n < lo || n > hi) return std::nullopt;
    return static_cast<int>(n);
  };
  const auto step = integer("step", 4, 256);
  const auto width = integer("width", 2, kMaxFramebuffer);
  const auto height = integer("height", 2, kMaxFramebuffer);
  if (!step || !width || !height) return bad("step in [4, 256] and a framebuffer size needed");
  const int cols = brightnessNodes(*width, *step), rows = brightnessNodes(*height, *step);
  if (integer("cols", cols, cols) != cols || integer("rows", rows, rows) != rows)
    return bad("cols and rows do not match the framebuffer and step");
  const auto values = j.find("white");
  if (values == j.end() || !values->is_array() ||
      values->size() != static_cast<std::size_t>(cols) * rows) {
    return bad("'white' must hold cols x rows values");
  }
  BrightnessMap out;
  out.step = *step;
  out.width = *width;
  out.height = *height;
  out.white = cv::Mat(rows, cols, CV_32FC1);
  for (int k = 0; k < cols * rows; ++k) {
    const auto& e = (*values)[static_cast<std::size_t>(k)];
    const double value = e.is_number() ? e.get<double>() : std::nan("");
    const auto node = static_cast<float>(value);
    if (!(std::isfinite(node) && node >= std::numeric_limits<float>::min()))
      return bad("a node that is not a finite number > 0 (as a float)");
    out.white.at<float>(k / cols, k % cols) = node;
  }
  // As measured maps are: no node below a thousandth of the brightest (matching divides
  // by them).
  double brightest = 0;
  cv::minMaxLoc(out.white, nullptr, &brightest);
  cv::max(out.white, 1e-3 * brightest, out.white);
  return out;
}

}  // namespace procam::blend
