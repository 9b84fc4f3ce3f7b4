#include "camera/camera.hpp"

#include <ctime>

namespace procam::camera {

const char* toString(Control control) {
  switch (control) {
    case Control::kExposure:
      return "exposure";
    case Control::kAutoExposure:
      return "auto exposure";
    case Control::kGain:
      return "gain";
    case Control::kWhiteBalance:
      return "white balance";
    case Control::kPowerLine:
      return "power-line frequency";
  }
  return "unknown control";
}

tl::unexpected<Error> unsupported(const std::string& device, Control control) {
  return fail(ErrorCode::kNotSupported,
              device + ": " + toString(control) + " is not supported by this device");
}

uint64_t monotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return uint64_t(ts.tv_sec) * 1'000'000'000ull + uint64_t(ts.tv_nsec);
}

}  // namespace procam::camera
