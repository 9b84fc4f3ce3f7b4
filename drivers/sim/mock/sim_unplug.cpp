#include "sim_unplug.hpp"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>

namespace procam::sim::mock {

namespace {

// "Seconds since start": the process's, set when the driver library loads.
const auto kProcessStart = std::chrono::steady_clock::now();

bool parseSeconds(std::string_view text, double& out) {
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && ptr == end && std::isfinite(out) && out >= 0;
}

}  // namespace

Result<std::vector<UnplugWindow>> parseUnplugWindows(std::string_view text) {
  std::vector<UnplugWindow> out;
  if (text.empty()) return out;
  for (bool more = true; more;) {
    const size_t comma = text.find(',');
    const std::string_view item = text.substr(0, comma);
    more = comma != std::string_view::npos;
    if (more) text = text.substr(comma + 1);
    const size_t at = item.rfind('@');
    const size_t dash = at == std::string_view::npos ? at : item.find('-', at);
    UnplugWindow w;
    if (at == 0 || dash == std::string_view::npos ||
        !parseSeconds(item.substr(at + 1, dash - at - 1), w.from_s) ||
        !parseSeconds(item.substr(dash + 1), w.to_s) || w.to_s < w.from_s) {
      return fail(ErrorCode::kInvalidInput, std::string(kUnplugVariable) + ": '" +
                                                std::string(item) +
                                                "' is not name@T1-T2 (seconds, T1 <= T2)");
    }
    w.device = std::string(item.substr(0, at));
    out.push_back(std::move(w));
  }
  return out;
}

bool unpluggedAt(const std::vector<UnplugWindow>& windows, std::string_view device, double t) {
  for (const auto& w : windows) {
    if (w.device == device && t >= w.from_s && t < w.to_s) return true;
  }
  return false;
}

Result<bool> unpluggedNow(std::string_view device) {
  const char* env = std::getenv(kUnplugVariable);
  if (!env || !*env) return false;
  auto windows = parseUnplugWindows(env);
  if (!windows) return tl::unexpected(windows.error());
  const double t =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - kProcessStart).count();
  return unpluggedAt(*windows, device, t);
}

}  // namespace procam::sim::mock
