#include "camera_snapshot.hpp"

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "driver.hpp"
#include "protocol.hpp"

namespace procam::daemon {

namespace code = proto::code;

SnapshotLevels snapshotLevels(const cv::Mat& image) {
  SnapshotLevels l;
  if (image.empty()) return l;
  const double full = image.depth() == CV_16U ? 65535.0 : 255.0;
  // The brightest channel of each pixel: clipping in any channel spoils a pattern.
  cv::Mat brightest = image;
  if (image.channels() > 1) {
    std::vector<cv::Mat> planes;
    cv::split(image, planes);
    brightest = planes[0].clone();
    for (int c = 1; c < std::min(3, image.channels()); ++c) {
      cv::max(brightest, planes[size_t(c)], brightest);
    }
  }
  const double n = double(brightest.total());
  l.saturated_pct = 100.0 * double(cv::countNonZero(brightest >= 0.98 * full)) / n;
  l.underexposed_pct = 100.0 * double(cv::countNonZero(brightest <= 0.02 * full)) / n;
  l.mean_pct = 100.0 * cv::mean(brightest)[0] / full;
  return l;
}

namespace {

// The frame in OpenCV's channel order (what imencode writes), copied out of the
// driver's buffer; empty for a format this daemon does not know.
cv::Mat frameImage(const procam_image& img) {
  const int w = static_cast<int>(img.width), h = static_cast<int>(img.height);
  cv::Mat out;
  switch (img.format) {
    case PROCAM_PIXEL_GRAY8:
      return cv::Mat(h, w, CV_8UC1, img.data, img.stride).clone();
    case PROCAM_PIXEL_GRAY16:
      return cv::Mat(h, w, CV_16UC1, img.data, img.stride).clone();
    case PROCAM_PIXEL_RGB8:
      cv::cvtColor(cv::Mat(h, w, CV_8UC3, img.data, img.stride), out, cv::COLOR_RGB2BGR);
      return out;
    case PROCAM_PIXEL_RGBA8:
      cv::cvtColor(cv::Mat(h, w, CV_8UC4, img.data, img.stride), out, cv::COLOR_RGBA2BGRA);
      return out;
  }
  return out;
}

}  // namespace

tl::expected<Snapshot, CalibrationFailure> takeSnapshot(const CalibrationDevice& camera,
                                                        std::optional<double> exposure_s) {
  const auto& raw = camera.device->raw();
  char err[256] = {0};
  if (exposure_s) {
    if (int rc = raw.ops.camera->set_exposure(raw.self, *exposure_s, err, sizeof err - 1);
        rc != PROCAM_OK) {
      auto f = deviceFailure("camera", camera.name, rc, "set the exposure", err);
      if (rc == PROCAM_ENOTSUP) f.code = code::kUnavailable;
      return tl::unexpected(f);
    }
  }
  procam_image img{};
  // 5 s, or long enough for two frames of a long exposure asked for.
  const int timeout_ms = exposure_s ? std::max(5000, int(2000 * *exposure_s) + 1000) : 5000;
  if (int rc = raw.ops.camera->capture(raw.self, timeout_ms, &img, err, sizeof err - 1);
      rc != PROCAM_OK) {
    return tl::unexpected(deviceFailure("camera", camera.name, rc, "capture", err));
  }
  Snapshot s;
  s.width = img.width;
  s.height = img.height;
  s.format = img.format;
  s.timestamp_ns = img.timestamp_ns;
  const cv::Mat image = frameImage(img);
  if (image.empty()) {
    return tl::unexpected(CalibrationFailure{
        code::kIo, "camera '" + camera.name + "' returned an unknown pixel format"});
  }
  s.levels = snapshotLevels(image);
  s.settings = plugins::cameraSettings(raw);
  // Fast PNG (level 1): a snapshot is looked at once; the loop waits for the reply.
  if (!cv::imencode(".png", image, s.png, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
    return tl::unexpected(
        CalibrationFailure{code::kInternal, "cannot encode camera '" + camera.name + "' as PNG"});
  }
  return s;
}

}  // namespace procam::daemon
