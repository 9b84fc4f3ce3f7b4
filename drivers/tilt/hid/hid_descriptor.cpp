#include "tilt/hid/hid_descriptor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>

#include "core/units.hpp"

namespace procam::tilt {
namespace {

constexpr std::uint16_t kSensorPage = 0x20;
constexpr std::uint16_t kAccelerometer3D = 0x73;
constexpr std::uint16_t kAccelAxes[3] = {0x453, 0x454, 0x455};
constexpr std::uint16_t kGyrometer3D = 0x76;
constexpr std::uint16_t kAngularVelocityAxes[3] = {0x457, 0x458, 0x459};

struct Globals {
  std::uint16_t usage_page = 0;
  std::int32_t logical_min = 0, logical_max = 0;
  std::uint32_t logical_max_unsigned = 0;  // the same item read without sign extension
  std::uint32_t unit = 0;
  int unit_exponent = 0;
  std::uint32_t report_size = 0, report_count = 0;
  std::uint8_t report_id = 0;
};

}  // namespace

std::optional<std::int64_t> HidField::extract(std::span<const std::uint8_t> report) const {
  if (bit_size == 0 || bit_size > 32 || (bit_offset + bit_size + 7) / 8 > report.size())
    return std::nullopt;
  std::uint64_t v = 0;
  for (std::uint32_t i = 0; i < bit_size; ++i) {
    const std::uint32_t bit = bit_offset + i;
    v |= std::uint64_t((report[bit / 8] >> (bit % 8)) & 1) << i;
  }
  if (isSigned() && bit_size < 64 && ((v >> (bit_size - 1)) & 1))
    v |= ~((std::uint64_t(1) << bit_size) - 1);
  return std::int64_t(v);
}

Result<HidDescriptor> parseHidDescriptor(std::span<const std::uint8_t> bytes) {
  HidDescriptor out;
  Globals g;
  std::vector<Globals> stack;
  std::vector<std::uint32_t> usages;  // local: extended (page << 16 | usage) when 4-byte
  std::uint32_t usage_min = 0, usage_max = 0;
  bool has_usage_min = false, has_usage_max = false;
  struct Collection {
    std::uint16_t page, usage;
  };
  std::vector<Collection> collections;
  std::map<std::uint8_t, std::uint32_t> input_bits;  // per report ID

  std::size_t i = 0;
  while (i < bytes.size()) {
    const std::uint8_t prefix = bytes[i];
    if (prefix == 0xFE) {  // long item: size, tag, data
      if (i + 2 >= bytes.size()) return fail(ErrorCode::kParse, "truncated long item");
      i += 3 + bytes[i + 1];
      continue;
    }
    const std::size_t size = (prefix & 3) == 3 ? 4 : (prefix & 3);
    const int type = (prefix >> 2) & 3, tag = prefix >> 4;
    if (i + 1 + size > bytes.size()) return fail(ErrorCode::kParse, "truncated item");
    std::uint32_t u = 0;
    for (std::size_t k = 0; k < size; ++k) u |= std::uint32_t(bytes[i + 1 + k]) << (8 * k);
    std::int32_t s = std::int32_t(u);
    if (size == 1) s = std::int8_t(u);
    if (size == 2) s = std::int16_t(u);
    i += 1 + size;

    if (type == 1) {  // global
      switch (tag) {
        case 0x0:
          g.usage_page = std::uint16_t(u);
          break;
        case 0x1:
          g.logical_min = s;
          break;
        case 0x2:
          g.logical_max = s;
          g.logical_max_unsigned = u;
          break;
        case 0x5:
          g.unit_exponent = (u <= 15) ? (u > 7 ? int(u) - 16 : int(u)) : s;
          break;
        case 0x6:
          g.unit = u;
          break;
        case 0x7:
          g.report_size = u;
          break;
        case 0x8:
          g.report_id = std::uint8_t(u);
          out.uses_report_ids = true;
          break;
        case 0x9:
          g.report_count = u;
          break;
        case 0xA:
          stack.push_back(g);
          break;
        case 0xB:
          if (stack.empty()) return fail(ErrorCode::kParse, "pop without push");
          g = stack.back();
          stack.pop_back();
          break;
        default:
          break;  // physical min/max: not needed
      }
    } else if (type == 2) {  // local
      if (tag == 0x0) usages.push_back(size == 4 ? u : (std::uint32_t(g.usage_page) << 16) | u);
      if (tag == 0x1) usage_min = u, has_usage_min = true;
      if (tag == 0x2) usage_max = u, has_usage_max = true;
    } else if (type == 0) {  // main
      if (tag == 0xA) {      // collection
        const std::uint32_t first = usages.empty() ? 0 : usages.front();
        collections.push_back({std::uint16_t(first >> 16), std::uint16_t(first & 0xFFFF)});
      } else if (tag == 0xC) {
        if (collections.empty())
          return fail(ErrorCode::kParse, "end collection without collection");
        collections.pop_back();
      } else if (tag == 0x8) {  // input
        std::uint32_t& bits = input_bits[g.report_id];
        const bool constant = u & 1;
        // A non-negative range whose maximum only looks negative after sign extension
        // (e.g. 0x26 0xFF 0xFF with a minimum of 0) means the unsigned value.
        const std::int64_t lmax = g.logical_min >= 0 && g.logical_max < 0
                                      ? std::int64_t(g.logical_max_unsigned)
                                      : std::int64_t(g.logical_max);
        for (std::uint32_t k = 0; k < g.report_count; ++k) {
          if (!constant) {
            std::uint32_t usage = 0;
            if (!usages.empty())
              usage = usages[std::min<std::size_t>(k, usages.size() - 1)];
            else if (has_usage_min && has_usage_max)
              usage = (std::uint32_t(g.usage_page) << 16) | std::min(usage_min + k, usage_max);
            HidField f;
            f.report_id = g.report_id;
            f.usage_page = std::uint16_t(usage >> 16);
            f.usage = std::uint16_t(usage & 0xFFFF);
            f.bit_offset = bits;
            f.bit_size = g.report_size;
            f.logical_min = g.logical_min;
            f.logical_max = lmax;
            f.unit = g.unit;
            f.unit_exponent = g.unit_exponent;
            if (!collections.empty()) {
              f.collection_page = collections.back().page;
              f.collection_usage = collections.back().usage;
            }
            out.inputs.push_back(f);
          }
          bits += g.report_size;
        }
      }
      usages.clear();
      has_usage_min = has_usage_max = false;
    }
  }
  if (!collections.empty()) return fail(ErrorCode::kParse, "unterminated collection");
  return out;
}

namespace {

// The X/Y/Z fields of the first `collection` of the sensor page, all in one report with
// one unit and exponent; `what` names the sensor in messages.
Result<std::array<HidField, 3>> motionAxes(const HidDescriptor& d, std::uint16_t collection,
                                           const std::uint16_t (&usages)[3], const char* what) {
  std::array<HidField, 3> axis;
  bool found[3] = {false, false, false};
  for (const HidField& f : d.inputs) {
    if (f.collection_page != kSensorPage || f.collection_usage != collection) continue;
    if (f.usage_page != kSensorPage) continue;
    for (int a = 0; a < 3; ++a)
      if (f.usage == usages[a] && !found[a]) {
        axis[a] = f;
        found[a] = true;
      }
  }
  if (!found[0] || !found[1] || !found[2])
    return fail(ErrorCode::kNotFound, std::string("no ") + what + " X/Y/Z input fields");
  for (const HidField& f : axis)
    if (f.unit != axis[0].unit || f.unit_exponent != axis[0].unit_exponent ||
        f.report_id != axis[0].report_id)
      return fail(ErrorCode::kInvalidInput, std::string(what) + " axes differ in unit or report");
  return axis;
}

}  // namespace

Result<HidAccelFields> findAccelerometer(const HidDescriptor& d) {
  auto axis = motionAxes(d, kAccelerometer3D, kAccelAxes, "Accelerometer 3D");
  if (!axis) return tl::unexpected(axis.error());
  HidAccelFields out;
  std::copy(axis->begin(), axis->end(), out.axis);
  const HidField& x = out.axis[0];
  double unit_scale = 0;
  if (x.unit == 0 || x.unit == 0x1A)
    unit_scale = kStandardGravity;  // default unit: g
  else if (x.unit == 0xE011)
    unit_scale = 1;  // "m/s^2" of the HID sensor usage tables
  else
    return fail(ErrorCode::kInvalidInput, "unsupported acceleration unit");
  out.scale = unit_scale * std::pow(10.0, x.unit_exponent);
  return out;
}

Result<HidGyroFields> findGyrometer(const HidDescriptor& d) {
  auto axis = motionAxes(d, kGyrometer3D, kAngularVelocityAxes, "Gyrometer 3D");
  if (!axis) return tl::unexpected(axis.error());
  HidGyroFields out;
  std::copy(axis->begin(), axis->end(), out.axis);
  const HidField& x = out.axis[0];
  double unit_scale = 0;
  // Degrees per second: the default, the usage tables' code and the one Linux's HID
  // sensor drivers name (0x15); radians per second.
  if (x.unit == 0 || x.unit == 0xF014 || x.unit == 0x15)
    unit_scale = degToRad(1.0);
  else if (x.unit == 0xF012)
    unit_scale = 1;
  else
    return fail(ErrorCode::kInvalidInput, "unsupported angular velocity unit");
  out.scale = unit_scale * std::pow(10.0, x.unit_exponent);
  return out;
}

}  // namespace procam::tilt
