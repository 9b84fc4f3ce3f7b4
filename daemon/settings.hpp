#pragma once
// The settings the daemon persists in its state directory (settings.json):
// manual keystone corners, auto keystone, keystone from the rig model, test
// pattern, content image.
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace procam::daemon {

// Output-pixel corners of the corrected image, in the order top-left,
// top-right, bottom-right, bottom-left (x right, y down; ARCHITECTURE.md).
using Quad = std::array<std::array<double, 2>, 4>;

struct Settings {
  bool auto_keystone = false;
  bool rig_keystone = false;     // keystone from the rig model's plane mapping
  std::optional<Quad> keystone;  // none: no manual correction
  std::string pattern = "off";   // off, grid, crosshair, white, black
  std::string content;           // image path; empty: none
};

constexpr int kSettingsSchema = 1;

bool isPatternName(std::string_view name);
// "off, grid, crosshair, white, black"
const char* patternNames();

// Finite coordinates, no three corners collinear, convex, and the corners in
// clockwise order on screen (y down) as listed above.
Result<void> validateQuad(const Quad& quad);

std::string settingsToJson(const Settings& settings);
Result<Settings> settingsFromJson(std::string_view text);

}  // namespace procam::daemon
