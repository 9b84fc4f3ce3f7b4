#pragma once
// The decisions of the KMS output that need no device: connector names, connector and
// mode choice from configuration, atomic-or-legacy choice from the property tables,
// and frame statistics from page-flip events. Tested with stored tables.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace procam::output::kms {

struct Mode {
  std::string name;  // "1920x1080"
  int width = 0, height = 0;
  double refresh_hz = 0;  // from clock / (htotal * vtotal)
  bool preferred = false;
};

struct Connector {
  uint32_t id = 0;
  std::string name;  // kernel naming: "HDMI-A-1", "DP-2", "eDP-1"
  bool connected = false;
  std::vector<Mode> modes;
  std::vector<uint32_t> crtcs;  // CRTC ids its encoders can drive, preferred first
};

// Configuration: connector name ("" = first connected), mode ("" or "preferred",
// "WIDTHxHEIGHT", "WIDTHxHEIGHT@HZ").
struct OutputRequest {
  std::string connector;
  std::string mode;
};

struct ModeSpec {
  bool preferred = true;
  int width = 0, height = 0;
  std::optional<double> refresh_hz;
};

// Vertical refresh of a mode line: clock (kHz) / (htotal * vtotal), doubled for
// interlaced and halved for double-scan modes; 0 when totals are zero.
double refreshHz(uint32_t clock_khz, uint32_t htotal, uint32_t vtotal, bool interlaced,
                 bool doublescan);

// kParse for anything but the three forms above.
Result<ModeSpec> parseModeSpec(const std::string& text);

// Kernel name of a connector type (DRM_MODE_CONNECTOR_*), e.g. 11 -> "HDMI-A".
std::string connectorTypeName(uint32_t type);

struct Choice {
  size_t connector = 0;  // index into the connector list
  size_t mode = 0;       // index into its modes
  uint32_t crtc = 0;
};

// kNotFound naming what is missing (no connected connector, unknown connector with the
// names available, no matching mode with the modes available, no free CRTC).
// Mode choice: the preferred mode (else the largest); WxH picks the highest refresh
// among exact-size modes; WxH@Hz the closest refresh within 0.5 Hz.
Result<Choice> chooseOutput(const std::vector<Connector>& connectors, const OutputRequest& request);

// Property names the atomic path needs on each object type.
struct PropertyTable {
  std::vector<std::string> connector, crtc, plane;
};
const PropertyTable& atomicProperties();

// Atomic modesetting when the client cap was accepted and every needed property is
// present; otherwise legacy, with the reason.
struct ApiChoice {
  bool atomic = false;
  std::string reason;
};
ApiChoice chooseModesetApi(bool atomic_cap_accepted, const PropertyTable& present);

// Frame-time and missed-vblank statistics from page-flip events (vblank sequence
// number and timestamp).
class FrameStats {
 public:
  void flip(uint32_t sequence, double seconds);
  uint64_t frames() const { return frames_; }
  uint64_t missedVblanks() const { return missed_; }
  double meanFrameSeconds() const { return intervals_ ? sum_ / intervals_ : 0; }
  double maxFrameSeconds() const { return max_; }

 private:
  bool has_last_ = false;
  uint32_t last_seq_ = 0;
  double last_t_ = 0, sum_ = 0, max_ = 0;
  uint64_t frames_ = 0, missed_ = 0, intervals_ = 0;
};

}  // namespace procam::output::kms
