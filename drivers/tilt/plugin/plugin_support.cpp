#include "tilt/plugin/plugin_support.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>

namespace procam::tilt::plugin {

int report(char* err, std::size_t len, const std::string& message, int status) {
  if (err && len > 0) std::snprintf(err, len, "%s", message.c_str());
  return status;
}

int statusOf(ErrorCode code) {
  switch (code) {
    case ErrorCode::kNotFound:
      return PROCAM_ENODEV;
    case ErrorCode::kInvalidInput:
    case ErrorCode::kParse:
      return PROCAM_EINVAL;
    case ErrorCode::kIo:
      return PROCAM_EIO;
    default:
      return PROCAM_EINTERNAL;
  }
}

int report(char* err, std::size_t len, const Error& error) {
  return report(err, len, error.message, statusOf(error.code));
}

PluginOptions::PluginOptions(std::string driver, const procam_config* config)
    : driver_(std::move(driver)), config_(config) {}

Result<void> PluginOptions::onlyKnown(std::initializer_list<const char*> known) const {
  for (std::size_t i = 0; config_ && i < config_->n_options; ++i) {
    const char* key = config_->options[i].key;
    bool ok = false;
    for (const char* k : known) ok = ok || (key && std::strcmp(key, k) == 0);
    if (ok) continue;
    std::string list;
    for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    return fail(ErrorCode::kInvalidInput, driver_ + " tilt: unknown option '" +
                                              (key ? key : "(null)") + "' (known: " + list + ")");
  }
  return {};
}

std::optional<std::string> PluginOptions::text(const char* key) const {
  // The last occurrence wins, as in a configuration file read top to bottom.
  std::optional<std::string> value;
  for (std::size_t i = 0; config_ && i < config_->n_options; ++i) {
    const procam_kv& kv = config_->options[i];
    if (kv.key && kv.value && std::strcmp(kv.key, key) == 0) value = kv.value;
  }
  return value;
}

Result<std::optional<long>> PluginOptions::integer(const char* key) const {
  const auto t = text(key);
  if (!t) return std::optional<long>();
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(t->c_str(), &end, 0);  // base 0: decimal or 0x hex
  if (t->empty() || *end != '\0' || errno == ERANGE)
    return fail(ErrorCode::kInvalidInput,
                driver_ + " tilt: option " + key + ": '" + *t + "' is not an integer");
  return std::optional<long>(v);
}

Result<std::optional<double>> PluginOptions::number(const char* key) const {
  const auto t = text(key);
  if (!t) return std::optional<double>();
  char* end = nullptr;
  const double v = std::strtod(t->c_str(), &end);
  if (t->empty() || *end != '\0' || !std::isfinite(v))
    return fail(ErrorCode::kInvalidInput,
                driver_ + " tilt: option " + key + ": '" + *t + "' is not a number");
  return std::optional<double>(v);
}

Result<std::optional<bool>> PluginOptions::flag(const char* key) const {
  const auto t = text(key);
  if (!t) return std::optional<bool>();
  if (*t == "true" || *t == "1" || *t == "yes") return std::optional<bool>(true);
  if (*t == "false" || *t == "0" || *t == "no") return std::optional<bool>(false);
  return fail(ErrorCode::kInvalidInput,
              driver_ + " tilt: option " + key + ": '" + *t + "' is not true or false");
}

Result<SampleGateOptions> PluginOptions::gate(SampleGateOptions g) const {
  auto range = number("gate_range_g");
  auto lo = number("min_norm_g");
  auto hi = number("max_norm_g");
  auto stuck = integer("stuck_limit");
  for (const auto* r : {&range, &lo, &hi})
    if (!*r) return tl::unexpected(r->error());
  if (!stuck) return tl::unexpected(stuck.error());
  g.range_g = range->value_or(g.range_g);
  g.min_norm_g = lo->value_or(g.min_norm_g);
  g.max_norm_g = hi->value_or(g.max_norm_g);
  g.stuck_limit = int(stuck->value_or(g.stuck_limit));
  if (!(g.range_g > 0) || !(g.min_norm_g >= 0) || !(g.max_norm_g > g.min_norm_g) ||
      g.stuck_limit < 0)
    return fail(ErrorCode::kInvalidInput,
                driver_ +
                    " tilt: need gate_range_g > 0, 0 <= min_norm_g < max_norm_g and "
                    "stuck_limit >= 0");
  return g;
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

namespace {

struct TiltDevice {
  std::unique_ptr<TiltSensor> sensor;
  SampleGate gate;
};

int readSample(void* self, procam_tilt_sample* out, char* err, std::size_t len) {
  try {
    auto* d = static_cast<TiltDevice*>(self);
    auto s = d->sensor->read();
    if (!s) {
      const Error& e = s.error();
      if (e.code == ErrorCode::kNotFound) return report(err, len, e.message, PROCAM_EAGAIN);
      // A reading the driver refused (outside the device's range, not a number) is a
      // garbage sample like those the gate rejects.
      if (e.code == ErrorCode::kInvalidInput || e.code == ErrorCode::kParse) {
        if (e.code == ErrorCode::kParse)
          d->gate.countNotFinite();
        else
          d->gate.countOutOfRange();
        return report(err, len, PROCAM_TILT_REJECTED_PREFIX + e.message, PROCAM_EAGAIN);
      }
      return report(err, len, e.message, statusOf(e.code));
    }
    auto checked = d->gate.check(*s);
    if (!checked)
      return report(err, len, PROCAM_TILT_REJECTED_PREFIX + checked.error().message, PROCAM_EAGAIN);
    for (int a = 0; a < 3; ++a) out->specific_force[a] = checked->specific_force(a);
    out->timestamp_ns = checked->timestamp_ns;
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

int pollFd(void* self) {
  return static_cast<TiltDevice*>(self)->sensor->pollFd();
}

void destroy(void* self) {
  delete static_cast<TiltDevice*>(self);  // the sensor's destructor closes it
}

const procam_tilt_ops kOps = {&readSample};

}  // namespace

int finishTiltDevice(std::unique_ptr<TiltSensor> sensor, const SampleGateOptions& gate,
                     procam_device* out, char* err, std::size_t len) {
  try {
    if (auto ok = sensor->open(); !ok)
      return report(err, len, sensor->name() + " tilt: " + ok.error().message,
                    statusOf(ok.error().code));
    auto d = std::make_unique<TiltDevice>(TiltDevice{std::move(sensor), SampleGate(gate)});
    out->family = PROCAM_FAMILY_TILT;
    out->self = d.release();
    out->poll_fd = &pollFd;
    out->destroy = &destroy;
    out->ops.tilt = &kOps;
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

const SampleCounts& tiltDeviceCounts(const procam_device& device) {
  return static_cast<const TiltDevice*>(device.self)->gate.counts();
}

}  // namespace procam::tilt::plugin
