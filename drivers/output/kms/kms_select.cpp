#include "kms/kms_select.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <system_error>

namespace procam::output::kms {

double refreshHz(uint32_t clock_khz, uint32_t htotal, uint32_t vtotal, bool interlaced,
                 bool doublescan) {
  if (htotal == 0 || vtotal == 0) return 0;
  double hz = clock_khz * 1000.0 / (static_cast<double>(htotal) * vtotal);
  if (interlaced) hz *= 2;
  if (doublescan) hz /= 2;
  return hz;
}

Result<ModeSpec> parseModeSpec(const std::string& text) {
  ModeSpec spec;
  if (text.empty() || text == "preferred") return spec;
  // WIDTHxHEIGHT[@HZ]: digits, 'x', digits, optionally '@' and a decimal number.
  auto bad = [&] {
    return fail(ErrorCode::kParse, "mode '" + text + "': expected preferred, WxH or WxH@Hz");
  };
  const char* p = text.data();
  const char* end = p + text.size();
  auto number = [&](int& out) {
    const auto r = std::from_chars(p, end, out);
    if (r.ec != std::errc() || r.ptr == p || r.ptr - p > 5) return false;
    p = r.ptr;
    return true;
  };
  spec.preferred = false;
  if (!number(spec.width) || p == end || *p++ != 'x' || !number(spec.height)) return bad();
  if (p != end) {
    if (*p++ != '@' || p == end) return bad();
    double hz = 0;
    const auto r = std::from_chars(p, end, hz);
    if (r.ec != std::errc() || r.ptr != end || !(hz > 0) || hz > 1000) return bad();
    spec.refresh_hz = hz;
  }
  if (spec.width <= 0 || spec.height <= 0) {
    return fail(ErrorCode::kParse, "mode '" + text + "': zero size");
  }
  return spec;
}

std::string connectorTypeName(uint32_t type) {
  // Names as the kernel prints them (drm_connector_enum_list).
  static const char* const names[] = {
      "Unknown", "VGA",       "DVI-I", "DVI-D", "DVI-A",     "Composite", "SVIDEO",
      "LVDS",    "Component", "DIN",   "DP",    "HDMI-A",    "HDMI-B",    "TV",
      "eDP",     "Virtual",   "DSI",   "DPI",   "Writeback", "SPI",       "USB"};
  if (type < sizeof(names) / sizeof(names[0])) return names[type];
  return "Unknown";
}

namespace {

std::string listNames(const std::vector<Connector>& cs) {
  std::string s;
  for (const auto& c : cs)
    s += (s.empty() ? "" : ", ") + c.name + (c.connected ? "" : " (disconnected)");
  return s.empty() ? "none" : s;
}

std::string listModes(const Connector& c) {
  std::string s;
  char buf[64];
  for (const auto& m : c.modes) {
    std::snprintf(buf, sizeof(buf), "%dx%d@%.2f", m.width, m.height, m.refresh_hz);
    s += (s.empty() ? "" : ", ") + std::string(buf);
  }
  return s.empty() ? "none" : s;
}

std::optional<size_t> pickMode(const Connector& c, const ModeSpec& spec) {
  std::optional<size_t> best;
  for (size_t i = 0; i < c.modes.size(); ++i) {
    const Mode& m = c.modes[i];
    if (spec.preferred) {
      if (m.preferred) return i;
      // No preferred flag: the largest mode, then the highest refresh.
      if (!best || m.width * m.height > c.modes[*best].width * c.modes[*best].height ||
          (m.width * m.height == c.modes[*best].width * c.modes[*best].height &&
           m.refresh_hz > c.modes[*best].refresh_hz)) {
        best = i;
      }
      continue;
    }
    if (m.width != spec.width || m.height != spec.height) continue;
    if (spec.refresh_hz) {
      const double d = std::abs(m.refresh_hz - *spec.refresh_hz);
      if (d <= 0.5 && (!best || d < std::abs(c.modes[*best].refresh_hz - *spec.refresh_hz)))
        best = i;
    } else if (!best || m.refresh_hz > c.modes[*best].refresh_hz) {
      best = i;
    }
  }
  return best;
}

}  // namespace

Result<Choice> chooseOutput(const std::vector<Connector>& connectors,
                            const OutputRequest& request) {
  auto spec = parseModeSpec(request.mode);
  if (!spec) return tl::unexpected(spec.error());
  std::optional<size_t> ci;
  for (size_t i = 0; i < connectors.size(); ++i) {
    if (request.connector.empty() ? connectors[i].connected
                                  : connectors[i].name == request.connector) {
      ci = i;
      break;
    }
  }
  if (!ci) {
    if (request.connector.empty()) {
      return fail(ErrorCode::kNotFound,
                  "no connected display connector (connectors: " + listNames(connectors) + ")");
    }
    return fail(ErrorCode::kNotFound, "connector '" + request.connector +
                                          "' not found (connectors: " + listNames(connectors) +
                                          ")");
  }
  const Connector& c = connectors[*ci];
  if (!c.connected) {
    return fail(ErrorCode::kNotFound, "connector " + c.name + " has no display connected");
  }
  const auto mi = pickMode(c, *spec);
  if (!mi) {
    return fail(ErrorCode::kNotFound, "connector " + c.name + " has no mode '" + request.mode +
                                          "' (modes: " + listModes(c) + ")");
  }
  if (c.crtcs.empty()) {
    return fail(ErrorCode::kNotFound, "connector " + c.name + ": no CRTC can drive it");
  }
  return Choice{*ci, *mi, c.crtcs.front()};
}

const PropertyTable& atomicProperties() {
  static const PropertyTable t{{"CRTC_ID"},
                               {"MODE_ID", "ACTIVE"},
                               {"FB_ID", "CRTC_ID", "SRC_X", "SRC_Y", "SRC_W", "SRC_H", "CRTC_X",
                                "CRTC_Y", "CRTC_W", "CRTC_H"}};
  return t;
}

ApiChoice chooseModesetApi(bool atomic_cap_accepted, const PropertyTable& present) {
  if (!atomic_cap_accepted) return {false, "driver refused DRM_CLIENT_CAP_ATOMIC"};
  const PropertyTable& need = atomicProperties();
  auto missing = [](const std::vector<std::string>& want, const std::vector<std::string>& have,
                    const char* object) -> std::string {
    for (const auto& n : want) {
      if (std::find(have.begin(), have.end(), n) == have.end()) {
        return std::string(object) + " property " + n + " missing";
      }
    }
    return "";
  };
  for (auto r :
       {missing(need.connector, present.connector, "connector"),
        missing(need.crtc, present.crtc, "CRTC"), missing(need.plane, present.plane, "plane")}) {
    if (!r.empty()) return {false, r};
  }
  return {true, "atomic"};
}

void FrameStats::flip(uint32_t sequence, double seconds) {
  ++frames_;
  if (has_last_) {
    // Vblank counters are 32-bit and wrap; unsigned subtraction handles it.
    const uint32_t delta = sequence - last_seq_;
    if (delta > 1) missed_ += delta - 1;
    const double dt = seconds - last_t_;
    if (dt >= 0) {
      sum_ += dt;
      max_ = std::max(max_, dt);
      ++intervals_;
    }
  }
  has_last_ = true;
  last_seq_ = sequence;
  last_t_ = seconds;
}

}  // namespace procam::output::kms
