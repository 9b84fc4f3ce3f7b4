#include "tracker/ir_camera/ir_camera_tracker.hpp"

#include <array>
#include <string>

#include "support/driver_support.hpp"

namespace procam::tracker {
namespace {

const char* pixelName(procam_pixel_format f) {
  return f == PROCAM_PIXEL_GRAY8 ? "gray8" : f == PROCAM_PIXEL_GRAY16 ? "gray16" : "rgb8";
}

}  // namespace

OwnedCamera& OwnedCamera::operator=(OwnedCamera&& other) noexcept {
  if (this != &other) {
    release();
    device_ = other.device_;
    other.device_ = {};
  }
  return *this;
}

void OwnedCamera::release() {
  if (device_.destroy) device_.destroy(device_.self);
  device_ = {};
}

Result<IrCameraTracker> IrCameraTracker::create(OwnedCamera camera, const IrCameraConfig& config) {
  if (!camera.valid()) return fail(ErrorCode::kInternal, "ir_camera tracker: no camera");
  const procam_device& raw = camera.raw();
  uint32_t width = 0, height = 0;
  procam_pixel_format pixel = PROCAM_PIXEL_GRAY8;
  if (const int rc = raw.ops.camera->get_format(raw.self, &width, &height, &pixel); rc != PROCAM_OK)
    return fail(plugins::codeOf(rc), "ir_camera tracker: the camera has no format");
  if (pixel != PROCAM_PIXEL_GRAY8 && pixel != PROCAM_PIXEL_GRAY16)
    return fail(ErrorCode::kInvalidInput,
                std::string("ir_camera tracker: the camera delivers ") + pixelName(pixel) +
                    "; IR blobs need gray8 or gray16 (camera.pixel = gray8)");
  // The detector checks its own options; a blank frame costs nothing.
  if (auto ok = tracking::detectBlobs(cv::Mat(1, 1, CV_8UC1, cv::Scalar(0)), {}, config.blobs); !ok)
    return fail(ErrorCode::kInvalidInput, "ir_camera tracker: " + ok.error().message);
  geom::CameraModel model;
  model.K = config.K;
  model.dist = config.dist;
  model.pose = config.pose;
  model.width = static_cast<int>(width);
  model.height = static_cast<int>(height);
  auto tracker = tracking::LedTracker::create(model, config.tracker);
  if (!tracker)
    return fail(ErrorCode::kInvalidInput, "ir_camera tracker: " + tracker.error().message);
  return IrCameraTracker(std::move(camera), config, std::move(*tracker));
}

int IrCameraTracker::pollFd() const {
  const procam_device& raw = camera_.raw();
  return raw.poll_fd ? raw.poll_fd(raw.self) : -1;
}

Result<procam_pose_sample> IrCameraTracker::read() {
  const procam_device& raw = camera_.raw();
  procam_image image{};
  std::array<char, 256> err{};
  const int rc = raw.ops.camera->capture(raw.self, config_.capture_timeout_ms, &image, err.data(),
                                         err.size() - 1);
  if (rc != PROCAM_OK) return fail(plugins::codeOf(rc), std::string("camera: ") + err.data());
  if (image.format != PROCAM_PIXEL_GRAY8 && image.format != PROCAM_PIXEL_GRAY16)
    return fail(ErrorCode::kIo, std::string("camera: a ") + pixelName(image.format) +
                                    " frame where gray8 or gray16 was negotiated");
  const cv::Mat frame(static_cast<int>(image.height), static_cast<int>(image.width),
                      image.format == PROCAM_PIXEL_GRAY8 ? CV_8UC1 : CV_16UC1, image.data,
                      image.stride);
  auto blobs = tracking::detectBlobs(frame, {}, config_.blobs);
  if (!blobs) return fail(ErrorCode::kInvalidInput, blobs.error().message);
  Points2 centres;
  centres.reserve(blobs->size());
  for (const tracking::Blob& b : *blobs) centres.push_back(b.center);

  const double time = static_cast<double>(image.timestamp_ns) * 1e-9;
  // A recording that starts over (or a camera whose clock jumped back) starts a new track.
  if (last_time_ && time <= *last_time_) tracker_.reset();
  last_time_ = time;
  auto pose = tracker_.update(centres, time);
  if (!pose) {
    // A frame without a pose is a frame's problem, never the device's.
    const bool unseen =
        pose.error().code == ErrorCode::kNotFound || pose.error().code == ErrorCode::kTooFewPoints;
    return fail(ErrorCode::kAgain, std::string(unseen ? "LEDs not seen: " : "no pose: ") +
                                       std::to_string(centres.size()) + " blob(s), " +
                                       pose.error().message);
  }
  last_ = *pose;
  procam_pose_sample s{};
  for (int i = 0; i < 3; ++i) s.position[i] = pose->predicted(i);
  s.orientation[0] = pose->orientation.w();
  s.orientation[1] = pose->orientation.x();
  s.orientation[2] = pose->orientation.y();
  s.orientation[3] = pose->orientation.z();
  s.timestamp_ns = image.timestamp_ns;
  return s;
}

}  // namespace procam::tracker
