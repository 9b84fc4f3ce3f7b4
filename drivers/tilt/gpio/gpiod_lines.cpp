#include "tilt/gpio/gpiod_lines.hpp"

#include <gpiod.h>

#include <cerrno>
#include <cstring>

namespace procam::tilt {

Result<std::unique_ptr<GpiodLines>> GpiodLines::open(const std::string& chip,
                                                     const std::vector<unsigned>& offsets) {
  std::unique_ptr<GpiodLines> out(new GpiodLines());
  out->chip_ = gpiod_chip_open_lookup(chip.c_str());
  if (!out->chip_) return fail(ErrorCode::kIo, chip + ": " + std::strerror(errno));
  out->bulk_ = std::make_unique<gpiod_line_bulk>();
  if (gpiod_chip_get_lines(out->chip_, const_cast<unsigned*>(offsets.data()),
                           unsigned(offsets.size()), out->bulk_.get()) < 0)
    return fail(ErrorCode::kIo, chip + ": lines: " + std::strerror(errno));
  if (gpiod_line_request_bulk_both_edges_events(out->bulk_.get(), "procamd") < 0)
    return fail(ErrorCode::kIo, chip + ": edge request: " + std::strerror(errno));
  return out;
}

GpiodLines::~GpiodLines() {
  if (bulk_ && chip_) gpiod_line_release_bulk(bulk_.get());
  if (chip_) gpiod_chip_close(chip_);
}

Result<std::vector<bool>> GpiodLines::levels() {
  std::vector<int> values(bulk_->num_lines);
  if (gpiod_line_get_value_bulk(bulk_.get(), values.data()) < 0)
    return fail(ErrorCode::kIo, std::string("gpio read: ") + std::strerror(errno));
  return std::vector<bool>(values.begin(), values.end());
}

Result<std::optional<GpioEdge>> GpiodLines::waitEdge(int timeout_ms) {
  const timespec timeout{timeout_ms / 1000, long(timeout_ms % 1000) * 1'000'000};
  gpiod_line_bulk ready;
  gpiod_line_bulk_init(&ready);
  const int r = gpiod_line_event_wait_bulk(bulk_.get(), &timeout, &ready);
  if (r < 0) return fail(ErrorCode::kIo, std::string("gpio wait: ") + std::strerror(errno));
  if (r == 0 || ready.num_lines == 0) return std::optional<GpioEdge>();
  gpiod_line* line = ready.lines[0];
  gpiod_line_event event{};
  if (gpiod_line_event_read(line, &event) < 0)
    return fail(ErrorCode::kIo, std::string("gpio event: ") + std::strerror(errno));
  GpioEdge edge;
  for (unsigned i = 0; i < bulk_->num_lines; ++i)
    if (bulk_->lines[i] == line) edge.line = int(i);
  edge.level = event.event_type == GPIOD_LINE_EVENT_RISING_EDGE;
  // v1.6 stamps events with CLOCK_MONOTONIC (kernel >= 5.7) or CLOCK_REALTIME before;
  // the read time keeps one clock for debouncing.
  edge.timestamp_ns = monotonicNs();
  return std::optional<GpioEdge>(edge);
}

}  // namespace procam::tilt
