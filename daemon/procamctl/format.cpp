#include "format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace procam::ctl {

using nlohmann::json;

namespace {

// j[key] as T, or `fallback` when j is not an object, lacks the key or holds another type
// (a procamd of another version): unlike json::value, never throws.
template <class T>
T val(const json& j, const char* key, T fallback) {
  if (!j.is_object()) return fallback;
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  try {
    return it->get<T>();
  } catch (const json::exception&) {
    return fallback;
  }
}

std::string val(const json& j, const char* key, const char* fallback) {
  return val(j, key, std::string(fallback));
}

std::string scalar(json v) {
  if (v.is_null()) return "-";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
    return buf;
  }
  return v.dump();
}

std::string pairList(json v) {
  if (!v.is_array()) return scalar(v);
  std::string out;
  for (json p : v) {
    if (!out.empty()) out += " ";
    if (p.is_array() && p.size() == 2) {
      out += scalar(p[0]) + "," + scalar(p[1]);
    } else {
      out += scalar(p);
    }
  }
  return out;
}

std::string field(const char* name, const std::string& value) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%-15s", *name ? (std::string(name) + ":").c_str() : "");
  return buf + value + "\n";
}

std::string keystoneText(json k) {
  std::string out = field("auto keystone", val(k, "auto", false) ? "on" : "off");
  json corners = k.contains("corners") ? k["corners"] : json(nullptr);
  out += field("corners", corners.is_null() ? "none (no manual correction)" : pairList(corners));
  if (k.contains("output_size") && !k["output_size"].is_null()) {
    out += field("output", scalar(k["output_size"][0]) + "x" + scalar(k["output_size"][1]));
  }
  // The yaw a tilt sensor cannot see: from the camera on the projector, or why not.
  if (k.contains("tilt") && k["tilt"].is_object() && k["tilt"].contains("yaw")) {
    json y = k["tilt"]["yaw"];
    std::string text = val(y, "source", "");
    if (y.contains("yaw_deg") && y["yaw_deg"].is_number()) {
      char deg[32];
      std::snprintf(deg, sizeof deg, "%.3f deg, ", y["yaw_deg"].get<double>());
      text = deg + text;
    }
    if (y.contains("unavailable")) text += " (" + scalar(y["unavailable"]) + ")";
    out += field("yaw", text);
  }
  // How long a tilt reading takes to reach the wall.
  if (k.contains("latency") && k["latency"].is_object()) {
    json l = k["latency"];
    char text[128];
    std::snprintf(text, sizeof text, "median %.1f ms, 95%% %.1f ms, max %.1f ms (%llu frames)",
                  val(l, "median_ms", 0.0), val(l, "p95_ms", 0.0), val(l, "max_ms", 0.0),
                  static_cast<unsigned long long>(val(l, "frames", 0ULL)));
    out += field("tilt to shown", text);
  }
  if (k.contains("homography") && k["homography"].is_array()) {
    for (size_t r = 0; r < k["homography"].size(); ++r) {
      out += field(r == 0 ? "homography" : "", pairList(k["homography"][r]));
    }
  }
  return out;
}

std::string contentText(json c) {
  if (c.is_null()) return "none";
  std::string s = val(c, "path", "");
  if (c.contains("stream")) {
    json st = c["stream"];
    for (const char* key : {"path", "uri", "v4l2", "pipeline"}) {
      if (st.contains(key)) s = st[key].get<std::string>();
    }
    if (st.contains("test")) s = "test video " + st["test"].get<std::string>();
  }
  if (c.contains("shared")) s = "shared memory";
  if (c.contains("object") && c.contains("display") && c["display"].is_object()) {
    json d = c["display"];
    json cov = val(d, "coverage", json::object());
    char line[200];
    std::snprintf(line, sizeof line,
                  ", painted on the object: white %.4g (%s), lit %.4f m2, unlit %.4f m2",
                  val(d, "white", 0.0), val(d, "units", "").c_str(), val(cov, "lit_m2", 0.0),
                  val(cov, "unlit_m2", 0.0));
    s += line;
  }
  if (c.contains("size")) s += " (" + scalar(c["size"][0]) + "x" + scalar(c["size"][1]) + ")";
  if (c.contains("frames")) {
    s += ", " + scalar(c["frames"]) + " frames" + (val(c, "ended", false) ? ", ended" : "");
  }
  return s;
}

std::string calibrateText(json r) {
  if (val(r, "state", "") == "started") {
    return "calibration " + scalar(r["operation"]) + ": " + scalar(r["frames"]) +
           " pattern frames on " + scalar(r["output"]) + ", cameras " + pairList(r["cameras"]) +
           " (" + scalar(r["mode"]) + ")\n";
  }
  json p = r["projector"];
  std::string out =
      field("projector", scalar(p["name"]) + " " + scalar(p["width"]) + "x" + scalar(p["height"]));
  // Route (b') calibrates a plane homography: no intrinsics, no position.
  if (p.contains("K") && p["K"].is_array() && p["K"].size() == 9) {
    char k[160];
    std::snprintf(k, sizeof k, "fx %.2f  fy %.2f  cx %.2f  cy %.2f", p["K"][0].get<double>(),
                  p["K"][4].get<double>(), p["K"][2].get<double>(), p["K"][5].get<double>());
    out += field("intrinsics", k);
  }
  if (r.contains("position")) out += field("position", pairList(r["position"]) + " m");
  out += field("reprojection", scalar(r["reprojection_rms_px"]) + " px RMS over " +
                                   scalar(p["points"]) + " points");
  out += field("surface", scalar(r["surface_type"]));
  // The adaptive path: what its coarse pass found, and where the plane came from.
  const json coarse = val(r, "coarse", json::object());
  if (coarse.contains("planar")) {
    char fit[160];
    std::snprintf(
        fit, sizeof fit, "%d blocks fit one homography to %.3f px RMS (a plane allows %.3f)",
        val(coarse, "blocks", 0), val(coarse, "rms_px", 0.0), val(coarse, "tolerance_px", 0.0));
    out += field("coarse pass",
                 (val(coarse, "planar", false) ? "planar, " : "not planar, ") + std::string(fit));
    if (coarse.contains("then")) out += field("", val(coarse, "then", ""));
  }
  if (r.contains("plane_source")) {
    std::string plane = val(r, "plane_source", "?");
    const json t = val(r, "triangulated_plane", json::object());
    if (t.contains("rms_m")) {
      char fit[96];
      std::snprintf(fit, sizeof fit, " (%d points, %.3f mm RMS)", val(t, "inliers", 0),
                    1000 * val(t, "rms_m", 0.0));
      plane += fit;
    }
    out += field("plane from", plane);
  }
  out += field("written", scalar(r["path"]));
  return out;
}

std::string latencyText(json r) {
  if (val(r, "state", "") == "started") {
    return "latency " + scalar(r["operation"]) + ": output " + scalar(r["output"]) + ", cameras " +
           pairList(r["cameras"]) + ", " + scalar(r["repeats"]) + " repeats\n";
  }
  char line[200];
  std::snprintf(line, sizeof line, "%.1f ms -> settle %s frames at %.1f Hz (margin %s)",
                val(r, "latency_s", 0.0) * 1e3, scalar(r["settle_frames"]).c_str(),
                val(r, "refresh_hz", 0.0), scalar(r["margin_frames"]).c_str());
  std::string out = field("output", scalar(r["output"])) + field("latency", line);
  for (json c : r["cameras"]) {
    json l = c["latency_s"];
    const size_t samples = c["samples"].is_array() ? c["samples"].size() : 0;
    std::snprintf(line, sizeof line, "median %.1f ms, spread %.1f ms, %zu samples, contrast %.1f",
                  val(l, "median", 0.0) * 1e3, val(l, "spread", 0.0) * 1e3, samples,
                  val(c, "contrast", 0.0));
    out += field(("camera " + scalar(c["name"])).c_str(), line);
  }
  return out;
}

std::string snapshotText(json r) {
  std::string out = field("camera", scalar(r["camera"]) + " " + scalar(r["width"]) + "x" +
                                        scalar(r["height"]) + " " + scalar(r["format"]));
  char line[160];
  // Exposure and gain are what the driver reports; not every driver can.
  const char* unknown = "not reported by the driver";
  if (r.contains("exposure_s") && r["exposure_s"].is_number()) {
    std::snprintf(line, sizeof line, "%.3f ms", r["exposure_s"].get<double>() * 1e3);
    out += field("exposure", line);
  } else {
    out += field("exposure", unknown);
  }
  if (r.contains("gain") && r["gain"].is_number()) {
    const bool db = val(r, "gain_unit", "") == "dB";
    std::snprintf(line, sizeof line, db ? "%.2f dB" : "%.6g (device units)",
                  r["gain"].get<double>());
    out += field("gain", line);
  } else {
    out += field("gain", unknown);
  }
  std::snprintf(line, sizeof line, "%.2f %% saturated, %.2f %% under-exposed, mean %.1f %%",
                val(r, "saturated_pct", 0.0), val(r, "underexposed_pct", 0.0),
                val(r, "mean_pct", 0.0));
  out += field("levels", line);
  if (r.contains("path")) out += field("written", scalar(r["path"]));
  return out;
}

std::string calibrateCameraText(json r) {
  if (r.contains("finishing")) return "finishing " + pairList(r["finishing"]) + "\n";
  if (val(r, "state", "") == "started") {
    return "camera calibration " + scalar(r["operation"]) + ": camera " + scalar(r["camera"]) +
           ", board " + scalar(r["board"]) + "; move the board before the camera\n";
  }
  json c = r["camera"];
  char line[200];
  std::string out =
      field("camera", scalar(c["name"]) + " " + scalar(c["width"]) + "x" + scalar(c["height"]));
  if (c.contains("K") && c["K"].is_array() && c["K"].size() == 9) {
    std::snprintf(line, sizeof line, "fx %.2f  fy %.2f  cx %.2f  cy %.2f", c["K"][0].get<double>(),
                  c["K"][4].get<double>(), c["K"][2].get<double>(), c["K"][5].get<double>());
    out += field("intrinsics", line);
  }
  std::snprintf(line, sizeof line, "%.3f px RMS over %s views (%s frames, %s rejected)",
                val(r, "reprojection_rms_px", 0.0), scalar(r["views"]).c_str(),
                scalar(r["frames"]).c_str(), scalar(r["rejected"]).c_str());
  out += field("reprojection", line);
  std::snprintf(line, sizeof line, "%.0f %% of the image", 100.0 * val(r, "coverage", 0.0));
  out += field("coverage", line);
  out += field("stopped", scalar(r["stopped"]));
  out += field("pose", val(c, "pose_known", false) ? "kept from the rig model"
                                                   : "unknown (calibrate the pair for it)");
  out += field("written", scalar(r["path"]));
  return out;
}

std::string trackerText(json r) {
  if (r.contains("tracker")) {  // a registration was made
    json g = r["registration"];
    char line[160];
    std::snprintf(line, sizeof line, "%s registered from %s points (%s), rms %.3f mm\n",
                  scalar(r["tracker"]).c_str(), scalar(g["points"]).c_str(),
                  scalar(g["source"]).c_str(), val(g, "rms_m", 0.0) * 1e3);
    return line + field("written", scalar(r["path"]));
  }
  std::string out;
  if (r["trackers"].empty()) out += "no trackers\n";
  for (json t : r["trackers"]) {
    char line[256];
    std::snprintf(line, sizeof line, "%-16s %-6s %s m, %.1f Hz, %s samples",
                  scalar(t["name"]).c_str(), scalar(t["state"]).c_str(),
                  pairList(t["position"]).c_str(), val(t, "rate_hz", 0.0),
                  scalar(t["samples"]).c_str());
    out += line;
    json g = t["registration"];
    if (g.is_object()) {
      std::snprintf(line, sizeof line, ", registered (%s, %s points, rms %.3f mm)",
                    scalar(g["source"]).c_str(), scalar(g["points"]).c_str(),
                    val(g, "rms_m", 0.0) * 1e3);
      out += line;
    } else {
      out += ", not registered";
    }
    out += "\n";
  }
  return out;
}

}  // namespace

std::string progressBar(double fraction, int width, const std::string& stage) {
  if (!std::isfinite(fraction)) fraction = 0;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(std::lround(fraction * width));
  std::string bar = "[" + std::string(filled, '#') + std::string(width - filled, '.') + "]";
  char pct[16];
  std::snprintf(pct, sizeof pct, " %3d%%", static_cast<int>(std::lround(fraction * 100)));
  return bar + pct + (stage.empty() ? "" : "  " + stage);
}

// Per output: where recalibrate = "on-drift" stands (status outputs.shown[].drift).
static std::string driftText(json status) {
  std::string out;
  if (status.contains("drift") && status["drift"].is_object()) {
    out += field("recalibrate", scalar(status["drift"]["policy"]));
  }
  if (!status.contains("outputs") || !status["outputs"].is_object()) return out;
  for (json o : val(status["outputs"], "shown", json::array())) {
    if (!o.is_object() || !o.contains("drift") || !o["drift"].is_object()) continue;
    json d = o["drift"];
    std::string text;
    if (d.contains("unavailable")) {
      text = "not checked: " + scalar(d["unavailable"]);
    } else {
      char line[256];
      std::snprintf(line, sizeof line, "%s, %.3f px (camera %s, %s tiles), %s correction(s)",
                    scalar(val(d, "state", json())).c_str(), val(d, "misregistration_px", 0.0),
                    scalar(val(d, "camera", json())).c_str(),
                    d.contains("tiles") ? scalar(d["tiles"]["used"]).c_str() : "no",
                    scalar(val(d, "corrections", json(0))).c_str());
      text = line;
      const json f = val(d, "fiducial", json());
      if (f.is_object() && val(f, "frames", 0.0) > 0) {
        std::snprintf(line, sizeof line, "; %s fiducial frame(s), the last %.3f px",
                      scalar(val(f, "frames", json(0))).c_str(), val(f, "misregistration_px", 0.0));
        text += line;
      }
    }
    out += field(("drift " + scalar(val(o, "name", json()))).c_str(), text);
  }
  return out;
}

namespace {

// The reply as text. Takes it by value: a key a reply lacks (a procamd of another
// version) reads as null through the non-const operator[], never past a map's end.
std::string replyText(json r) {
  const std::string cls = val(r, "class", "");
  if (cls == "ERROR") return "error (" + val(r, "code", "") + "): " + val(r, "message", "") + "\n";
  if (cls == "VERSION") {
    return "procamd " + val(r, "release", "") + ", protocol " + scalar(r["proto_major"]) + "." +
           scalar(r["proto_minor"]) + ", plugin ABI " + scalar(val(r, "plugin_abi", json())) + "\n";
  }
  if (cls == "STATUS") {
    std::string out = field("release", val(r, "release", ""));
    out += field("pid", scalar(r["pid"]));
    char up[32];
    std::snprintf(up, sizeof up, "%.0f s", val(r, "uptime_s", 0.0));
    out += field("uptime", up);
    out += field("virtual rig", scalar(r["sim"]));
    out += field("config", scalar(r["config"]));
    std::string devs;
    for (const auto& [family, n] : r["devices"].items()) {
      devs += (devs.empty() ? "" : ", ") + scalar(n) + " " + family;
    }
    out += field("devices", devs);
    out += field("clients", scalar(r["clients"]) + " (" + scalar(r["watchers"]) + " watching)");
    out += keystoneText(r["keystone"]);
    out += field("pattern", scalar(r["pattern"]));
    out += field("content", contentText(r["content"]));
    out += field("log level", scalar(r["log_level"]));
    out += driftText(r);
    if (r.contains("viewer") && r["viewer"].is_object()) {
      out += field("viewer", pairList(r["viewer"]["position"]) + " m (tracker " +
                                 scalar(r["viewer"]["tracker"]) + ")");
    }
    std::string caps;
    for (const auto& [name, on] : r["capabilities"].items()) {
      caps += (caps.empty() ? "" : ", ") + name + (on.get<bool>() ? "" : " (not built)");
    }
    out += field("capabilities", caps);
    for (json w : r["warnings"]) out += field("warning", scalar(w));
    return out;
  }
  if (cls == "DEVICES") {
    std::string out;
    if (r["devices"].empty()) out += "no devices\n";
    for (json d : r["devices"]) {
      char line[256];
      std::snprintf(line, sizeof line, "%-8s %-16s %-20s %s", scalar(d["family"]).c_str(),
                    scalar(d["name"]).c_str(), scalar(d["driver"]).c_str(),
                    scalar(d["state"]).c_str());
      out += line;
      if (d.contains("error")) out += ": " + scalar(d["error"]);
      for (const char* count : {"frames", "samples"}) {
        if (!d.contains(count)) continue;
        std::snprintf(line, sizeof line, ", %s %s at %.1f Hz", scalar(d[count]).c_str(), count,
                      val(d, "rate_hz", 0.0));
        out += line;
      }
      out += "\n";
    }
    out += std::to_string(r["drivers"].size()) + " driver(s) available\n";
    return out;
  }
  if (cls == "KEYSTONE") return keystoneText(r);
  if (cls == "PATTERN") {
    return "pattern " + scalar(r["pattern"]) +
           (val(r, "shown", false) ? " (shown)" : " (no output showed it)") + "\n";
  }
  if (cls == "CONTENT") return "content: " + contentText(r["content"]) + "\n";
  if (cls == "OBJECT") {
    json o = val(r, "object", json());
    if (!o.is_object()) return "object: none\n";
    json placed = val(o, "placed", json::object());
    std::string out = field("object", val(o, "mesh", std::string()) + " (" +
                                          val(placed, "method", std::string()) + ")");
    out += field("position", pairList(val(o, "t", json::array())) + " m");
    if (o.contains("fit_rms_m") && o["fit_rms_m"].is_number()) {
      char line[64];
      std::snprintf(line, sizeof line, "%.2f mm RMS", 1000 * o["fit_rms_m"].get<double>());
      out += field("fit", line);
    }
    json g = val(r, "refined", json());
    if (g.is_object()) {
      char line[160];
      std::snprintf(line, sizeof line,
                    "from %ld of %ld measured points: moved %.2f mm, turned %.3f deg, %.2f mm RMS",
                    val(g, "points", 0L), val(g, "candidates", 0L), 1000 * val(g, "moved_m", 0.0),
                    val(g, "turned_deg", 0.0), 1000 * val(g, "rms_m", 0.0));
      out += field("refined", line);
      for (json f : val(g, "free", json::array())) {
        out += field("not fixed", val(f, "kind", std::string()) + " along " +
                                      pairList(val(f, "axis", json::array())) + " (as placed)");
      }
    }
    out += field("painted", val(o, "painted", false) ? "yes" : "no");
    return out;
  }
  if (cls == "SAVE") return "saved " + scalar(r["path"]) + " (" + scalar(r["bytes"]) + " bytes)\n";
  if (cls == "RELOAD") return "reloaded " + scalar(r["config"]) + "\n";
  if (cls == "LOG-LEVEL") return "log level " + scalar(r["level"]) + "\n";
  if (cls == "TRACKER") return trackerText(r);
  if (cls == "CALIBRATE") return calibrateText(r);
  if (cls == "LATENCY") return latencyText(r);
  if (cls == "SNAPSHOT") return snapshotText(r);
  if (cls == "CALIBRATE-CAMERA") return calibrateCameraText(r);
  if (cls == "CANCEL") return "cancelled " + pairList(r["cancelled"]) + "\n";
  if (cls == "WATCH") {
    return val(r, "enabled", false) ? "watching: " + pairList(r["events"]) + "\n"
                                    : "not watching\n";
  }
  return r.dump() + "\n";
}

}  // namespace

std::string formatReply(const json& reply) {
  try {
    return replyText(reply);
  } catch (const json::exception&) {
    // A value of another type than this procamctl expects: the reply as it came.
    return reply.dump() + "\n";
  }
}

std::string formatEvent(const json& e) {
  if (!e.is_object()) return e.dump() + "\n";
  std::string out = val(e, "event", "event");
  for (const auto& [k, v] : e.items()) {
    if (k == "class" || k == "id" || k == "event") continue;
    out += " " + k + "=" + (v.is_array() ? pairList(v) : v.is_object() ? v.dump() : scalar(v));
  }
  return out + "\n";
}

}  // namespace procam::ctl
