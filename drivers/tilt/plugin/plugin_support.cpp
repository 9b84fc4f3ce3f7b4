#include "tilt/plugin/plugin_support.hpp"

#include <exception>

namespace procam::tilt::plugin {

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
                who() +
                    ": need gate_range_g > 0, 0 <= min_norm_g < max_norm_g and "
                    "stuck_limit >= 0");
  return g;
}

namespace {

struct TiltDevice {
  std::unique_ptr<TiltSensor> sensor;
  SampleGate gate;
  std::optional<procam_rate_sample> rate;  // with the sample read() last returned
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
        return report(err, len, "sample rejected: " + e.message, PROCAM_EAGAIN);
      }
      return report(err, len, e.message, statusOf(e.code));
    }
    auto checked = d->gate.check(*s);
    if (!checked)
      return report(err, len, "sample rejected: " + checked.error().message, PROCAM_EAGAIN);
    for (int a = 0; a < 3; ++a) out->specific_force[a] = checked->specific_force(a);
    out->timestamp_ns = checked->timestamp_ns;
    d->rate.reset();
    if (s->angular_velocity && s->angular_velocity->allFinite()) {
      procam_rate_sample r{};
      for (int a = 0; a < 3; ++a) r.angular_velocity[a] = (*s->angular_velocity)(a);
      r.timestamp_ns = checked->timestamp_ns;
      d->rate = r;
    }
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

int getCounts(void* self, procam_tilt_counts* out) {
  const SampleCounts& c = static_cast<const TiltDevice*>(self)->gate.counts();
  *out = {c.accepted, c.not_finite, c.out_of_range, c.stuck, c.bad_norm};
  return PROCAM_OK;
}

int readRate(void* self, procam_rate_sample* out, char* err, std::size_t len) {
  const auto* d = static_cast<const TiltDevice*>(self);
  if (!d->rate) return report(err, len, "no gyroscope reading with this sample", PROCAM_ENOTSUP);
  *out = *d->rate;
  return PROCAM_OK;
}

int pollFd(void* self) {
  return static_cast<TiltDevice*>(self)->sensor->pollFd();
}

void destroy(void* self) {
  delete static_cast<TiltDevice*>(self);  // the sensor's destructor closes it
}

const procam_tilt_ops kOps = {PROCAM_TILT_OPS_VERSION, &readSample, &getCounts, &readRate};

}  // namespace

int finishTiltDevice(std::unique_ptr<TiltSensor> sensor, const SampleGateOptions& gate,
                     procam_device* out, char* err, std::size_t len) {
  try {
    if (auto ok = sensor->open(); !ok)
      return report(err, len, sensor->name() + " tilt: " + ok.error().message,
                    statusOf(ok.error().code));
    auto d =
        std::make_unique<TiltDevice>(TiltDevice{std::move(sensor), SampleGate(gate), std::nullopt});
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

}  // namespace procam::tilt::plugin
