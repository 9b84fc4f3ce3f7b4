#pragma once
// What the camera-request tests (snapshot, calibrate-camera) share: the clipped
// pixels of an image counted pixel by pixel, and an operation's final reply.
#include <opencv2/core.hpp>
#include <vector>

#include "daemon_harness.hpp"

namespace procam::itest {

inline constexpr const char* kCameraBoard = "checker:9x6:0.08";  // the camera_board scene's

struct Levels {
  double saturated = 0, underexposed = 0;
};

// The shares of clipped pixels, counted pixel by pixel: at or above 98 % of the
// full scale in some channel, at or below 2 % in every channel.
inline Levels countLevels(const cv::Mat& image) {
  const double full = image.depth() == CV_16U ? 65535.0 : 255.0;
  Levels l;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      double brightest = 0;
      for (int c = 0; c < std::min(3, image.channels()); ++c) {
        const double v = image.depth() == CV_16U
                             ? double(image.ptr<uint16_t>(y)[x * image.channels() + c])
                             : double(image.ptr<uint8_t>(y)[x * image.channels() + c]);
        brightest = std::max(brightest, v);
      }
      l.saturated += brightest >= 0.98 * full;
      l.underexposed += brightest <= 0.02 * full;
    }
  }
  const double n = double(image.total());
  return {100.0 * l.saturated / n, 100.0 * l.underexposed / n};
}

// Reads messages until the reply with `id`; the views events on the way are kept.
inline std::optional<json> finalReply(Connection& c, int id, std::vector<json>& views,
                                      std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    auto m = c.next(std::chrono::duration_cast<std::chrono::milliseconds>(
        end - std::chrono::steady_clock::now()));
    if (!m) return std::nullopt;
    if ((*m)["class"] == "EVENT") {
      if ((*m)["event"] == "views") views.push_back(*m);
      continue;
    }
    if ((*m)["id"] == id && m->value("state", "") != "started") return m;
  }
  return std::nullopt;
}

}  // namespace procam::itest
