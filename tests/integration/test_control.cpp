// The daemon over its socket: banner, status and devices, watch events,
// keystone/pattern/content/log-level commands, malformed input.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>

#include <opencv2/imgcodecs.hpp>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

// A rig with one tilt sensor served by the constant-tilt fixture plugin.
constexpr const char* kRigConfig = R"(
[daemon]
log_level = "debug"

[[tilt]]
name = "imu"
[tilt.options]
z = 9.5

[[camera]]
name = "cam0"
driver = "v4l2-not-built"
)";

struct Rig {
  TempDir dir;
  std::optional<DaemonProcess> daemon;
  explicit Rig(const std::string& config = kRigConfig) {
    dir.write("procamd.toml", config);
    daemon.emplace(dir, DaemonProcess::Launch{{"--config", dir.file("procamd.toml"), "--plugin-dir",
                                               PROCAM_FIXTURE_DIR},
                                              {},
                                              -1,
                                              true});
  }
  Connection connect() const { return Connection(daemon->socketPath()); }
};

TEST(Control, BannerIsTheVersionLine) {
  Rig rig;
  ASSERT_TRUE(rig.daemon->started()) << rig.daemon->log();
  Connection c = rig.connect();
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c.banner()["class"], "VERSION");
  EXPECT_EQ(c.banner()["proto_major"], 1);
  EXPECT_EQ(c.banner()["proto_minor"], 0);
  EXPECT_EQ(c.banner()["release"], PROCAM_RELEASE);
  auto v = c.call({{"cmd", "version"}, {"id", "v1"}});
  ASSERT_TRUE(v);
  EXPECT_EQ((*v)["class"], "VERSION");
  EXPECT_EQ((*v)["id"], "v1");
  EXPECT_EQ((*v)["plugin_abi"], 2);
}

TEST(Control, StatusAndDevicesListTheRig) {
  Rig rig;
  ASSERT_TRUE(rig.daemon->started()) << rig.daemon->log();
  Connection c = rig.connect();
  auto devices = c.call({{"cmd", "devices"}, {"id", 1}});
  ASSERT_TRUE(devices);
  ASSERT_EQ((*devices)["class"], "DEVICES");
  const json& list = (*devices)["devices"];
  ASSERT_EQ(list.size(), 2u);
  auto byName = [&](const char* name) {
    for (const auto& d : list) {
      if (d["name"] == name) return d;
    }
    return json::object();
  };
  const json imu = byName("imu"), cam = byName("cam0");
  EXPECT_EQ(imu["family"], "tilt");
  EXPECT_EQ(imu["driver"], "constant-tilt");  // chosen by probe(): no driver configured
  EXPECT_EQ(imu["state"], "open");
  EXPECT_EQ(cam["family"], "camera");
  EXPECT_EQ(cam["state"], "error");
  EXPECT_NE(cam.value("error", "").find("v4l2-not-built"), std::string::npos) << cam.dump();

  auto status = c.call({{"cmd", "status"}, {"id", 2}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["class"], "STATUS");
  EXPECT_EQ((*status)["devices"]["tilt"], 1);
  EXPECT_EQ((*status)["devices"]["camera"], 1);
  EXPECT_EQ((*status)["pid"], rig.daemon->pid());
  // The fixture directory also holds a wrong-ABI plugin: reported, not loaded.
  bool abi_warning = false;
  for (const auto& w : (*status)["warnings"]) {
    abi_warning = abi_warning || w.get<std::string>().find("ABI version 2") != std::string::npos;
  }
  EXPECT_TRUE(abi_warning) << status->dump();
}

TEST(Control, WatchersReceiveEventsCausedByOtherClients) {
  Rig rig;
  ASSERT_TRUE(rig.daemon->started());
  Connection watcher = rig.connect(), actor = rig.connect();
  auto w = watcher.call({{"cmd", "watch"}, {"id", "w"}});
  ASSERT_TRUE(w);
  EXPECT_EQ((*w)["class"], "WATCH");
  EXPECT_EQ((*w)["enabled"], true);

  auto p = actor.call({{"cmd", "pattern"}, {"name", "crosshair"}, {"id", 1}});
  ASSERT_TRUE(p);
  EXPECT_EQ((*p)["pattern"], "crosshair");
  const json corners = {{10, 10}, {1900, 20}, {1890, 1070}, {5, 1060}};
  ASSERT_TRUE(actor.call({{"cmd", "keystone"}, {"action", "set"}, {"corners", corners}}));

  auto e1 = watcher.next();
  ASSERT_TRUE(e1);
  EXPECT_EQ((*e1)["class"], "EVENT");
  EXPECT_EQ((*e1)["event"], "pattern");
  EXPECT_EQ((*e1)["pattern"], "crosshair");
  auto e2 = watcher.next();
  ASSERT_TRUE(e2);
  EXPECT_EQ((*e2)["event"], "keystone");
  EXPECT_EQ((*e2)["corners"], corners);

  ASSERT_TRUE(watcher.call({{"cmd", "watch"}, {"enable", false}}));
  ASSERT_TRUE(actor.call({{"cmd", "pattern"}, {"name", "off"}}));
  auto none = watcher.call({{"cmd", "version"}, {"id", "after"}});
  ASSERT_TRUE(none);
  EXPECT_EQ((*none)["id"], "after");  // no pattern event came first
}

TEST(Control, KeystoneSetGetClearAndUnavailableAuto) {
  Rig rig;
  ASSERT_TRUE(rig.daemon->started());
  Connection c = rig.connect();
  auto get = c.call({{"cmd", "keystone"}, {"id", 1}});
  ASSERT_TRUE(get);
  EXPECT_TRUE((*get)["corners"].is_null());
  EXPECT_EQ((*get)["auto"], false);

  auto bad = c.call({{"cmd", "keystone"},
                     {"action", "set"},
                     {"corners", {{0, 0}, {0, 1079}, {1919, 1079}, {1919, 0}}},
                     {"id", 2}});
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["class"], "ERROR");
  EXPECT_EQ((*bad)["code"], "bad-argument");
  EXPECT_EQ((*bad)["id"], 2);

  auto on = c.call({{"cmd", "keystone"}, {"action", "auto"}, {"enable", true}, {"id", 3}});
  ASSERT_TRUE(on);
  EXPECT_EQ((*on)["code"], "unavailable");
  auto off = c.call({{"cmd", "keystone"}, {"action", "auto"}, {"enable", false}, {"id", 4}});
  ASSERT_TRUE(off);
  EXPECT_EQ((*off)["class"], "KEYSTONE");

  auto cal = c.call({{"cmd", "calibrate"}, {"id", 5}});
  ASSERT_TRUE(cal);
  EXPECT_EQ((*cal)["code"], "unavailable");
  auto cancel = c.call({{"cmd", "cancel"}, {"id", 6}});
  ASSERT_TRUE(cancel);
  EXPECT_EQ((*cancel)["code"], "not-found");
}

TEST(Control, ContentLoadDecodesOnAWorkerAndReportsProgress) {
  Rig rig;
  ASSERT_TRUE(rig.daemon->started());
  const std::string png = contentFile(rig.dir, "slide.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30))));
  Connection c = rig.connect();
  ASSERT_TRUE(c.send({{"cmd", "content"}, {"action", "load"}, {"path", png}, {"id", "L"}}));
  std::vector<json> lines;
  for (int i = 0; i < 4; ++i) {
    auto m = c.next();
    ASSERT_TRUE(m);
    lines.push_back(*m);
  }
  EXPECT_EQ(lines[0]["event"], "progress");
  EXPECT_EQ(lines[0]["fraction"], 0.0);
  EXPECT_EQ(lines[1]["event"], "progress");
  EXPECT_EQ(lines[1]["fraction"], 1.0);
  EXPECT_EQ(lines[2]["event"], "finished");
  EXPECT_EQ(lines[2]["ok"], true);
  EXPECT_EQ(lines[3]["class"], "CONTENT");
  EXPECT_EQ(lines[3]["id"], "L");
  EXPECT_EQ(lines[3]["content"]["size"], json({64, 48}));

  auto missing = c.call({{"cmd", "content"},
                         {"action", "load"},
                         {"path", contentFile(rig.dir, "none.png")},
                         {"id", "M"}});
  ASSERT_TRUE(missing);
  EXPECT_EQ((*missing)["class"], "ERROR");
  EXPECT_EQ((*missing)["code"], "io-error");
  auto cleared = c.call({{"cmd", "content"}, {"action", "clear"}});
  ASSERT_TRUE(cleared);
  EXPECT_TRUE((*cleared)["content"].is_null());
}

TEST(Control, LogLevelAndReload) {
  Rig rig;
  ASSERT_TRUE(rig.daemon->started());
  Connection c = rig.connect();
  auto lvl = c.call({{"cmd", "log-level"}, {"level", "warning"}});
  ASSERT_TRUE(lvl);
  EXPECT_EQ((*lvl)["level"], "warning");
  EXPECT_EQ((*c.call({{"cmd", "log-level"}}))["level"], "warning");

  rig.dir.write("procamd.toml", "[daemon]\nlog_level = \"info\"\nbogus = 1\n");
  auto bad = c.call({{"cmd", "reload"}, {"id", 9}});
  ASSERT_TRUE(bad);
  EXPECT_EQ((*bad)["code"], "config-error");
  EXPECT_NE((*bad)["message"].get<std::string>().find(":3: daemon.bogus: unknown key"),
            std::string::npos)
      << bad->dump();
  rig.dir.write("procamd.toml", "[daemon]\nlog_level = \"error\"\n");
  auto good = c.call({{"cmd", "reload"}, {"id", 10}});
  ASSERT_TRUE(good);
  EXPECT_EQ((*good)["class"], "RELOAD");
  EXPECT_EQ((*good)["devices"], 0);  // the reloaded config has no devices
  EXPECT_EQ((*c.call({{"cmd", "log-level"}}))["level"], "error");
}

TEST(Control, TwoHundredMalformedOrOversizedRequestsEachGetAnError) {
  Rig rig;
  ASSERT_TRUE(rig.daemon->started());
  Connection c = rig.connect();
  std::vector<std::string> bad;
  const std::string big(70 * 1024, 'x');
  for (int i = 0; i < 200; ++i) {
    switch (i % 10) {
      case 0:
        bad.push_back("not json " + std::to_string(i));
        break;
      case 1:
        bad.push_back("{\"cmd\":");
        break;
      case 2:
        bad.push_back("[1,2,3]");
        break;
      case 3:
        bad.push_back("{\"id\":" + std::to_string(i) + "}");
        break;
      case 4:
        bad.push_back("{\"cmd\":\"frobnicate\",\"id\":" + std::to_string(i) + "}");
        break;
      case 5:
        bad.push_back("{\"cmd\":\"pattern\",\"name\":\"plaid\",\"id\":" + std::to_string(i) + "}");
        break;
      case 6:
        bad.push_back("{\"cmd\":\"status\",\"extra\":1,\"id\":" + std::to_string(i) + "}");
        break;
      case 7:
        bad.push_back("{\"cmd\":\"keystone\",\"action\":\"set\",\"corners\":[1,2],\"id\":" +
                      std::to_string(i) + "}");
        break;
      case 8:
        bad.push_back("{\"cmd\":\"status\",\"pad\":\"" + big + "\"}");
        break;
      case 9:
        bad.push_back(std::string("{\"cmd\":\"st\xc3\x28tus\"}"));
        break;
    }
  }
  std::string all;
  for (const auto& b : bad) all += b + "\n";
  ASSERT_TRUE(c.sendRaw(all));
  int errors = 0;
  for (size_t i = 0; i < bad.size(); ++i) {
    auto m = c.next();
    ASSERT_TRUE(m) << "no reply to request " << i;
    EXPECT_EQ((*m)["class"], "ERROR") << i << ": " << m->dump();
    if (i % 10 == 8) {
      EXPECT_EQ((*m)["code"], "too-large");
    }
    if (i % 10 >= 3 && i % 10 <= 7) {
      EXPECT_EQ((*m)["id"], static_cast<int>(i));
    }
    errors += (*m)["class"] == "ERROR";
  }
  EXPECT_EQ(errors, 200);
  // Same connection still usable, daemon healthy for others.
  auto s = c.call({{"cmd", "status"}, {"id", "ok"}});
  ASSERT_TRUE(s);
  EXPECT_EQ((*s)["class"], "STATUS");
  Connection other = rig.connect();
  ASSERT_TRUE(other.ok());
  EXPECT_EQ((*other.call({{"cmd", "version"}}))["class"], "VERSION");
}

TEST(Control, HalfClosedClientStillGetsItsReplies) {
  Rig rig;
  ASSERT_TRUE(rig.daemon->started());
  Connection c = rig.connect();
  ASSERT_TRUE(c.sendRaw("{\"cmd\":\"save\",\"id\":1}\n{\"cmd\":\"version\",\"id\":2}\n"));
  ::shutdown(c.fd(), SHUT_WR);
  std::vector<json> replies;
  while (auto m = c.next(3s)) replies.push_back(*m);
  ASSERT_EQ(replies.size(), 2u);
  EXPECT_EQ(replies[0]["id"], 2);          // version is immediate
  EXPECT_EQ(replies[1]["class"], "SAVE");  // save comes back from the I/O worker
}

}  // namespace
}  // namespace procam::itest
