#include "tracker/plugin/led_tracker_options.hpp"

#include <cmath>
#include <cstdlib>
#include <vector>

namespace procam::tracker::plugin {
namespace {

tl::unexpected<Error> bad(const plugins::DriverOptions& o, const char* key,
                          const std::string& why) {
  return fail(ErrorCode::kInvalidInput, o.who() + ": option " + key + ": " + why);
}

// Finite numbers separated by `sep`.
std::optional<std::vector<double>> numbers(const std::string& text, char sep) {
  std::vector<double> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(sep, start), text.size());
    const std::string item = text.substr(start, end - start);
    char* stop = nullptr;
    const double v = std::strtod(item.c_str(), &stop);
    while (stop && (*stop == ' ' || *stop == '\t')) ++stop;
    if (item.find_first_not_of(" \t") == std::string::npos || *stop != '\0' || !std::isfinite(v))
      return std::nullopt;
    out.push_back(v);
    start = end + 1;
  }
  return out;
}

// An OpenCV rotation vector (axis * angle, radians) as a rotation matrix.
Mat3 rodrigues(const Vec3& r) {
  const double angle = r.norm();
  if (angle == 0) return Mat3::Identity();
  return Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
}

// Sets `out` from the option when present.
Result<void> number(const plugins::DriverOptions& o, const char* key, double& out) {
  auto v = o.number(key);
  if (!v) return tl::unexpected(v.error());
  if (*v) out = **v;
  return {};
}

}  // namespace

Result<Vec3> vec3Option(const plugins::DriverOptions& o, const char* key, const std::string& text) {
  auto v = numbers(text, ',');
  if (!v || v->size() != 3) return bad(o, key, "'" + text + "' is not x,y,z");
  return Vec3((*v)[0], (*v)[1], (*v)[2]);
}

Result<Points3> pointsOption(const plugins::DriverOptions& o, const char* key,
                             const std::string& text) {
  Points3 points;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    auto p = vec3Option(o, key, text.substr(start, end - start));
    if (!p) return bad(o, key, "'" + text + "' is not x,y,z;x,y,z;... (metres)");
    points.push_back(*p);
    start = end + 1;
  }
  return points;
}

Result<geom::CameraModel> trackerCamera(const plugins::DriverOptions& o) {
  geom::CameraModel c;
  for (const char* key : {"fx", "fy", "cx", "cy"})
    if (!o.text(key))
      return fail(ErrorCode::kInvalidInput,
                  o.who() + ": the camera's intrinsics are needed: option " + key + " (pixels)");
  double* intrinsics[] = {&c.K.fx, &c.K.fy, &c.K.cx, &c.K.cy};
  const char* keys[] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i)
    if (auto ok = number(o, keys[i], *intrinsics[i]); !ok) return tl::unexpected(ok.error());
  if (!(c.K.fx > 0)) return bad(o, "fx", "must be > 0");
  if (!(c.K.fy > 0)) return bad(o, "fy", "must be > 0");
  double* dist[] = {&c.dist.k1, &c.dist.k2, &c.dist.p1, &c.dist.p2, &c.dist.k3};
  const char* dist_keys[] = {"k1", "k2", "p1", "p2", "k3"};
  for (int i = 0; i < 5; ++i)
    if (auto ok = number(o, dist_keys[i], *dist[i]); !ok) return tl::unexpected(ok.error());

  Vec3 centre = Vec3::Zero();
  if (auto t = o.text("camera_position")) {
    auto v = vec3Option(o, "camera_position", *t);
    if (!v) return tl::unexpected(v.error());
    centre = *v;
  }
  const auto rvec = o.text("camera_rvec");
  const auto look_at = o.text("camera_look_at");
  if (rvec && look_at)
    return fail(ErrorCode::kInvalidInput,
                o.who() + ": give camera_rvec or camera_look_at, not both");
  if (!look_at && o.text("camera_up"))
    return fail(ErrorCode::kInvalidInput, o.who() + ": camera_up needs camera_look_at");
  if (rvec) {
    auto r = vec3Option(o, "camera_rvec", *rvec);
    if (!r) return tl::unexpected(r.error());
    c.pose.R = rodrigues(*r);
    c.pose.t = -c.pose.R * centre;
  } else if (look_at) {
    auto target = vec3Option(o, "camera_look_at", *look_at);
    if (!target) return tl::unexpected(target.error());
    Vec3 up(0, 0, 1);
    if (auto u = o.text("camera_up")) {
      auto v = vec3Option(o, "camera_up", *u);
      if (!v) return tl::unexpected(v.error());
      up = *v;
    }
    if ((*target - centre).norm() == 0) return bad(o, "camera_look_at", "is the camera's position");
    c.pose = geom::Pose::lookAt(centre, *target, up);
  } else {
    c.pose.t = -centre;
  }
  return c;
}

Result<tracking::LedTrackerOptions> ledTrackerOptions(const plugins::DriverOptions& o) {
  tracking::LedTrackerOptions t;
  const auto leds = o.text("leds");
  if (!leds)
    return fail(ErrorCode::kInvalidInput,
                o.who() +
                    ": the LED layout is needed: option leds = \"x,y,z;x,y,z;...\" (m, "
                    ">= 4 LEDs)");
  auto points = pointsOption(o, "leds", *leds);
  if (!points) return tl::unexpected(points.error());
  if (points->size() < 4) return bad(o, "leds", "at least 4 LEDs are needed");
  t.leds = std::move(*points);

  for (auto [key, value] :
       {std::pair{"max_reprojection_px", &t.pose.max_reprojection_px},
        std::pair{"pixel_sigma", &t.pose.pixel_sigma},
        std::pair{"min_cutoff_hz", &t.filter.one_euro.min_cutoff_hz},
        std::pair{"beta", &t.filter.one_euro.beta},
        std::pair{"derivative_cutoff_hz", &t.filter.one_euro.derivative_cutoff_hz},
        std::pair{"accel_noise", &t.filter.kalman.accel_noise},
        std::pair{"measurement_sigma", &t.filter.kalman.measurement_sigma},
        std::pair{"prediction_s", &t.filter.prediction_s}})
    if (auto ok = number(o, key, *value); !ok) return tl::unexpected(ok.error());
  if (!(t.pose.max_reprojection_px > 0)) return bad(o, "max_reprojection_px", "must be > 0");
  if (!(t.pose.pixel_sigma > 0)) return bad(o, "pixel_sigma", "must be > 0");
  auto min_leds = o.integer("min_leds");
  if (!min_leds) return tl::unexpected(min_leds.error());
  if (*min_leds) {
    if (**min_leds < 4 || **min_leds > static_cast<long>(t.leds.size()))
      return bad(o, "min_leds", "must be 4..the number of LEDs");
    t.pose.min_leds = static_cast<int>(**min_leds);
  }
  if (const auto kind = o.text("filter")) {
    if (*kind == "one_euro")
      t.filter.kind = tracking::FilterKind::kOneEuro;
    else if (*kind == "kalman")
      t.filter.kind = tracking::FilterKind::kKalman;
    else
      return bad(o, "filter", "'" + *kind + "' is not one_euro or kalman");
  }
  if (!(t.filter.prediction_s >= 0)) return bad(o, "prediction_s", "must be >= 0");
  if (!tracking::MotionFilter::create(t.filter))
    return fail(ErrorCode::kInvalidInput,
                o.who() +
                    ": filter parameters must be positive (min_cutoff_hz, "
                    "derivative_cutoff_hz, accel_noise, measurement_sigma; beta >= 0)");

  const auto rvec = o.text("to_world_rvec");
  const auto tvec = o.text("to_world_t");
  const auto scale = o.text("to_world_scale");
  if (rvec || tvec || scale) {
    tracking::TrackerRegistration reg;
    if (rvec) {
      auto r = vec3Option(o, "to_world_rvec", *rvec);
      if (!r) return tl::unexpected(r.error());
      reg.tracker_to_world.R = rodrigues(*r);
    }
    if (tvec) {
      auto v = vec3Option(o, "to_world_t", *tvec);
      if (!v) return tl::unexpected(v.error());
      reg.tracker_to_world.t = *v;
    }
    if (auto ok = number(o, "to_world_scale", reg.scale); !ok) return tl::unexpected(ok.error());
    if (!(reg.scale > 0)) return bad(o, "to_world_scale", "must be > 0");
    t.to_world = reg;
  }
  return t;
}

}  // namespace procam::tracker::plugin
