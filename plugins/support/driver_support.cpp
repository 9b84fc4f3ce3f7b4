#include "support/driver_support.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

namespace procam::plugins {

int report(char* err, std::size_t len, const std::string& message, int status) {
  if (err && len > 0) std::snprintf(err, len, "%s", message.c_str());
  return status;
}

namespace {

// The device codes of ErrorCode and kInvalidInput, one status each, both ways.
constexpr std::pair<ErrorCode, int> kStatuses[] = {{ErrorCode::kInvalidInput, PROCAM_EINVAL},
                                                   {ErrorCode::kNoDevice, PROCAM_ENODEV},
                                                   {ErrorCode::kIo, PROCAM_EIO},
                                                   {ErrorCode::kTimeout, PROCAM_ETIMEDOUT},
                                                   {ErrorCode::kAgain, PROCAM_EAGAIN},
                                                   {ErrorCode::kNotSupported, PROCAM_ENOTSUP},
                                                   {ErrorCode::kEnded, PROCAM_EEND},
                                                   {ErrorCode::kInternal, PROCAM_EINTERNAL},
                                                   {ErrorCode::kCancelled, PROCAM_ECANCELED}};

}  // namespace

int statusOf(ErrorCode code) {
  if (code == ErrorCode::kNotFound) return PROCAM_ENODEV;
  if (code == ErrorCode::kParse) return PROCAM_EINVAL;
  for (const auto& [c, status] : kStatuses) {
    if (c == code) return status;
  }
  return PROCAM_EINTERNAL;
}

ErrorCode codeOf(int status) {
  for (const auto& [code, s] : kStatuses) {
    if (s == status) return code;
  }
  return ErrorCode::kInternal;
}

int report(char* err, std::size_t len, const Error& error) {
  return report(err, len, error.message, statusOf(error.code));
}

std::string property(const procam_device_desc* d, const char* key) {
  for (std::size_t i = 0; d && i < d->n_properties; ++i) {
    const procam_kv& kv = d->properties[i];
    if (kv.key && kv.value && std::strcmp(kv.key, key) == 0) return kv.value;
  }
  return {};
}

bool startsWith(const char* text, const char* prefix) {
  return text && std::strncmp(text, prefix, std::strlen(prefix)) == 0;
}

DriverOptions::DriverOptions(std::string who, const procam_config* config)
    : who_(std::move(who)), config_(config) {}

Result<void> DriverOptions::onlyKnown(std::initializer_list<const char*> known) const {
  for (std::size_t i = 0; config_ && i < config_->n_options; ++i) {
    const char* key = config_->options[i].key;
    bool ok = false;
    for (const char* k : known) ok = ok || (key && std::strcmp(key, k) == 0);
    if (ok) continue;
    std::string list;
    for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    return fail(ErrorCode::kInvalidInput,
                who_ + ": unknown option '" + (key ? key : "(null)") + "' (known: " + list + ")");
  }
  return {};
}

std::optional<std::string> DriverOptions::text(const char* key) const {
  std::optional<std::string> value;
  for (std::size_t i = 0; config_ && i < config_->n_options; ++i) {
    const procam_kv& kv = config_->options[i];
    if (kv.key && kv.value && std::strcmp(kv.key, key) == 0) value = kv.value;
  }
  return value;
}

tl::unexpected<Error> DriverOptions::bad(const char* key, const std::string& value,
                                         const char* what) const {
  return fail(ErrorCode::kInvalidInput,
              who_ + ": option " + key + ": '" + value + "' is not " + what);
}

Result<std::optional<long>> DriverOptions::integer(const char* key) const {
  const auto t = text(key);
  if (!t) return std::optional<long>();
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(t->c_str(), &end, 0);  // base 0: decimal or 0x hex
  if (t->empty() || *end != '\0' || errno == ERANGE) return bad(key, *t, "an integer");
  return std::optional<long>(v);
}

Result<std::optional<double>> DriverOptions::number(const char* key) const {
  const auto t = text(key);
  if (!t) return std::optional<double>();
  char* end = nullptr;
  const double v = std::strtod(t->c_str(), &end);
  if (t->empty() || *end != '\0' || !std::isfinite(v)) return bad(key, *t, "a number");
  return std::optional<double>(v);
}

Result<std::optional<bool>> DriverOptions::flag(const char* key) const {
  const auto t = text(key);
  if (!t) return std::optional<bool>();
  if (*t == "true" || *t == "1" || *t == "yes") return std::optional<bool>(true);
  if (*t == "false" || *t == "0" || *t == "no") return std::optional<bool>(false);
  return bad(key, *t, "true or false");
}

}  // namespace procam::plugins
