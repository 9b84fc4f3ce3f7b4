#pragma once
// Ball tilt switches on GPIO lines: debounced edges -> coarse orientation (upright,
// tilted left/right, upside down). The line access is an interface (GpioLines) so the
// logic is tested with scripted edges; gpiod_lines.hpp is the libgpiod v1.6 backend.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "tilt/tilt_sensor.hpp"

namespace procam::tilt {

struct GpioEdge {
  int line = 0;  // index into the requested lines
  bool level = false;
  std::uint64_t timestamp_ns = 0;
};

class GpioLines {
 public:
  virtual ~GpioLines() = default;
  virtual Result<std::vector<bool>> levels() = 0;
  // The next edge, or nullopt after timeout_ms without one.
  virtual Result<std::optional<GpioEdge>> waitEdge(int timeout_ms) = 0;
  virtual std::uint64_t nowNs() = 0;
};

// Per-line debouncing: a level counts once it has held for `debounce_ns`.
class Debouncer {
 public:
  Debouncer(std::vector<bool> initial, std::uint64_t debounce_ns);
  void edge(const GpioEdge& e);
  // Applies every pending level that has been stable long enough; true if any changed.
  bool settle(std::uint64_t now_ns);
  const std::vector<bool>& levels() const { return stable_; }

 private:
  std::vector<bool> stable_, pending_;
  std::vector<std::uint64_t> last_edge_;
  std::uint64_t debounce_ns_;
};

enum class CoarseOrientation { kUpright, kTiltedLeft, kTiltedRight, kUpsideDown };

struct BallSwitchConfig {
  // Orientation for each combination of the two switch levels, indexed by
  // level0 | level1 << 1 (the wiring of the sensor decides it).
  std::array<CoarseOrientation, 4> table = {
      CoarseOrientation::kUpsideDown, CoarseOrientation::kTiltedLeft,
      CoarseOrientation::kTiltedRight, CoarseOrientation::kUpright};
  std::uint64_t debounce_ns = 20'000'000;  // 20 ms
  double tilt_angle = 0.785398163397448;   // rad: nominal roll reported when tilted
  int wait_ms = 50;                        // per read()
};

// Nominal specific force (m/s^2, x right, y down, z forward) of a coarse orientation;
// tilted right = rolled clockwise (seen from behind) by `tilt_angle`.
Vec3 nominalSpecificForce(CoarseOrientation o, double tilt_angle);

class BallSwitchTilt final : public TiltSensor {
 public:
  BallSwitchTilt(std::unique_ptr<GpioLines> lines, BallSwitchConfig config)
      : lines_(std::move(lines)), config_(config) {}
  ~BallSwitchTilt() override { close(); }

  Result<void> open() override;
  // Waits up to wait_ms for edges, then reports the debounced orientation.
  Result<TiltSample> read() override;
  void close() override { debouncer_.reset(); }
  std::string name() const override { return "gpio"; }

  std::optional<CoarseOrientation> orientation() const;

 private:
  std::unique_ptr<GpioLines> lines_;
  BallSwitchConfig config_;
  std::optional<Debouncer> debouncer_;
};

}  // namespace procam::tilt
