// procamctl: command-line client of procamd (daemon/PROTOCOL.md).
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "client.hpp"
#include "core/guarded_main.hpp"
#include "format.hpp"

namespace {

using nlohmann::json;
using procam::ctl::ExitCode;

constexpr const char* kUsage =
    "usage: procamctl [--socket PATH] [--json] [--timeout SECONDS] COMMAND [ARGS]\n"
    "commands:\n"
    "  version | status | devices | save | reload\n"
    "  watch                          stream events until interrupted\n"
    "  calibrate [KEY=VALUE ...]      run a calibration with a progress bar; keys: mode,\n"
    "                                 step, phase_steps, grid, settle_frames, output,\n"
    "                                 cameras=A,B, projectors=P,Q|all, response=true,\n"
    "                                 plane=[A,B,C,D], board=SPEC (daemon/PROTOCOL.md)\n"
    "  latency [KEY=VALUE ...]        measure the display-to-capture latency; keys:\n"
    "                                 output, cameras=A,B, repeats, timeout_s, margin_frames\n"
    "  cancel [OPERATION]\n"
    "  keystone [get]\n"
    "  keystone set X,Y X,Y X,Y X,Y   corners: top-left top-right bottom-right bottom-left\n"
    "  keystone clear\n"
    "  keystone auto on|off\n"
    "  pattern [off|grid|crosshair|white|black]\n"
    "  content [get] | content load PATH | content clear\n"
    "  content load MODEL [texture=IMAGE] [specular=S] [shininess=N]\n"
    "                                 on a rig with an object: paint its placed model\n"
    "                                 (MODEL, .obj or .ply with texture coordinates)\n"
    "  object [get] | object clear    the object the projectors paint (shader lamps)\n"
    "  object place MODEL FILE [max_rms_m=M]\n"
    "                                 register MODEL to the rig from FILE: {\"points\":\n"
    "                                 [{\"model\": [x,y,z], \"world\": [x,y,z]}, ...]}, 4 or more\n"
    "  object refine [max_distance_m=D]\n"
    "                                 refine the placed model's pose against the surface\n"
    "                                 calibration measured, from within D (default 0.01 m)\n"
    "  content stream PATH [WxH [rgb8|rgba8 [FPS]]]\n"
    "                                 raw frames (with a size) or a video file\n"
    "                                 (PATH: under the daemon's content roots; a relative\n"
    "                                 PATH that exists here is sent as an absolute one)\n"
    "  content uri URI                video from file:, http(s): or rtsp(s): URIs\n"
    "  content v4l2 /dev/videoN       video from a capture device\n"
    "  content test PATTERN [WxH [FPS]]  a test video (smpte, ball, snow, white...)\n"
    "  content pipeline 'GST-SOURCE'  video from a gst-launch source description\n"
    "                                 (only where [content] allow_pipeline = true)\n"
    "  calibrate-camera [CAMERA] --board SPEC [KEY=VALUE ...]\n"
    "                                 intrinsics from a board moved before the camera,\n"
    "                                 written to rig.json; keys: views, coverage, rms_px,\n"
    "                                 timeout_s, interval_s, min_shift\n"
    "  calibrate-camera finish        solve a running one with the views it has\n"
    "  snapshot [CAMERA] [-o FILE.png] [--exposure SECONDS]\n"
    "                                 one frame of a camera (default: the first) as PNG\n"
    "                                 (default FILE: CAMERA.png here), with its exposure,\n"
    "                                 gain and saturated/under-exposed pixels\n"
    "  log-level [error|warning|info|debug]\n"
    "  tracker [get]                  trackers: positions, rates, registrations\n"
    "  tracker register FILE          FILE: the request's JSON, e.g. {\"points\": [{\"tracker\":\n"
    "                                 [x,y,z], \"world\": [x,y,z]}, ...]} (daemon/PROTOCOL.md)\n"
    "exit codes: 0 ok, 1 daemon error, 2 usage, 3 cannot connect, 4 protocol, 5 unavailable\n";

struct Options {
  std::string socket;
  bool json = false;
  std::chrono::milliseconds timeout{10000};
};

[[noreturn]] void usage(const std::string& problem) {
  std::fprintf(stderr, "procamctl: %s\n%s", problem.c_str(), kUsage);
  std::exit(procam::ctl::kExitUsage);
}

bool parsePoint(const std::string& text, json& out) {
  const size_t comma = text.find(',');
  if (comma == std::string::npos) return false;
  char* end = nullptr;
  const std::string xs = text.substr(0, comma), ys = text.substr(comma + 1);
  const double x = std::strtod(xs.c_str(), &end);
  if (xs.empty() || *end) return false;
  const double y = std::strtod(ys.c_str(), &end);
  if (ys.empty() || *end) return false;
  out = json::array({x, y});
  return true;
}

// The request for a one-shot command line.
// A relative path that names a file here is what the user means: sent absolute.
// Otherwise it is sent as given, and the daemon takes it under its first content root.
std::string clientPath(const std::string& path) {
  std::error_code ec;
  if (path.empty() || path.front() == '/' || !std::filesystem::exists(path, ec)) return path;
  return std::filesystem::absolute(path, ec).lexically_normal().string();
}

// "WxH" into the request's width and height; usage error otherwise.
void sizeInto(json& r, const std::string& what, const std::string& text) {
  int w = 0, h = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &tail) != 2) {
    usage(what + ": size '" + text + "' is not WxH");
  }
  r["width"] = w;
  r["height"] = h;
}

json keyValueRequest(const std::string& cmd, const std::vector<std::string>& a);

json buildRequest(const std::string& cmd, const std::vector<std::string>& a) {
  auto arity = [&](size_t lo, size_t hi) {
    if (a.size() < lo || a.size() > hi) usage("wrong number of arguments for " + cmd);
  };
  json r = {{"cmd", cmd}};
  if (cmd == "version" || cmd == "status" || cmd == "devices" || cmd == "save" || cmd == "reload") {
    arity(0, 0);
  } else if (cmd == "cancel") {
    arity(0, 1);
    if (a.size() == 1) r["operation"] = a[0];
  } else if (cmd == "keystone") {
    const std::string action = a.empty() ? "get" : a[0];
    if (action == "get") {
      arity(0, 1);
    } else if (action == "set") {
      arity(5, 5);
      json corners = json::array();
      for (size_t i = 1; i < 5; ++i) {
        json p;
        if (!parsePoint(a[i], p)) usage("corner '" + a[i] + "' is not X,Y");
        corners.push_back(p);
      }
      r["action"] = "set";
      r["corners"] = corners;
    } else if (action == "clear") {
      arity(1, 1);
      r["action"] = "set";
      r["corners"] = nullptr;
    } else if (action == "auto") {
      arity(2, 2);
      if (a[1] != "on" && a[1] != "off") usage("keystone auto takes on or off");
      r["action"] = "auto";
      r["enable"] = a[1] == "on";
    } else {
      usage("unknown keystone action '" + action + "'");
    }
  } else if (cmd == "pattern" || cmd == "log-level") {
    arity(0, 1);
    if (a.size() == 1) r[cmd == "pattern" ? "name" : "level"] = a[0];
  } else if (cmd == "content") {
    const std::string action = a.empty() ? "get" : a[0];
    r["action"] = action;
    if (action == "load") {
      arity(2, 5);
      r["path"] = clientPath(a[1]);
      // The look of an object's model: KEY=VALUE after it.
      const json look = keyValueRequest("content", {a.begin() + 2, a.end()});
      for (const auto& [key, value] : look.items()) {
        if (key == "cmd") continue;
        if (key != "texture" && key != "specular" && key != "shininess")
          usage("content load takes texture=, specular= and shininess= after the path");
        r[key] = key == "texture" && value.is_string() ? json(clientPath(value)) : value;
      }
    } else if (action == "get" || action == "clear") {
      arity(0, 1);
    } else if (action == "uri" || action == "v4l2") {
      arity(2, 2);
      r["action"] = "stream";
      r[action] = a[1];
    } else if (action == "test") {
      arity(2, 4);
      r["action"] = "stream";
      r["test"] = a[1];
      if (a.size() > 2) sizeInto(r, "content test", a[2]);
      if (a.size() > 3) r["fps"] = std::atof(a[3].c_str());
    } else if (action == "stream") {
      arity(2, 5);
      r["path"] = clientPath(a[1]);
      if (a.size() > 2) sizeInto(r, "content stream", a[2]);
      if (a.size() > 3) r["format"] = a[3];
      if (a.size() > 4) r["fps"] = std::atof(a[4].c_str());
    } else if (action == "pipeline") {
      arity(2, 2);
      r["action"] = "stream";
      r["pipeline"] = a[1];
    } else {
      usage("unknown content action '" + action + "'");
    }
  } else if (cmd == "object") {
    const std::string action = a.empty() ? "get" : a[0];
    r["action"] = action;
    if (action == "get" || action == "clear") {
      arity(0, 1);
    } else if (action == "place") {
      arity(3, 4);
      r["model"] = clientPath(a[1]);
      std::ifstream in(a[2]);
      const json body = json::parse(in, nullptr, false);
      if (!in.is_open() || !body.is_object() || !body.contains("points"))
        usage("object place: " + a[2] + " is not a JSON object with \"points\"");
      r["points"] = body["points"];
      if (a.size() == 4) {
        const json extra = keyValueRequest("object", {a[3]});
        if (!extra.contains("max_rms_m")) usage("object place takes max_rms_m= after FILE");
        r["max_rms_m"] = extra["max_rms_m"];
      }
    } else if (action == "refine") {
      arity(1, 2);
      if (a.size() == 2) {
        const json extra = keyValueRequest("object", {a[1]});
        if (!extra.contains("max_distance_m")) usage("object refine takes max_distance_m=");
        r["max_distance_m"] = extra["max_distance_m"];
      }
    } else {
      usage("unknown object action '" + action + "'");
    }
  } else if (cmd == "tracker") {
    const std::string action = a.empty() ? "get" : a[0];
    if (action == "get") {
      arity(0, 1);
    } else if (action == "register") {
      arity(2, 2);
      std::ifstream in(a[1]);
      const json body = json::parse(in, nullptr, false);
      if (!in.is_open() || !body.is_object())
        usage("tracker register: " + a[1] + " is not a JSON object");
      r.update(body);
      r["cmd"] = "tracker";
      r["action"] = "register";
    } else {
      usage("unknown tracker action '" + action + "'");
    }
  } else {
    usage("unknown command '" + cmd + "'");
  }
  return r;
}

int exitFor(const json& reply) {
  if (reply.value("class", "") != "ERROR") return procam::ctl::kExitOk;
  return reply.value("code", "") == "unavailable" ? procam::ctl::kExitUnavailable
                                                  : procam::ctl::kExitError;
}

int fail(const procam::ctl::ClientError& e) {
  std::fprintf(stderr, "procamctl: %s\n", e.message.c_str());
  return e.exit;
}

void print(const Options& o, const json& msg, bool event) {
  if (o.json) {
    std::printf("%s\n", msg.dump().c_str());
  } else {
    std::fputs((event ? procam::ctl::formatEvent(msg) : procam::ctl::formatReply(msg)).c_str(),
               msg.value("class", "") == "ERROR" ? stderr : stdout);
  }
  std::fflush(stdout);
}

int runWatch(const Options& o, procam::ctl::Client& c) {
  auto reply = c.call({{"cmd", "watch"}}, o.timeout);
  if (!reply) return fail(reply.error());
  print(o, *reply, false);
  if (exitFor(*reply) != 0) return exitFor(*reply);
  for (;;) {
    auto msg = c.next(std::chrono::milliseconds(-1));
    if (!msg) return fail(msg.error());
    print(o, *msg, msg->value("class", "") == "EVENT");
  }
}

// An operation's KEY=VALUE arguments: numbers as numbers, true/false as booleans,
// [..] or {..} as JSON, cameras= and projectors= as comma-separated name lists
// (projectors=all stays the word), anything else as text.
json keyValueRequest(const std::string& cmd, const std::vector<std::string>& a) {
  json r = {{"cmd", cmd}};
  for (const std::string& kv : a) {
    const size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) usage(cmd + " takes KEY=VALUE arguments");
    const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
    char* end = nullptr;
    const double n = std::strtod(value.c_str(), &end);
    if ((key == "cameras" || key == "projectors") && value != "all") {
      json names = json::array();
      for (size_t start = 0;;) {
        const size_t comma = value.find(',', start);
        const std::string name = value.substr(start, comma - start);
        if (name.empty()) usage(key + "= takes names separated by commas");
        names.push_back(name);
        if (comma == std::string::npos) break;
        start = comma + 1;
      }
      r[key] = names;
    } else if (value == "true" || value == "false") {
      r[key] = value == "true";
    } else if (!value.empty() && (value.front() == '[' || value.front() == '{')) {
      json parsed = json::parse(value, nullptr, false);
      if (parsed.is_discarded()) usage(key + "=" + value + " is not JSON");
      r[key] = std::move(parsed);
    } else if (!value.empty() && *end == '\0' && std::isfinite(n)) {
      // Integers stay integers: the daemon checks integer arguments as such.
      if (n == std::floor(n) && std::abs(n) < 1e15) {
        r[key] = static_cast<std::int64_t>(n);
      } else {
        r[key] = n;
      }
    } else {
      r[key] = value;
    }
  }
  return r;
}

// snapshot [CAMERA] [-o FILE] [--exposure SECONDS]: the request, and where the PNG goes.
json snapshotRequest(const std::vector<std::string>& a, std::string& out_file) {
  json r = {{"cmd", "snapshot"}};
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] == "-o" || a[i] == "--exposure") {
      if (i + 1 >= a.size()) usage("snapshot: " + a[i] + " needs a value");
      const std::string value = a[++i];
      if (a[i - 1] == "-o") {
        out_file = value;
        continue;
      }
      char* end = nullptr;
      const double s = std::strtod(value.c_str(), &end);
      if (value.empty() || *end || !(s > 0)) usage("snapshot: --exposure takes seconds");
      r["exposure_s"] = s;
    } else if (!a[i].empty() && a[i][0] == '-') {
      usage("snapshot: unknown option '" + a[i] + "'");
    } else if (!r.contains("camera")) {
      r["camera"] = a[i];
    } else {
      usage("snapshot takes one camera");
    }
  }
  return r;
}

// calibrate-camera [CAMERA] --board SPEC [KEY=VALUE ...] | calibrate-camera finish.
json calibrateCameraRequest(const std::vector<std::string>& a) {
  if (a.size() == 1 && a[0] == "finish") return {{"cmd", "calibrate-camera"}, {"action", "finish"}};
  std::vector<std::string> pairs;
  std::string camera, board;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] == "--board") {
      if (i + 1 >= a.size())
        usage("calibrate-camera: --board needs a board, e.g. checker:9x6:0.08");
      board = a[++i];
    } else if (a[i].find('=') != std::string::npos) {
      pairs.push_back(a[i]);
    } else if (camera.empty() && !a[i].empty() && a[i][0] != '-') {
      camera = a[i];
    } else {
      usage("calibrate-camera: unexpected '" + a[i] + "'");
    }
  }
  if (board.empty()) usage("calibrate-camera needs --board SPEC");
  json r = keyValueRequest("calibrate-camera", pairs);
  r["board"] = board;
  if (!camera.empty()) r["camera"] = camera;
  return r;
}

// Copies the daemon's snapshot (in its state directory, readable by its group) to
// the file the user asked for.
int saveSnapshot(const Options& o, const json& reply, std::string file) {
  const std::string from = reply.value("path", "");
  // The daemon's file name is the camera's made safe for a file system.
  if (file.empty()) file = std::filesystem::path(from).filename().string();
  if (file.empty()) file = "snapshot.png";
  std::error_code ec;
  std::filesystem::copy_file(from, file, std::filesystem::copy_options::overwrite_existing, ec);
  if (ec) {
    std::fprintf(stderr, "procamctl: cannot copy the snapshot %s to %s: %s\n", from.c_str(),
                 file.c_str(), ec.message().c_str());
    return procam::ctl::kExitError;
  }
  if (!o.json) std::printf("%-15s%s\n", "saved:", file.c_str());
  return procam::ctl::kExitOk;
}

// Sends a request that starts an operation and follows its progress events
// until the reply arrives. An operation that answers at once with "state":
// "started" (calibrate) is followed until its second, final reply.
int runOperation(const Options& o, procam::ctl::Client& c, const json& request) {
  const bool tty = !o.json && ::isatty(STDERR_FILENO);
  bool bar_shown = false;
  auto on_event = [&](const json& e) {
    if (o.json) return print(o, e, true);
    if (!tty) return;
    if (e.value("event", "") == "views") {  // calibrate-camera, after every frame
      const json& rms = e["rms_px"];
      std::fprintf(
          stderr, "\rviews %s kept, %s rejected (last: %s), coverage %.0f %%, RMS %s\033[K",
          e["views"].dump().c_str(), e["rejected"].dump().c_str(), e.value("last", "").c_str(),
          100.0 * e.value("coverage", 0.0),
          rms.is_number() ? (std::to_string(rms.get<double>()).substr(0, 5) + " px").c_str() : "-");
      bar_shown = true;
      return;
    }
    if (e.value("event", "") != "progress") return;
    std::string stage = e.value("stage", "");
    if (e.contains("captures") && stage == "capturing") {
      stage += " " + e["capture"].dump() + "/" + e["captures"].dump();
    }
    std::fprintf(stderr, "\r%s\033[K",
                 procam::ctl::progressBar(e.value("fraction", 0.0), 30, stage).c_str());
    bar_shown = true;
  };
  // Long operations: no reply timeout, the daemon reports progress.
  auto reply = c.call(request, std::chrono::milliseconds(-1), on_event);
  if (reply && reply->value("state", "") == "started") {
    print(o, *reply, false);
    const json id = (*reply)["id"];
    for (;;) {
      reply = c.next(std::chrono::milliseconds(-1));
      if (!reply || (reply->value("class", "") != "EVENT" && (*reply)["id"] == id)) break;
      if (reply->value("class", "") == "EVENT") on_event(*reply);
    }
  }
  if (bar_shown) std::fputs("\n", stderr);
  if (!reply) return fail(reply.error());
  print(o, *reply, false);
  return exitFor(*reply);
}

}  // namespace

static int run(int argc, char** argv) {
  Options o;
  const char* env = std::getenv("PROCAMD_SOCKET");
  o.socket = env && *env ? env : "/run/procamd/control.sock";
  int i = 1;
  for (; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--socket" && i + 1 < argc) {
      o.socket = argv[++i];
    } else if (a == "--json") {
      o.json = true;
    } else if (a == "--timeout" && i + 1 < argc) {
      char* end = nullptr;
      const double s = std::strtod(argv[++i], &end);
      if (*end || !(s > 0)) usage("--timeout needs a positive number of seconds");
      o.timeout = std::chrono::milliseconds(static_cast<int64_t>(s * 1000));
    } else if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      usage("unknown option '" + a + "'");
    } else {
      break;
    }
  }
  if (i >= argc) usage("no command");
  const std::string cmd = argv[i++];
  const std::vector<std::string> args(argv + i, argv + argc);
  json request;
  const bool key_value = cmd == "calibrate" || cmd == "latency";
  std::string snapshot_file;
  if (cmd == "snapshot") {
    request = snapshotRequest(args, snapshot_file);
  } else if (cmd == "calibrate-camera") {
    request = calibrateCameraRequest(args);
  } else if (cmd != "watch" && !key_value) {
    request = buildRequest(cmd, args);
  }
  if (key_value) request = keyValueRequest(cmd, args);
  if (cmd == "watch" && !args.empty()) usage(cmd + " takes no arguments");

  auto client = procam::ctl::Client::connect(o.socket, o.timeout);
  if (!client) return fail(client.error());
  if (cmd == "watch") return runWatch(o, *client);
  if (key_value) return runOperation(o, *client, request);
  if (cmd == "calibrate-camera" && request.value("action", "") != "finish") {
    return runOperation(o, *client, request);
  }
  if (cmd == "content" && request.value("action", "") == "load") {
    return runOperation(o, *client, request);
  }
  // A long exposure asked for takes its time before the daemon can answer.
  const auto timeout = std::max(o.timeout, std::chrono::milliseconds(static_cast<int64_t>(
                                               2000 * request.value("exposure_s", 0.0) + 6000)));
  auto reply = client->call(request, cmd == "snapshot" ? timeout : o.timeout);
  if (!reply) return fail(reply.error());
  print(o, *reply, false);
  if (cmd == "snapshot" && exitFor(*reply) == 0) return saveSnapshot(o, *reply, snapshot_file);
  return exitFor(*reply);
}

int main(int argc, char** argv) {
  return procam::guardedMain("procamctl", [&] { return run(argc, argv); });
}
