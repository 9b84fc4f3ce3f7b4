#include "config.hpp"

#include <fcntl.h>
#include <grp.h>
#include <sys/stat.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

namespace procam::daemon {

namespace {

class Checker {
 public:
  explicit Checker(const std::string& source) : source_(source) {}

  void error(const toml::source_region& where, const std::string& key, const std::string& what) {
    std::string line = source_ + ":" + std::to_string(where.begin.line) + ": ";
    if (!key.empty()) line += key + ": ";
    errors_.push_back(line + what);
  }
  bool ok() const { return errors_.empty(); }
  std::string joined() const {
    std::string all;
    for (const auto& e : errors_) all += (all.empty() ? "" : "\n") + e;
    return all;
  }

  // Reports every key of `table` not in `known`.
  void onlyKnown(const toml::table& table, const std::string& prefix,
                 std::initializer_list<std::string_view> known) {
    for (auto&& [key, value] : table) {
      bool found = false;
      for (auto k : known) found = found || key.str() == k;
      if (!found) {
        std::string expected;
        for (auto k : known) expected += (expected.empty() ? "" : ", ") + std::string(k);
        error(key.source(), prefix + std::string(key.str()),
              "unknown key (expected one of: " + expected + ")");
      }
    }
  }

  bool string(const toml::node& node, const std::string& key, std::string& out) {
    if (auto s = node.value<std::string>(); s && node.is_string()) {
      out = *s;
      return true;
    }
    error(node.source(), key, "expected a string");
    return false;
  }

  bool boolean(const toml::node& node, const std::string& key, bool& out) {
    if (!node.is_boolean()) {
      error(node.source(), key, "expected true or false");
      return false;
    }
    out = *node.value<bool>();
    return true;
  }

  bool integer(const toml::node& node, const std::string& key, int lo, int hi, int& out) {
    if (!node.is_integer()) {
      error(node.source(), key, "expected an integer");
      return false;
    }
    const int64_t v = node.as_integer()->get();
    if (v < lo || v > hi) {
      error(node.source(), key,
            std::to_string(v) + " is out of range [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "]");
      return false;
    }
    out = static_cast<int>(v);
    return true;
  }

  bool number(const toml::node& node, const std::string& key, double lo, double hi, double& out) {
    if (!node.is_number()) {
      error(node.source(), key, "expected a number");
      return false;
    }
    const double v = *node.value<double>();
    if (!(v >= lo && v <= hi)) {  // also rejects nan
      std::ostringstream msg;
      msg << v << " is out of range [" << lo << ", " << hi << "]";
      error(node.source(), key, msg.str());
      return false;
    }
    out = v;
    return true;
  }

 private:
  std::string source_;
  std::vector<std::string> errors_;
};

void parseDaemon(Checker& c, const toml::table& t, Config& cfg) {
  c.onlyKnown(t, "daemon.",
              {"log_level", "plugin_dir", "group", "max_clients", "client_queue_kib",
               "client_stall_timeout_s"});
  if (auto* n = t.get("log_level")) {
    std::string s;
    if (c.string(*n, "daemon.log_level", s)) {
      if (auto level = parseLogLevel(s)) {
        cfg.log_level = *level;
      } else {
        c.error(n->source(), "daemon.log_level", level.error().message);
      }
    }
  }
  if (auto* n = t.get("plugin_dir")) c.string(*n, "daemon.plugin_dir", cfg.plugin_dir);
  if (auto* n = t.get("group")) {
    if (c.string(*n, "daemon.group", cfg.group)) cfg.group_line = int(n->source().begin.line);
  }
  if (auto* n = t.get("max_clients")) c.integer(*n, "daemon.max_clients", 1, 4096, cfg.max_clients);
  if (auto* n = t.get("client_queue_kib")) {
    c.integer(*n, "daemon.client_queue_kib", 64, 65536, cfg.client_queue_kib);
  }
  if (auto* n = t.get("client_stall_timeout_s")) {
    c.number(*n, "daemon.client_stall_timeout_s", 0.1, 3600.0, cfg.client_stall_timeout_s);
  }
}

void parsePolicy(Checker& c, const toml::table& t, Config& cfg) {
  c.onlyKnown(
      t, "policy.",
      {"auto_keystone", "recalibrate", "drift_period_s", "drift_threshold_px", "drift_settle_s",
       "drift_frames", "drift_fiducial_period_s", "drift_stream_period_s"});
  if (auto* n = t.get("auto_keystone")) c.boolean(*n, "policy.auto_keystone", cfg.auto_keystone);
  if (auto* n = t.get("recalibrate")) {
    std::string s;
    if (c.string(*n, "policy.recalibrate", s)) {
      if (s == "off") {
        cfg.recalibrate = RecalibratePolicy::kOff;
      } else if (s == "on-drift") {
        cfg.recalibrate = RecalibratePolicy::kOnDrift;
      } else if (s == "on-drift-silent") {
        cfg.recalibrate = RecalibratePolicy::kOnDriftSilent;
      } else {
        c.error(n->source(), "policy.recalibrate",
                "'" + s + "' is not one of: off, on-drift, on-drift-silent");
      }
    }
  }
  if (auto* n = t.get("drift_period_s")) {
    c.number(*n, "policy.drift_period_s", 0.05, 60.0, cfg.drift.period_s);
  }
  if (auto* n = t.get("drift_threshold_px")) {
    c.number(*n, "policy.drift_threshold_px", 0.05, 50.0, cfg.drift.threshold_px);
  }
  if (auto* n = t.get("drift_settle_s")) {
    c.number(*n, "policy.drift_settle_s", 0.0, 60.0, cfg.drift.settle_s);
  }
  if (auto* n = t.get("drift_frames"))
    c.integer(*n, "policy.drift_frames", 1, 16, cfg.drift.frames);
  if (auto* n = t.get("drift_fiducial_period_s")) {
    c.number(*n, "policy.drift_fiducial_period_s", 0.0, 3600.0, cfg.drift.fiducial_period_s);
  }
  if (auto* n = t.get("drift_stream_period_s")) {
    c.number(*n, "policy.drift_stream_period_s", 0.0, 3600.0, cfg.drift.stream_period_s);
  }
}

void parseSim(Checker& c, const toml::table& t, Config& cfg) {
  c.onlyKnown(t, "sim.", {"scene"});
  if (auto* n = t.get("scene")) c.string(*n, "sim.scene", cfg.sim_scene);
}

// A TOML array of exactly N numbers inside [lo, hi].
template <size_t N>
bool numbers(Checker& c, const toml::node& node, const std::string& key, double lo, double hi,
             std::array<double, N>& out) {
  const toml::array* a = node.as_array();
  if (!a || a->size() != N) {
    c.error(node.source(), key, "expected an array of " + std::to_string(N) + " numbers");
    return false;
  }
  std::array<double, N> v{};
  for (size_t i = 0; i < N; ++i) {
    if (!c.number(*a->get(i), key + "[" + std::to_string(i) + "]", lo, hi, v[i])) return false;
  }
  out = v;
  return true;
}

void parseContent(Checker& c, const toml::table& t, Config& cfg) {
  c.onlyKnown(t, "content.",
              {"viewer", "viewer_threshold_m", "roots", "allow_pipeline", "projection",
               "dome_front", "dome_fov_deg"});
  if (auto* n = t.get("projection")) {
    std::string s;
    if (c.string(*n, "content.projection", s)) {
      if (s == "perspective" || s == "dome") {
        cfg.content_dome = s == "dome";
      } else {
        c.error(n->source(), "content.projection", "'" + s + "' is not one of: perspective, dome");
      }
    }
  }
  if (auto* n = t.get("dome_fov_deg")) {
    c.number(*n, "content.dome_fov_deg", 1.0, 360.0, cfg.content_dome_fov_deg);
  }
  std::array<double, 3> front{};
  if (auto* n = t.get("dome_front"); n && numbers(c, *n, "content.dome_front", -1e4, 1e4, front)) {
    if (std::hypot(front[0], front[1]) < 1e-6 * std::max(1.0, std::abs(front[2]))) {
      c.error(n->source(), "content.dome_front", "must point away from the vertical");
    } else {
      cfg.content_dome_front = front;
    }
  }
  if (auto* n = t.get("allow_pipeline")) {
    c.boolean(*n, "content.allow_pipeline", cfg.content_allow_pipeline);
  }
  if (auto* n = t.get("roots")) {
    const toml::array* a = n->as_array();
    if (!a || a->empty() || a->size() > 64) {
      c.error(n->source(), "content.roots", "expected an array of 1 to 64 absolute folder paths");
    } else {
      for (std::size_t i = 0; i < a->size(); ++i) {
        const std::string key = "content.roots[" + std::to_string(i) + "]";
        std::string dir;
        if (!c.string(*a->get(i), key, dir)) continue;
        if (dir.empty() || dir.front() != '/') {
          c.error(a->get(i)->source(), key, "'" + dir + "' is not an absolute path");
          continue;
        }
        cfg.content_roots.push_back(dir);
      }
    }
  }
  if (auto* n = t.get("viewer_threshold_m")) {
    c.number(*n, "content.viewer_threshold_m", 0.0, 1.0, cfg.content_viewer_threshold_m);
  }
  std::array<double, 3> eye{};
  if (auto* n = t.get("viewer"); n && numbers(c, *n, "content.viewer", -1e4, 1e4, eye)) {
    cfg.content_viewer = eye;
  }
}

void parseLimits(Checker& c, const toml::table& t, Config& cfg) {
  c.onlyKnown(t, "limits.",
              {"file_mib", "image_pixels", "frame_pixels", "mesh_vertices", "mesh_faces",
               "face_indices", "client_jobs"});
  ContentLimits& l = cfg.limits;
  auto bounded = [&](const char* key, int lo, int hi, std::uint64_t& out, std::uint64_t scale) {
    if (auto* n = t.get(key)) {
      int v = 0;
      if (c.integer(*n, std::string("limits.") + key, lo, hi, v)) out = std::uint64_t(v) * scale;
    }
  };
  bounded("file_mib", 1, 4096, l.file_bytes, std::uint64_t{1} << 20);
  bounded("image_pixels", 4, 1 << 30, l.image_pixels, 1);
  bounded("frame_pixels", 4, 1 << 30, l.frame_pixels, 1);
  bounded("mesh_vertices", 3, 100'000'000, l.mesh_vertices, 1);
  bounded("mesh_faces", 1, 100'000'000, l.mesh_faces, 1);
  bounded("face_indices", 3, 1'000'000, l.face_indices, 1);
  bounded("client_jobs", 1, 100'000, l.client_jobs, 1);
}

void parseKeystone(Checker& c, const toml::table& t, Config& cfg) {
  c.onlyKnown(t, "keystone.",
              {"cutoff_hz", "hysteresis_deg", "poll_hz", "mount", "accel_offset_g", "accel_scale",
               "display_centre", "display_size", "camera_yaw", "yaw_frames"});
  KeystoneConfig& k = cfg.keystone;
  if (auto* n = t.get("cutoff_hz")) c.number(*n, "keystone.cutoff_hz", 0.01, 1000.0, k.cutoff_hz);
  if (auto* n = t.get("hysteresis_deg")) {
    c.number(*n, "keystone.hysteresis_deg", 0.0, 10.0, k.hysteresis_deg);
  }
  if (auto* n = t.get("poll_hz")) c.number(*n, "keystone.poll_hz", 1.0, 1000.0, k.poll_hz);
  if (auto* n = t.get("camera_yaw")) c.boolean(*n, "keystone.camera_yaw", k.camera_yaw);
  if (auto* n = t.get("yaw_frames")) c.integer(*n, "keystone.yaw_frames", 1, 256, k.yaw_frames);
  if (auto* n = t.get("mount")) {
    std::array<double, 9> m{};
    if (numbers(c, *n, "keystone.mount", -1.0, 1.0, m)) k.mount = m;
  }
  if (auto* n = t.get("accel_offset_g")) {
    numbers(c, *n, "keystone.accel_offset_g", -1.0, 1.0, k.accel_offset_g);
  }
  if (auto* n = t.get("accel_scale"))
    numbers(c, *n, "keystone.accel_scale", 0.5, 2.0, k.accel_scale);
  if (auto* n = t.get("display_centre")) {
    std::array<double, 3> v{};
    if (numbers(c, *n, "keystone.display_centre", -1e4, 1e4, v)) k.display_centre = v;
  }
  if (auto* n = t.get("display_size")) {
    std::array<double, 2> v{};
    if (numbers(c, *n, "keystone.display_size", 1e-3, 1e4, v)) k.display_size = v;
  }
  // One without the other says nothing about the rectangle.
  const toml::node* centre = t.get("display_centre");
  const toml::node* size = t.get("display_size");
  if ((centre == nullptr) != (size == nullptr)) {
    const toml::node& given = centre ? *centre : *size;
    c.error(given.source(), centre ? "keystone.display_centre" : "keystone.display_size",
            "display_centre and display_size go together");
  }
}

void parseCalibration(Checker& c, const toml::table& t, Config& cfg) {
  c.onlyKnown(t, "calibration.",
              {"settle_frames", "margin_frames", "latency_repeats", "latency_timeout_s"});
  CalibrationConfig& k = cfg.calibration;
  if (auto* n = t.get("settle_frames")) {
    if (n->is_string() && *n->value<std::string>() == "auto") {
      k.auto_settle = true;
    } else if (!n->is_integer()) {
      c.error(n->source(), "calibration.settle_frames", "expected an integer or \"auto\"");
    } else {
      c.integer(*n, "calibration.settle_frames", 0, 600, k.settle_frames);
    }
  }
  if (auto* n = t.get("margin_frames")) {
    c.integer(*n, "calibration.margin_frames", 0, 60, k.margin_frames);
  }
  if (auto* n = t.get("latency_repeats")) {
    c.integer(*n, "calibration.latency_repeats", 1, 20, k.latency_repeats);
  }
  if (auto* n = t.get("latency_timeout_s")) {
    c.number(*n, "calibration.latency_timeout_s", 0.05, 10.0, k.latency_timeout_s);
  }
}

void parseDevices(Checker& c, const toml::node& node, const std::string& section,
                  procam_family family, Config& cfg, std::set<std::string>& names) {
  const toml::array* list = node.as_array();
  if (!list) {
    c.error(node.source(), section, "expected an array of tables ([[" + section + "]])");
    return;
  }
  for (size_t i = 0; i < list->size(); ++i) {
    const toml::node& item = *list->get(i);
    const std::string key = section + "[" + std::to_string(i) + "]";
    const toml::table* t = item.as_table();
    if (!t) {
      c.error(item.source(), key, "expected a table");
      continue;
    }
    c.onlyKnown(*t, key + ".", {"name", "driver", "devnode", "options"});
    DeviceConfig dev;
    dev.family = family;
    dev.line = static_cast<int>(t->source().begin.line);
    if (auto* n = t->get("name")) {
      if (c.string(*n, key + ".name", dev.name)) {
        if (dev.name.empty()) c.error(n->source(), key + ".name", "must not be empty");
        if (!names.insert(dev.name).second) {
          c.error(n->source(), key + ".name", "duplicate device name '" + dev.name + "'");
        }
      }
    } else {
      c.error(t->source(), key + ".name", "missing (every device needs a unique name)");
    }
    if (auto* n = t->get("driver")) {
      c.string(*n, key + ".driver", dev.driver);
      dev.driver_line = static_cast<int>(n->source().begin.line);
    }
    if (auto* n = t->get("devnode")) c.string(*n, key + ".devnode", dev.devnode);
    if (auto* n = t->get("options")) {
      if (const toml::table* opts = n->as_table()) {
        for (auto&& [k, v] : *opts) {
          const std::string okey = key + ".options." + std::string(k.str());
          if (v.is_string()) {
            dev.options.emplace_back(std::string(k.str()), *v.value<std::string>());
          } else if (v.is_integer()) {
            dev.options.emplace_back(std::string(k.str()), std::to_string(v.as_integer()->get()));
          } else if (v.is_floating_point()) {
            std::ostringstream text;
            text.precision(17);
            text << v.as_floating_point()->get();
            dev.options.emplace_back(std::string(k.str()), text.str());
          } else if (v.is_boolean()) {
            dev.options.emplace_back(std::string(k.str()), *v.value<bool>() ? "true" : "false");
          } else {
            c.error(v.source(), okey, "expected a string, number or boolean");
          }
        }
      } else {
        c.error(n->source(), key + ".options", "expected a table");
      }
    }
    cfg.devices.push_back(std::move(dev));
  }
}

}  // namespace

const char* recalibratePolicyName(RecalibratePolicy policy) {
  switch (policy) {
    case RecalibratePolicy::kOnDrift:
      return "on-drift";
    case RecalibratePolicy::kOnDriftSilent:
      return "on-drift-silent";
    case RecalibratePolicy::kOff:
      break;
  }
  return "off";
}

Result<Config> parseConfig(std::string_view text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    return fail(ErrorCode::kParse, source + ":" + std::to_string(e.source().begin.line) + ":" +
                                       std::to_string(e.source().begin.column) + ": " +
                                       std::string(e.description()));
  }
  Config cfg;
  cfg.source = source;
  Checker c(source);
  c.onlyKnown(root, "",
              {"daemon", "policy", "keystone", "calibration", "content", "limits", "sim",
               "projector", "camera", "tilt", "tracker"});
  auto section = [&](const char* name, void (*parse)(Checker&, const toml::table&, Config&)) {
    if (auto* n = root.get(name)) {
      if (const toml::table* t = n->as_table()) {
        parse(c, *t, cfg);
      } else {
        c.error(n->source(), name, "expected a table ([" + std::string(name) + "])");
      }
    }
  };
  section("daemon", parseDaemon);
  section("policy", parsePolicy);
  section("sim", parseSim);
  section("keystone", parseKeystone);
  section("calibration", parseCalibration);
  section("content", parseContent);
  section("limits", parseLimits);
  std::set<std::string> names;
  const std::pair<const char*, procam_family> families[] = {{"projector", PROCAM_FAMILY_OUTPUT},
                                                            {"camera", PROCAM_FAMILY_CAMERA},
                                                            {"tilt", PROCAM_FAMILY_TILT},
                                                            {"tracker", PROCAM_FAMILY_TRACKER}};
  for (const auto& [name, family] : families) {
    if (auto* n = root.get(name)) parseDevices(c, *n, name, family, cfg, names);
  }
  if (!c.ok()) return fail(ErrorCode::kInvalidInput, c.joined());
  return cfg;
}

Result<Config> loadConfig(const std::string& path) {
  // Non-blocking open: a FIFO must not hang start-up or the loop on reload.
  UniqueFd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (!fd.valid()) {
    return fail(ErrorCode::kIo, "cannot open config file " + path + ": " + std::strerror(errno));
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0 || !S_ISREG(st.st_mode)) {
    return fail(ErrorCode::kIo, "config file " + path + " is not a regular file");
  }
  if (std::uint64_t(st.st_size) > kMaxConfigBytes) {
    return fail(ErrorCode::kTooLarge, "config file " + path + " is over " +
                                          std::to_string(kMaxConfigBytes >> 10) + " KiB");
  }
  std::string text(std::size_t(st.st_size), '\0');
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::read(fd.get(), text.data() + done, text.size() - done);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) return fail(ErrorCode::kIo, "cannot read config file " + path);
    if (n == 0) break;
    done += std::size_t(n);
  }
  text.resize(done);
  auto cfg = parseConfig(text, path);
  if (!cfg) return cfg;
  if (cfg->group_line > 0) {
    // A group named in the file must exist; the default may be absent (no group
    // then shares the socket).
    struct group g {};
    struct group* found = nullptr;
    std::vector<char> buf(16384);
    int rc = 0;
    // A group with many members (a directory service) needs a larger buffer.
    while ((rc = ::getgrnam_r(cfg->group.c_str(), &g, buf.data(), buf.size(), &found)) == ERANGE &&
           buf.size() < (std::size_t{1} << 24)) {
      buf.resize(buf.size() * 2);
    }
    const std::string where = path + ":" + std::to_string(cfg->group_line) + ": daemon.group: ";
    if (rc != 0) {
      return fail(ErrorCode::kIo,
                  where + "cannot look up group '" + cfg->group + "': " + std::strerror(rc));
    }
    if (!found) {
      return fail(ErrorCode::kInvalidInput, where + "no group '" + cfg->group + "' on this system");
    }
  }
  return cfg;
}

}  // namespace procam::daemon
