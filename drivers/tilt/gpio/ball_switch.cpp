#include "tilt/gpio/ball_switch.hpp"

#include <cmath>

namespace procam::tilt {

Debouncer::Debouncer(std::vector<bool> initial, std::uint64_t debounce_ns)
    : stable_(initial),
      pending_(initial),
      last_edge_(initial.size(), 0),
      debounce_ns_(debounce_ns) {}

void Debouncer::edge(const GpioEdge& e) {
  if (e.line < 0 || std::size_t(e.line) >= pending_.size()) return;
  pending_[std::size_t(e.line)] = e.level;
  last_edge_[std::size_t(e.line)] = e.timestamp_ns;
}

bool Debouncer::settle(std::uint64_t now_ns) {
  bool changed = false;
  for (std::size_t i = 0; i < stable_.size(); ++i)
    if (pending_[i] != stable_[i] && now_ns >= last_edge_[i] + debounce_ns_) {
      stable_[i] = pending_[i];
      changed = true;
    }
  return changed;
}

Vec3 nominalSpecificForce(CoarseOrientation o, double tilt_angle) {
  // Specific force points up; rolled clockwise by r, up in the device frame is
  // (-sin r, -cos r, 0).
  double roll = 0;
  switch (o) {
    case CoarseOrientation::kUpright:
      roll = 0;
      break;
    case CoarseOrientation::kTiltedRight:
      roll = tilt_angle;
      break;
    case CoarseOrientation::kTiltedLeft:
      roll = -tilt_angle;
      break;
    case CoarseOrientation::kUpsideDown:
      roll = M_PI;
      break;
  }
  return kStandardGravity * Vec3(-std::sin(roll), -std::cos(roll), 0);
}

Result<void> BallSwitchTilt::open() {
  if (debouncer_) return {};
  auto levels = lines_->levels();
  if (!levels) return tl::unexpected(levels.error());
  if (levels->size() != 2) return fail(ErrorCode::kInvalidInput, "gpio tilt needs two lines");
  debouncer_.emplace(*levels, config_.debounce_ns);
  return {};
}

std::optional<CoarseOrientation> BallSwitchTilt::orientation() const {
  if (!debouncer_) return std::nullopt;
  const auto& l = debouncer_->levels();
  return config_.table[std::size_t(l[0]) | (std::size_t(l[1]) << 1)];
}

Result<TiltSample> BallSwitchTilt::read() {
  if (!debouncer_) return fail(ErrorCode::kIo, "gpio: not open");
  const std::uint64_t deadline = lines_->nowNs() + std::uint64_t(config_.wait_ms) * 1'000'000;
  // Edges already queued are taken even with wait_ms = 0 (a timer-polled device); a
  // switch chattering without end cannot hold the read past the deadline for long.
  for (int late = 0; late < 64;) {
    const std::uint64_t now = lines_->nowNs();
    late += now >= deadline;
    auto edge = lines_->waitEdge(now >= deadline ? 0 : int((deadline - now) / 1'000'000));
    if (!edge) return tl::unexpected(edge.error());
    if (!*edge) break;
    debouncer_->edge(**edge);
  }
  debouncer_->settle(lines_->nowNs());
  TiltSample s;
  s.timestamp_ns = lines_->nowNs();
  s.specific_force = nominalSpecificForce(*orientation(), config_.tilt_angle);
  return s;
}

}  // namespace procam::tilt
