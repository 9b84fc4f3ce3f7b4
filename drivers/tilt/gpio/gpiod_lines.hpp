#pragma once
// libgpiod v1.6 backend of GpioLines: both-edge events on lines of one chip.
#include <string>
#include <vector>

#include "tilt/gpio/ball_switch.hpp"

struct gpiod_chip;
struct gpiod_line_bulk;

namespace procam::tilt {

class GpiodLines final : public GpioLines {
 public:
  // `chip`: a path (/dev/gpiochipN) or a name (gpiochipN). kIo when unavailable.
  static Result<std::unique_ptr<GpiodLines>> open(const std::string& chip,
                                                  const std::vector<unsigned>& offsets);
  ~GpiodLines() override;

  Result<std::vector<bool>> levels() override;
  Result<std::optional<GpioEdge>> waitEdge(int timeout_ms) override;
  std::uint64_t nowNs() override { return monotonicNs(); }

 private:
  GpiodLines() = default;
  gpiod_chip* chip_ = nullptr;
  std::unique_ptr<gpiod_line_bulk> bulk_;
};

}  // namespace procam::tilt
