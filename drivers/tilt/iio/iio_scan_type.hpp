#pragma once
// IIO buffer element format ("scan_elements/in_<ch>_type", kernel ABI
// sysfs-bus-iio): "[be|le]:[s|u]bits/storagebits[Xrepeat]>>shift", and the packed
// record layout of the enabled channels (each element aligned to its storage size).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace procam::tilt {

struct IioScanType {
  bool big_endian = false;
  bool is_signed = false;
  int bits = 0;          // valid bits
  int storage_bits = 0;  // 8, 16, 32 or 64
  int repeat = 1;
  int shift = 0;

  // Decodes one element (storage_bits / 8 bytes).
  std::int64_t decode(const std::uint8_t* p) const;
};

Result<IioScanType> parseIioScanType(const std::string& text);

struct IioScanChannel {
  std::string name;  // e.g. "accel_x", "timestamp"
  int index = 0;
  IioScanType type;
  std::size_t offset = 0;  // byte offset in the record, filled by layoutIioRecord
};

// Sorts by index, assigns offsets; returns the record size in bytes.
std::size_t layoutIioRecord(std::vector<IioScanChannel>& channels);

}  // namespace procam::tilt
