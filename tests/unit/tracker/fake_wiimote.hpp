#pragma once
// A Wii Remote behind WiimoteTransport: acknowledges output reports as the device does
// (0x16 always, the others when they ask), with scripted failures, then delivers queued
// input reports; records everything written in a log that outlives it (a failed
// setup destroys the transport).
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "tracker/hid/wiimote_ir_source.hpp"

namespace procam::tracker::wiimote::testing {

class FakeWiimote final : public WiimoteTransport {
 public:
  struct Input {
    Report report;
    std::uint64_t time_ns = 0;  // what the clock reads once it is delivered
  };

  std::shared_ptr<std::vector<Report>> written = std::make_shared<std::vector<Report>>();
  std::deque<Input> inbox;             // delivered after any pending acknowledgements
  std::optional<std::uint8_t> silent;  // never acknowledges this output report
  std::optional<std::pair<std::uint8_t, std::uint8_t>> error_ack;  // (report, error code)
  std::optional<Report> before_ack;  // delivered ahead of every acknowledgement
  bool write_fails = false;
  std::uint64_t now_ns = 0;  // time of the last delivered input

  Result<void> write(std::span<const std::uint8_t> report) override {
    if (write_fails) return fail(ErrorCode::kIo, "write: No such device");
    written->emplace_back(report.begin(), report.end());
    const std::uint8_t id = report[0];
    const bool wants_ack = id == 0x16 || (report.size() > 1 && (report[1] & 0x02));
    if (!wants_ack || silent == id) return {};
    if (before_ack) acks_.push_back(*before_ack);
    const std::uint8_t code = error_ack && error_ack->first == id ? error_ack->second : 0;
    acks_.push_back({0x22, 0x00, 0x00, id, code});
    return {};
  }

  Result<std::vector<std::uint8_t>> read(int) override {
    if (!acks_.empty()) {
      Report r = acks_.front();
      acks_.pop_front();
      return r;
    }
    if (inbox.empty()) return fail(ErrorCode::kNotFound, "no report within the timeout");
    Input in = inbox.front();
    inbox.pop_front();
    now_ns = in.time_ns;
    return in.report;
  }

 private:
  std::deque<Report> acks_;
};

}  // namespace procam::tracker::wiimote::testing
