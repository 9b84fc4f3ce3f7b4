#include "settings.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

namespace procam::daemon {

namespace {
constexpr const char* kPatterns[] = {"off", "grid", "crosshair", "white", "black"};
}

bool isPatternName(std::string_view name) {
  for (const char* p : kPatterns) {
    if (name == p) return true;
  }
  return false;
}

const char* patternNames() {
  return "off, grid, crosshair, white, black";
}

Result<void> validateQuad(const Quad& q) {
  for (const auto& p : q) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1])) {
      return fail(ErrorCode::kInvalidInput, "corner coordinates must be finite numbers");
    }
  }
  // z of (b - a) x (c - b) at every corner: with y down, a clockwise-on-screen
  // quad has every turn positive. Zero means collinear corners.
  for (int i = 0; i < 4; ++i) {
    const auto& a = q[i];
    const auto& b = q[(i + 1) % 4];
    const auto& c = q[(i + 2) % 4];
    const double cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]);
    const double scale =
        std::hypot(b[0] - a[0], b[1] - a[1]) * std::hypot(c[0] - b[0], c[1] - b[1]);
    if (!(cross > 1e-9 * scale) || scale == 0) {
      return fail(ErrorCode::kInvalidInput,
                  "corners must form a convex quadrilateral listed top-left, top-right, "
                  "bottom-right, bottom-left (problem at corner " +
                      std::to_string((i + 1) % 4) + ")");
    }
  }
  return {};
}

std::string settingsToJson(const Settings& s) {
  nlohmann::json j;
  j["schema"] = kSettingsSchema;
  j["auto_keystone"] = s.auto_keystone;
  j["rig_keystone"] = s.rig_keystone;
  if (s.keystone) {
    nlohmann::json corners = nlohmann::json::array();
    for (const auto& p : *s.keystone) corners.push_back({p[0], p[1]});
    j["keystone"] = {{"corners", corners}};
  } else {
    j["keystone"] = nullptr;
  }
  j["pattern"] = s.pattern;
  j["content"] = s.content.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.content);
  return j.dump(2) + "\n";
}

Result<Settings> settingsFromJson(std::string_view text) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded()) return fail(ErrorCode::kParse, "not valid JSON");
  if (!j.is_object()) return fail(ErrorCode::kParse, "not a JSON object");
  auto field = [&](const char* key) -> const nlohmann::json* {
    auto it = j.find(key);
    return it == j.end() ? nullptr : &*it;
  };
  const auto* schema = field("schema");
  if (!schema || !schema->is_number_integer() || schema->get<int64_t>() != kSettingsSchema) {
    return fail(ErrorCode::kParse, "missing or unsupported \"schema\" (expected " +
                                       std::to_string(kSettingsSchema) + ")");
  }
  Settings s;
  const auto* autok = field("auto_keystone");
  if (!autok || !autok->is_boolean())
    return fail(ErrorCode::kParse, "\"auto_keystone\" must be a boolean");
  s.auto_keystone = autok->get<bool>();
  // Absent in files written before keystone from the rig model existed: off.
  if (const auto* rigk = field("rig_keystone")) {
    if (!rigk->is_boolean()) return fail(ErrorCode::kParse, "\"rig_keystone\" must be a boolean");
    s.rig_keystone = rigk->get<bool>();
  }
  const auto* ks = field("keystone");
  if (!ks) return fail(ErrorCode::kParse, "missing \"keystone\"");
  if (!ks->is_null()) {
    const auto it = ks->is_object() ? ks->find("corners") : ks->end();
    if (it == ks->end() || !it->is_array() || it->size() != 4) {
      return fail(ErrorCode::kParse, "\"keystone.corners\" must be 4 [x, y] pairs");
    }
    Quad q{};
    for (size_t i = 0; i < 4; ++i) {
      const auto& p = (*it)[i];
      if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
        return fail(ErrorCode::kParse, "\"keystone.corners\" must be 4 [x, y] pairs");
      }
      q[i] = {p[0].get<double>(), p[1].get<double>()};
    }
    if (auto ok = validateQuad(q); !ok) return fail(ErrorCode::kParse, ok.error().message);
    s.keystone = q;
  }
  const auto* pattern = field("pattern");
  if (!pattern || !pattern->is_string() || !isPatternName(pattern->get<std::string>())) {
    return fail(ErrorCode::kParse, std::string("\"pattern\" must be one of ") + patternNames());
  }
  s.pattern = pattern->get<std::string>();
  const auto* content = field("content");
  if (!content || !(content->is_null() || content->is_string())) {
    return fail(ErrorCode::kParse, "\"content\" must be a path or null");
  }
  if (content->is_string()) s.content = content->get<std::string>();
  return s;
}

}  // namespace procam::daemon
