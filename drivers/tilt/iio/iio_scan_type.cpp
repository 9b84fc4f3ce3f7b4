#include "tilt/iio/iio_scan_type.hpp"

#include <algorithm>
#include <cstdio>

namespace procam::tilt {

Result<IioScanType> parseIioScanType(const std::string& text) {
  IioScanType t;
  char endian[3] = {}, sign = 0;
  int used = 0;
  if (std::sscanf(text.c_str(), "%2[bl]e:%c%d/%d%n", endian, &sign, &t.bits, &t.storage_bits,
                  &used) != 4)
    return fail(ErrorCode::kParse, "bad IIO scan type '" + text + "'");
  std::string rest = text.substr(std::size_t(used));
  if (!rest.empty() && rest[0] == 'X') {
    int n = 0;
    if (std::sscanf(rest.c_str(), "X%d%n", &t.repeat, &n) != 1)
      return fail(ErrorCode::kParse, "bad IIO repeat in '" + text + "'");
    rest = rest.substr(std::size_t(n));
  }
  while (!rest.empty() && (rest.back() == '\n' || rest.back() == ' ')) rest.pop_back();
  if (std::sscanf(rest.c_str(), ">>%d", &t.shift) != 1)
    return fail(ErrorCode::kParse, "bad IIO shift in '" + text + "'");
  t.big_endian = endian[0] == 'b';
  if (sign != 's' && sign != 'u') return fail(ErrorCode::kParse, "bad IIO sign in '" + text + "'");
  t.is_signed = sign == 's';
  const bool storage_ok =
      t.storage_bits == 8 || t.storage_bits == 16 || t.storage_bits == 32 || t.storage_bits == 64;
  if (!storage_ok || t.bits < 1 || t.bits > t.storage_bits || t.shift < 0 ||
      t.shift + t.bits > t.storage_bits || t.repeat < 1)
    return fail(ErrorCode::kParse, "inconsistent IIO scan type '" + text + "'");
  return t;
}

std::int64_t IioScanType::decode(const std::uint8_t* p) const {
  const int bytes = storage_bits / 8;
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) {
    const int byte = big_endian ? i : bytes - 1 - i;
    v = (v << 8) | p[byte];
  }
  v >>= shift;
  if (bits < 64) {
    const std::uint64_t mask = (std::uint64_t(1) << bits) - 1;
    v &= mask;
    if (is_signed && (v >> (bits - 1)) & 1) v |= ~mask;  // sign-extend
  }
  return std::int64_t(v);
}

std::size_t layoutIioRecord(std::vector<IioScanChannel>& channels) {
  std::sort(channels.begin(), channels.end(),
            [](const IioScanChannel& a, const IioScanChannel& b) { return a.index < b.index; });
  std::size_t offset = 0, largest = 1;
  for (auto& c : channels) {
    const std::size_t size = std::size_t(c.type.storage_bits / 8);
    offset = (offset + size - 1) / size * size;
    c.offset = offset;
    offset += size * std::size_t(c.type.repeat);
    largest = std::max(largest, size);
  }
  return (offset + largest - 1) / largest * largest;
}

}  // namespace procam::tilt
