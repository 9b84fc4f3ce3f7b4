#pragma once
// One frame of a camera for an installer aiming it, focusing it and setting its
// exposure (the `snapshot` request, PROTOCOL.md): the frame as the camera gave it,
// encoded as PNG, the exposure and gain the driver reports, and how much of the
// frame is clipped at either end of the camera's range.
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <tl/expected.hpp>
#include <vector>

#include "calibration_job.hpp"

namespace procam::daemon {

// Pixel shares of a frame, in percent. A pixel is saturated when a channel is at or
// above 98 % of the full scale, under-exposed when every channel is at or below 2 %:
// the margins of an exposure indicator, which keep one code of noise from deciding.
struct SnapshotLevels {
  double saturated_pct = 0;
  double underexposed_pct = 0;
  double mean_pct = 0;  // mean of the brightest channel, percent of the full scale
};
SnapshotLevels snapshotLevels(const cv::Mat& image);

struct Snapshot {
  uint32_t width = 0, height = 0;
  procam_pixel_format format = PROCAM_PIXEL_GRAY8;
  uint64_t timestamp_ns = 0;
  SnapshotLevels levels;
  std::optional<procam_camera_settings> settings;
  std::vector<unsigned char> png;
};

// Sets the exposure first when one is given (the camera keeps it), then captures one
// frame (5 s at most, or two exposures and a second) and encodes it. Worker thread; the caller
// holds the camera.
tl::expected<Snapshot, CalibrationFailure> takeSnapshot(const CalibrationDevice& camera,
                                                        std::optional<double> exposure_s);

}  // namespace procam::daemon
