// What a careless or hostile client, file or configuration can do to procamd:
// each case answers within a second, reaches no file outside the content roots,
// keeps its memory bounded and does not spin (ARCHITECTURE.md, "Bounds").
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "daemon_harness.hpp"
#include "truth_rig_file.hpp"

namespace procam::itest {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// A reply to `request` within `limit`: the bound every hostile request is held to.
json answeredWithin(Connection& c, const json& request, double limit_s = 1.0) {
  const auto start = Clock::now();
  auto reply = c.call(request, std::chrono::milliseconds(int(limit_s * 1000 * kSlowdown)));
  const double took = secondsSince(start);
  EXPECT_TRUE(reply) << request.dump() << ": no reply within " << limit_s << " s";
  EXPECT_LE(took, limit_s * kSlowdown) << request.dump();
  return reply ? *reply : json(nullptr);
}

void expectCode(const json& reply, const char* code) {
  EXPECT_EQ(reply.value("class", ""), "ERROR") << reply.dump();
  EXPECT_EQ(reply.value("code", ""), code) << reply.dump();
}

json loadRequest(const std::string& path) {
  return {{"cmd", "content"}, {"action", "load"}, {"path", path}};
}

// A /proc/PID/status field in kB (VmHWM, VmRSS).
long statusKb(pid_t pid, const std::string& field) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(field + ":", 0) == 0) return std::stol(line.substr(field.size() + 1));
  }
  return -1;
}

// CPU seconds the process used (user + system).
double cpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::istringstream fields(text.substr(text.rfind(')') + 2));
  std::string f;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> f; ++i) {
    if (i == 14) utime = std::stoull(f);
    if (i == 15) stime = std::stoull(f);
  }
  return double(utime + stime) / double(::sysconf(_SC_CLK_TCK));
}

std::uintmax_t fileSize(const std::string& path) {
  std::error_code ec;
  const auto n = std::filesystem::file_size(path, ec);
  return ec ? 0 : n;
}

// A PNG signature and IHDR chunk declaring `w` x `h` RGB pixels, then nothing:
// what a decoder would allocate w*h*3 bytes for before finding no data.
std::string pngHeader(uint32_t w, uint32_t h) {
  std::string b("\x89PNG\r\n\x1a\n", 8);
  auto be32 = [&](uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) b += char((v >> s) & 0xFF);
  };
  be32(13);
  b += "IHDR";
  be32(w);
  be32(h);
  b += std::string("\x08\x02\x00\x00\x00", 5);
  be32(0);  // CRC: the header is refused before it is checked
  return b;
}

// The tests that load meshes want a rig with a pose and a wall: the scene's truth,
// asked for explicitly.
DaemonProcess::Launch onTheTrueObliqueWall(const TempDir& dir) {
  return {{"--sim", "wall_oblique", "--rig", truthRigFile(dir, "wall_oblique")}, {}, -1, true};
}

// 1. Content only under the roots: raw GStreamer text is off, paths and file URIs
// outside the roots, symlinks and `..` are refused, nothing is read or written.
TEST(Hardening, ContentReachesNoFileOutsideItsRoots) {
  TempDir dir;
  dir.write("secret.txt", "not for clients\n");
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "handheld"}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  const std::string secret = dir.file("secret.txt"), copy = dir.file("copied");

  // The probe that copied a file through a tee into a filesink.
  expectCode(
      answeredWithin(c, {{"cmd", "content"},
                         {"action", "stream"},
                         {"pipeline", "filesrc location=" + secret +
                                          " ! tee name=t ! queue ! filesink location=" + copy +
                                          " t. ! queue ! fakesink videotestsrc "
                                          "num-buffers=1"}}),
      "forbidden");
  expectCode(answeredWithin(c, loadRequest(secret)), "forbidden");
  expectCode(answeredWithin(c, loadRequest("../../secret.txt")), "forbidden");
  ASSERT_EQ(::symlink(secret.c_str(), contentFile(dir, "link.png").c_str()), 0);
  expectCode(answeredWithin(c, loadRequest(contentFile(dir, "link.png"))), "forbidden");
  ASSERT_EQ(::symlink(dir.path().c_str(), contentFile(dir, "outside").c_str()), 0);
  expectCode(answeredWithin(c, loadRequest(contentFile(dir, "outside/secret.txt"))), "forbidden");
  expectCode(answeredWithin(c, {{"cmd", "content"},
                                {"action", "stream"},
                                {"path", secret},
                                {"width", 4},
                                {"height", 4}}),
             "forbidden");
#if PROCAM_HAVE_GSTREAMER
  expectCode(
      answeredWithin(c, {{"cmd", "content"}, {"action", "stream"}, {"uri", "file://" + secret}}),
      "forbidden");
  expectCode(answeredWithin(c, {{"cmd", "content"},
                                {"action", "stream"},
                                {"uri", "http://x/\" ! filesink location=" + copy + " \""}}),
             "bad-argument");
  expectCode(answeredWithin(c, {{"cmd", "content"}, {"action", "stream"}, {"uri", "ftp://x/y"}}),
             "bad-argument");
#endif
  EXPECT_FALSE(std::filesystem::exists(copy));
  // What lies in the root loads, by absolute or relative path.
  writeContent(dir, "ok.pgm", "P5 4 4 255\n" + std::string(16, '\x80'));
  json ok = answeredWithin(c, loadRequest("ok.pgm"), 5.0);
  EXPECT_EQ(ok.value("class", ""), "CONTENT") << ok.dump();
  EXPECT_EQ(ok["content"]["size"], json({4, 4})) << ok.dump();
}

// 2. Clients near the descriptor limit: those that would leave the daemon fewer than
// its headroom hear `busy` (a device reopened, a timer armed or a stream started must
// still get one), the loop does not spin and the log does not flood; new clients get in
// afterwards. accept() failing for want of descriptors is the unit tests'
// (ControlServerDescriptors).
TEST(Hardening, ClientsNearTheDescriptorLimitHearBusyWithoutSpinning) {
  // UBSan tests whether memory is readable through a pipe before it checks a vptr:
  // with few descriptors left it reports every virtual call as one through a bad vptr,
  // so under the sanitizers this case says nothing about procamd.
  if (kSlowdown > 1) GTEST_SKIP() << "runs without sanitizers (they need descriptors too)";
  TempDir dir;
  DaemonProcess::Launch launch{{"--sim", "handheld"}, {}, -1, true};
  launch.max_fds = 64;
  DaemonProcess d(dir, launch);
  ASSERT_TRUE(d.started()) << d.log();
  const double cpu_before = cpuSeconds(d.pid());
  const auto log_before = fileSize(dir.file("daemon.log"));
  std::vector<std::unique_ptr<Connection>> clients;
  int versions = 0, busy = 0, silent = 0;
  for (int i = 0; i < 80; ++i) {
    clients.push_back(std::make_unique<Connection>(d.socketPath()));
    const json& banner = clients.back()->banner();
    if (!clients.back()->ok()) {
      ++silent;
    } else if (banner.value("class", "") == "VERSION") {
      ++versions;
    } else if (banner.value("code", "") == "busy") {
      ++busy;
    }
  }
  std::printf("descriptors: %d banners, %d busy, %d silent of 80\n", versions, busy, silent);
  EXPECT_EQ(silent, 0);
  EXPECT_GT(busy, 0);
  EXPECT_EQ(versions + busy, 80);
  // ServerOptions' headroom under the limit of 64 (a quarter of it: 16): the clients hold
  // descriptors below 48, next to the daemon's own.
  EXPECT_LE(versions, 64 - 16);
  // Held there for two seconds: a spinning loop would burn both of them.
  std::this_thread::sleep_for(2s);
  const double cpu = cpuSeconds(d.pid()) - cpu_before;
  const auto logged = fileSize(dir.file("daemon.log")) - log_before;
  std::printf("descriptors: %.2f s CPU, %ju log bytes over the storm\n", cpu, logged);
  EXPECT_LT(cpu, 0.5 * kSlowdown);
  EXPECT_LT(logged, 64u * 1024u);
  clients.clear();
  EXPECT_TRUE(eventually(
      [&] {
        Connection again(d.socketPath());
        return again.ok() && again.banner().value("class", "") == "VERSION";
      },
      3s))
      << d.log();
}

// 3. Jobs that used to block the worker or go unanswered: a FIFO named like an
// image, a directory named like a mesh, a PLY declaring 1e19 faces.
TEST(Hardening, EveryContentJobIsAnswered) {
  TempDir dir;
  DaemonProcess d(dir, onTheTrueObliqueWall(dir));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_EQ(::mkfifo(contentFile(dir, "f.png").c_str(), 0600), 0);
  expectCode(answeredWithin(c, loadRequest(contentFile(dir, "f.png"))), "io-error");
  json pattern = answeredWithin(c, {{"cmd", "pattern"}, {"name", "white"}}, 2.0);
  EXPECT_EQ(pattern.value("class", ""), "PATTERN") << pattern.dump();
  std::filesystem::create_directory(contentFile(dir, "d.obj"));
  expectCode(answeredWithin(c, loadRequest(contentFile(dir, "d.obj"))), "io-error");
  writeContent(dir, "lie.ply",
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
               "property float z\nelement face 10000000000000000000\n"
               "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
               "3 0 1 2\n");
  const json lie = answeredWithin(c, loadRequest(contentFile(dir, "lie.ply")));
  EXPECT_EQ(lie.value("class", ""), "ERROR") << lie.dump();
  pattern = answeredWithin(c, {{"cmd", "pattern"}, {"name", "black"}}, 2.0);
  EXPECT_EQ(pattern.value("class", ""), "PATTERN") << pattern.dump();
}

// A binary PLY sheet of n x n quads (2 n^2 triangles), rippled so that its shading varies.
std::string plySheet(int n) {
  std::string b =
      "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string((n + 1) * (n + 1)) +
      "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
      std::to_string(2 * n * n) + "\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&](auto v) { b.append(reinterpret_cast<const char*>(&v), sizeof v); };
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const float x = float(i) / float(n) - 0.5f, y = float(j) / float(n) - 0.5f;
      put(x);
      put(y);
      put(0.05f * std::sin(20 * x) * std::cos(20 * y));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int32_t a = j * (n + 1) + i, c = a + n + 1;
      for (const std::array<int32_t, 3> t :
           {std::array<int32_t, 3>{a, a + 1, c + 1}, std::array<int32_t, 3>{a, c + 1, c}}) {
        put(uint8_t(3));
        for (int32_t v : t) put(v);
      }
    }
  }
  return b;
}

// 3b. A frame of a large mesh does not hold a newer request back by a whole frame:
// a `pattern` a client waits for stops the frame in flight midway, and the mesh is
// drawn in full again afterwards.
TEST(Hardening, AnObsoleteFrameStopsMidway) {
  TempDir dir;
  DaemonProcess d(dir, onTheTrueObliqueWall(dir));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  writeContent(dir, "sheet.ply", plySheet(500));  // 500,000 triangles
  auto loaded = c.call(loadRequest(contentFile(dir, "sheet.ply")), std::chrono::seconds(120));
  ASSERT_TRUE(loaded && (*loaded)["class"] == "CONTENT") << (loaded ? loaded->dump() : "none");
  // The mesh's first frame is in flight now (the reply follows its submission).
  const json pattern = answeredWithin(c, {{"cmd", "pattern"}, {"name", "grid"}});
  EXPECT_EQ(pattern.value("class", ""), "PATTERN") << pattern.dump();
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  std::printf("obsolete frame: pattern answered, %d frame(s) stopped\n",
              (*status)["outputs"]["frames_stopped"].get<int>());
  EXPECT_GE((*status)["outputs"]["frames_stopped"].get<int>(), 1) << status->dump();
  // Back to the mesh: drawn in full, the same frame as one never stopped.
  auto off = c.call({{"cmd", "pattern"}, {"name", "off"}}, std::chrono::seconds(60));
  ASSERT_TRUE(off && (*off)["shown"] == true) << (off ? off->dump() : "none");
  status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  const json shown = (*status)["outputs"]["shown"][0];
  EXPECT_EQ(shown.value("source", ""), "content") << shown.dump();
  EXPECT_EQ(shown.value("path", ""), "planar-3d") << shown.dump();
  EXPECT_GT(shown.value("lit_fraction", 0.0), 0.01) << shown.dump();
  // The reference: the mesh loaded again and left alone.
  ASSERT_TRUE(c.call({{"cmd", "content"}, {"action", "clear"}}));
  ASSERT_TRUE(eventually([&] {  // the cleared frame's statistics first
    auto s = c.call({{"cmd", "status"}});
    return s && (*s)["outputs"]["shown"][0].value("source", "") == "none";
  }));
  loaded = c.call(loadRequest(contentFile(dir, "sheet.ply")), std::chrono::seconds(120));
  ASSERT_TRUE(loaded && (*loaded)["class"] == "CONTENT");
  json reference;
  ASSERT_TRUE(eventually(
      [&] {
        auto s = c.call({{"cmd", "status"}});
        if (!s) return false;
        reference = (*s)["outputs"]["shown"][0];
        return reference.value("source", "") == "content";
      },
      std::chrono::seconds(60)));
  EXPECT_EQ(reference.value("lit_fraction", -1.0), shown.value("lit_fraction", -2.0));
  EXPECT_EQ(reference["mean_rgb"], shown["mean_rgb"]);
}

// 4. Sizes a client controls are refused with `too-large` before the memory is
// taken: a polygon of 300,000 indices, a 30000x30000 PNG, 16384^2 frames.
TEST(Hardening, OversizedInputsAreRefusedBeforeTheyCostMemory) {
  TempDir dir;
  DaemonProcess d(dir, onTheTrueObliqueWall(dir));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_TRUE(eventually([&] { return (*c.call({{"cmd", "status"}}))["outputs"]["frames"] > 0; }));
  const long hwm_before = statusKb(d.pid(), "VmHWM");

  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i < 300000; ++i) obj += " " + std::to_string(1 + i % 3);
  writeContent(dir, "fan.obj", obj + "\n");
  expectCode(answeredWithin(c, loadRequest(contentFile(dir, "fan.obj"))), "too-large");
  writeContent(dir, "huge.png", pngHeader(30000, 30000));
  expectCode(answeredWithin(c, loadRequest(contentFile(dir, "huge.png"))), "too-large");
  ASSERT_EQ(::mkfifo(contentFile(dir, "big").c_str(), 0600), 0);
  expectCode(answeredWithin(c, {{"cmd", "content"},
                                {"action", "stream"},
                                {"path", contentFile(dir, "big")},
                                {"width", 16384},
                                {"height", 16384}}),
             "too-large");
  expectCode(answeredWithin(
                 c, {{"cmd", "content"}, {"action", "share"}, {"width", 16384}, {"height", 16384}}),
             "too-large");
  const long hwm_after = statusKb(d.pid(), "VmHWM");
  std::printf("oversized: peak RSS %ld -> %ld kB\n", hwm_before, hwm_after);
  // The refused inputs would have taken 2.7 GB (PNG) and 1 GiB (frames).
  EXPECT_LT(hwm_after - hwm_before, 64 * 1024);
}

// 5. A configuration that is not a regular file is refused at start and on reload,
// and the daemon keeps the settings it has.
TEST(Hardening, ConfigurationMustBeARegularFile) {
  TempDir dir;
  ASSERT_EQ(::mkfifo(dir.file("fifo.toml").c_str(), 0600), 0);
  for (const std::string& config : {dir.file("fifo.toml"), dir.path(), std::string("/dev/zero")}) {
    const auto start = Clock::now();
    auto run = runProgram({PROCAMD_BIN, "--config", config, "--runtime-dir", dir.file("run"),
                           "--state-dir", dir.file("state")});
    EXPECT_EQ(run.status, 1) << config << ": " << run.err;
    EXPECT_NE(run.err.find("not a regular file"), std::string::npos) << run.err;
    EXPECT_LT(secondsSince(start), 1.0 * kSlowdown) << config;
  }
  dir.write("group.toml", "[daemon]\ngroup = \"no-such-group-procam\"\n");
  auto run = runProgram({PROCAMD_BIN, "--config", dir.file("group.toml"), "--runtime-dir",
                         dir.file("run"), "--state-dir", dir.file("state")});
  EXPECT_EQ(run.status, 1) << run.err;
  EXPECT_NE(run.err.find("group.toml:2: daemon.group: no group 'no-such-group-procam'"),
            std::string::npos)
      << run.err;

  dir.write("procamd.toml", "[daemon]\nlog_level = \"debug\"\n");
  DaemonProcess d(dir,
                  DaemonProcess::Launch{
                      {"--config", dir.file("procamd.toml"), "--sim", "handheld"}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  std::filesystem::remove(dir.file("procamd.toml"));
  ASSERT_EQ(::mkfifo(dir.file("procamd.toml").c_str(), 0600), 0);
  expectCode(answeredWithin(c, {{"cmd", "reload"}}), "config-error");
  std::filesystem::remove(dir.file("procamd.toml"));
  std::filesystem::create_directory(dir.file("procamd.toml"));
  expectCode(answeredWithin(c, {{"cmd", "reload"}}), "config-error");
  const json level = answeredWithin(c, {{"cmd", "log-level"}});
  EXPECT_EQ(level.value("level", ""), "debug") << level.dump();
}

// 6. The tools exit with a message, never an abort, on a directory where a file
// belongs and on counts beyond the daemon's own bounds.
TEST(Hardening, ToolsExitWithAMessageOnBadFiles) {
  TempDir dir;
  std::filesystem::create_directory(dir.file("d"));
  std::filesystem::create_directories(dir.file("seq/sequence.json"));
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"solve-fiducials", "--fiducials", dir.file("d"), "--projector",
                                 "64x40", "--out", dir.file("rig.json")},
        std::vector<std::string>{"solve-fiducials", "--fiducials", dir.file("d"), "--cameras",
                                 dir.file("d"), "--projector", "64x40", "--out",
                                 dir.file("rig.json")},
        std::vector<std::string>{"decode", "--patterns", dir.file("seq"), "--captures",
                                 dir.file("d"), "--out", dir.file("c.pfm")},
        std::vector<std::string>{"patterns", "--projector", "64x40", "--mode", "gray+phase",
                                 "--phase-steps", "1000000", "--out", dir.file("p")}}) {
    std::vector<std::string> argv = {PROCAM_CALIBRATE_BIN};
    argv.insert(argv.end(), args.begin(), args.end());
    auto run = runProgram(argv);
    EXPECT_EQ(run.status, 1) << args[0] << ": " << run.err;
    EXPECT_FALSE(run.err.empty()) << args[0];
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("p")));
}

// 7. One client's flood of pipelined `save`s does not hold another's back: the
// workers serve their clients in turn, queued saves write the newest settings once,
// and a client's queue is bounded (the rest answered `too-large`).
TEST(Hardening, OneClientsFloodDoesNotDelayAnother) {
  TempDir dir;
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "handheld"}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection flood(d.socketPath()), other(d.socketPath());
  ASSERT_TRUE(flood.ok() && other.ok());
  // The probe's 20,000; a tenth under the sanitizers, whose daemon is 8x slower.
  constexpr int kSaves = kSlowdown > 1 ? 2000 : 20000;
  std::atomic<int> answered{0}, refused{0};
  std::jthread reader([&] {
    while (answered < kSaves) {
      auto line = flood.next(10s * kSlowdown);
      if (!line) break;
      if ((*line)["class"] == "EVENT") continue;
      if ((*line).value("code", "") == "too-large") ++refused;
      ++answered;
    }
  });
  std::string lines;
  for (int i = 0; i < kSaves; ++i) lines += "{\"cmd\":\"save\",\"id\":" + std::to_string(i) + "}\n";
  std::jthread writer([&] { flood.sendRaw(lines); });
  ASSERT_TRUE(eventually([&] { return answered > 100; }, 10s));
  const auto asked = Clock::now();
  const json saved = answeredWithin(other, {{"cmd", "save"}});
  std::printf("flood: the other client's save answered in %.1f ms\n", 1e3 * secondsSince(asked));
  EXPECT_EQ(saved.value("class", ""), "SAVE") << saved.dump();
  writer.join();
  reader.join();
  std::printf("flood: %d of %d answered, %d refused as too-large\n", answered.load(), kSaves,
              refused.load());
  std::string unusual;
  std::istringstream log(d.log());
  for (std::string line; std::getline(log, line);) {
    if (line.find("settings saved") == std::string::npos) unusual += line + "\n";
  }
  EXPECT_EQ(answered, kSaves) << unusual;
}

}  // namespace
}  // namespace procam::itest
