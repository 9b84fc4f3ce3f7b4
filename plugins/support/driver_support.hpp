#pragma once
// What every in-tree driver behind the plugin ABI (include/procamd/procam_plugin.h)
// needs on its side of the boundary: the mapping of procam::Error to the ABI's status
// codes, the reason written into the caller's (err, err_len) buffer, and the reading of
// device properties and configuration options. Nothing here throws.
#include <procamd/procam_plugin.h>

#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>

#include "core/error.hpp"

namespace procam::plugins {

// Writes `message` into the caller's buffer (truncated, always terminated) and returns
// `status`.
int report(char* err, std::size_t len, const std::string& message, int status);
// PROCAM_E* for an error: each device code of ErrorCode (kIo, kNoDevice, kTimeout, kAgain,
// kNotSupported, kEnded, kInternal) to its status, kNotFound -> ENODEV,
// kInvalidInput/kParse -> EINVAL, anything else -> EINTERNAL.
int statusOf(ErrorCode code);
// The ErrorCode of a PROCAM_E* status another driver returned (statusOf's inverse on
// the device codes and kInvalidInput); kInternal for an unknown status.
ErrorCode codeOf(int status);
// report() of an Error with its status.
int report(char* err, std::size_t len, const Error& error);

// A udev/config property of a device description, empty when absent.
std::string property(const procam_device_desc* d, const char* key);
bool startsWith(const char* text, const char* prefix);

// A driver's options from procam_config. `who` names the driver in every message
// ("i2c tilt", "headless output"); a bad value fails with kInvalidInput
// "<who>: option K: 'V' is not ...". The last occurrence of a key wins, as in a
// configuration file read top to bottom. Paths and names are text().
class DriverOptions {
 public:
  DriverOptions(std::string who, const procam_config* config);

  // kInvalidInput naming the first key not in `known` (and listing them).
  Result<void> onlyKnown(std::initializer_list<const char*> known) const;
  std::optional<std::string> text(const char* key) const;
  // Decimal or 0x-prefixed integer.
  Result<std::optional<long>> integer(const char* key) const;
  Result<std::optional<double>> number(const char* key) const;  // finite
  Result<std::optional<bool>> flag(const char* key) const;      // true/false/1/0/yes/no

  const std::string& who() const { return who_; }

 private:
  tl::unexpected<Error> bad(const char* key, const std::string& value, const char* what) const;
  std::string who_;
  const procam_config* config_;
};

}  // namespace procam::plugins
