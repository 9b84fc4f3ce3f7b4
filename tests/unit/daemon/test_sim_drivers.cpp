// The virtual rig's mock drivers through the plugin ABI: the tilt sensor
// reports gravity, the camera sees what the mock projector shows (after the
// camera's latency).
#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <thread>

#include "core/monotonic_clock.hpp"
#include "loader.hpp"
#include "registry.hpp"
#include "sim/embedded_scenes.hpp"
#include "sim_plugin.hpp"
#include "sim_world.hpp"

namespace procam::plugins {
namespace {

DeviceDescription simDevice(procam_family family, const char* name,
                            const std::string& scene = "handheld") {
  DeviceDescription d;
  d.family = family;
  d.subsystem = "sim";
  d.name = name;
  d.properties = {{"SIM_SCENE", scene}, {"SIM_DEVICE", name}};
  return d;
}

// handheld.toml with the hand held still and level the whole time.
std::string handheldHeldStill() {
  std::string text;
  for (std::size_t i = 0; i < sim::detail::kEmbeddedSceneCount; ++i) {
    if (sim::detail::kEmbeddedScenes[i].name == "handheld") {
      text = std::string(sim::detail::kEmbeddedScenes[i].text);
    }
  }
  const std::size_t keys = text.find("keyframes = [\n");
  const std::size_t keys_end = text.find("]\n\n", keys);
  EXPECT_NE(keys, std::string::npos);
  EXPECT_NE(keys_end, std::string::npos);
  if (keys != std::string::npos && keys_end != std::string::npos) {
    text.replace(keys, keys_end + 2 - keys,
                 "keyframes = [\n"
                 "  { t = 0.0, position = [0.0, 0.0, 1.2] },\n"
                 "  { t = 8.0, position = [0.0, 0.0, 1.2] },\n"
                 "]\n");
  }
  return text;
}

// handheld.toml with a display-to-capture latency on its camera, and the hand
// held still: captures taken at different times see the wall from the same
// pose, so their black levels differ by noise only (the tilting hand changes
// the camera's view by more than that within a second).
std::string handheldWithLatency(double latency_s) {
  std::string text = handheldHeldStill();
  const std::string camera = "[[cameras]]\n";
  const std::size_t at = text.find(camera);
  EXPECT_NE(at, std::string::npos);
  if (at != std::string::npos) {
    text.insert(at + camera.size(), "latency_s = " + std::to_string(latency_s) + "\n");
  }
  return text;
}

// `text` with `from` replaced by `to` (which must be there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

DriverRegistry simRegistry() {
  static const StaticPlugin plugins[] = {{"sim", &procam_sim_plugin_entry}};
  auto drivers = loadStaticPlugins(plugins);
  EXPECT_TRUE(drivers);
  DriverRegistry r;
  for (const auto& d : *drivers) r.add(d);
  return r;
}

Device open(const DriverRegistry& r, DeviceDescription desc) {
  auto match = r.bestMatch(desc);
  EXPECT_TRUE(match);
  EXPECT_EQ(match->score, 100);
  auto dev = createDevice(match->driver, desc, {});
  EXPECT_TRUE(dev) << dev.error().message;
  return std::move(*dev);
}

TEST(SimDrivers, TiltReportsGravityMagnitude) {
  auto r = simRegistry();
  Device tilt = open(r, simDevice(PROCAM_FAMILY_TILT, "accel"));
  procam_tilt_sample s{};
  char err[256] = {};
  ASSERT_EQ(tilt.raw().ops.tilt->read(tilt.raw().self, &s, err, sizeof err), PROCAM_OK) << err;
  const double norm = std::hypot(s.specific_force[0], s.specific_force[1], s.specific_force[2]);
  // handheld.toml: 50 mg bias per axis (<= 0.087 g in norm) and 400 ug/sqrt(Hz)
  // noise; 0.1 g covers both with margin.
  EXPECT_NEAR(norm, 9.80665, 0.1 * 9.80665);
}

TEST(SimDrivers, TiltGivesItsGyroscopeWhenTheSceneHasOne) {
  auto r = simRegistry();
  // handheld_tour's sensor has a gyroscope; at t ~ 0 the projector is still: the reading
  // is its bias, [0.8, -0.6, 0.4] deg/s (0.005 deg/s/sqrt(Hz) of noise at 100 Hz: 0.035).
  Device with = open(r, simDevice(PROCAM_FAMILY_TILT, "accel", "handheld_tour"));
  procam_tilt_sample s{};
  char err[256] = {};
  ASSERT_EQ(with.raw().ops.tilt->read(with.raw().self, &s, err, sizeof err), PROCAM_OK) << err;
  const auto rate = tiltRate(with.raw());
  ASSERT_TRUE(rate);
  const Vec3 dps =
      Vec3(rate->angular_velocity[0], rate->angular_velocity[1], rate->angular_velocity[2]) *
      (180 / M_PI);
  EXPECT_LT((dps - Vec3(0.8, -0.6, 0.4)).norm(), 0.2) << dps.transpose();
  EXPECT_EQ(rate->timestamp_ns, s.timestamp_ns);
  // handheld's has none.
  Device without = open(r, simDevice(PROCAM_FAMILY_TILT, "accel"));
  ASSERT_EQ(without.raw().ops.tilt->read(without.raw().self, &s, err, sizeof err), PROCAM_OK);
  EXPECT_FALSE(tiltRate(without.raw()));
}

TEST(SimDrivers, TiltSamplesAtItsRateIntoAFifoThatAReaderDrains) {
  // handheld_tour's sensor samples at 100 Hz. A reader that falls behind by 0.3 s gets
  // the 30-odd samples it missed, in order and 10 ms apart, the descriptor readable
  // until it has caught up.
  auto r = simRegistry();
  Device tilt = open(r, simDevice(PROCAM_FAMILY_TILT, "accel", "handheld_tour"));
  const int fd = tilt.pollFd();
  ASSERT_GE(fd, 0);
  auto readable = [fd](int timeout_ms) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) == 1;
  };
  auto next = [&tilt] {
    procam_tilt_sample s{};
    char err[256] = {};
    EXPECT_EQ(tilt.raw().ops.tilt->read(tilt.raw().self, &s, err, sizeof err), PROCAM_OK) << err;
    return s.timestamp_ns;
  };
  const uint64_t first = next();
  EXPECT_EQ(first % 10'000'000, 0u) << first;
  const auto slept = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  uint64_t last = first;
  int drained = 0;
  while (readable(0) && drained < 1000) {
    const uint64_t t = next();
    EXPECT_EQ(t - last, 10'000'000u) << "sample " << drained;
    last = t;
    ++drained;
  }
  // 100 samples a second since the first, give or take the one due as the loop ends.
  const double behind =
      100 * std::chrono::duration<double>(std::chrono::steady_clock::now() - slept).count();
  EXPECT_GE(drained, 29);
  EXPECT_LE(drained, behind + 2);
  // Caught up: a read with none waiting gives the newest again (or the one that came
  // due meanwhile); the descriptor is readable again within a period, and the oldest
  // unread sample is the next on the grid.
  const uint64_t again = next();
  EXPECT_TRUE(again == last || again == last + 10'000'000u) << again - last;
  last = again;
  EXPECT_TRUE(readable(100));
  EXPECT_EQ(next(), last + 10'000'000u);
}

TEST(SimDrivers, TiltGarbageIsDroppedAndCountedByTheDriver) {
  // A broken accelerometer on a projector at a fixed pose: no noise and 2.5 g of bias on
  // the chip's z (up), clamped to its 2 g full scale. It reports the same vector, 2 g
  // long, every time (a trajectory, even a still one, varies it by rounding).
  std::string text = replaced(handheldHeldStill(), "trajectory = \"hand\"",
                              "pose = { position = [0.0, 0.0, 1.2] }");
  text = replaced(text, "noise_density_ug = 400.0", "noise_density_ug = 0.0");
  text = replaced(text, "bias_mg = [50.0, -50.0, 50.0]", "bias_mg = [0.0, 0.0, 2500.0]");
  const auto file = std::filesystem::temp_directory_path() /
                    ("procam_broken_tilt_" + std::to_string(::getpid()) + ".toml");
  {
    std::ofstream out(file);
    out << text;
  }
  auto r = simRegistry();
  Device tilt = open(r, simDevice(PROCAM_FAMILY_TILT, "accel", file.string()));
  for (int i = 0; i < 100; ++i) {
    procam_tilt_sample s{};
    char err[256] = {};
    EXPECT_EQ(tilt.raw().ops.tilt->read(tilt.raw().self, &s, err, sizeof err), PROCAM_EAGAIN)
        << i << ": " << err;
  }
  std::filesystem::remove(file);
  auto c = tiltCounts(tilt.raw());
  ASSERT_TRUE(c);
  // The tilt drivers' gate (SampleGateOptions' defaults): |f| outside [0.5, 1.5] g until
  // the 64th identical vector in a row, stuck from then on.
  EXPECT_EQ(c->accepted, 0u);
  EXPECT_EQ(c->bad_norm, 63u);
  EXPECT_EQ(c->stuck, 37u);
  EXPECT_EQ(c->not_finite + c->out_of_range, 0u);
  EXPECT_EQ(rejectedSamples(*c), 100u);
}

TEST(SimDrivers, CameraSeesWhiteBrighterThanBlack) {
  auto r = simRegistry();
  Device out = open(r, simDevice(PROCAM_FAMILY_OUTPUT, "proj"));
  Device cam = open(r, simDevice(PROCAM_FAMILY_CAMERA, "cam"));
  uint32_t w = 0, h = 0;
  double hz = 0;
  ASSERT_EQ(out.raw().ops.output->get_mode(out.raw().self, &w, &h, &hz), PROCAM_OK);
  ASSERT_EQ(w, 1280u);
  ASSERT_EQ(h, 720u);
  auto meanWith = [&](uint8_t level) {
    std::vector<uint8_t> px(static_cast<size_t>(w) * h * 3, level);
    procam_image frame{w, h, w * 3, PROCAM_PIXEL_RGB8, px.data(), 0};
    char err[256] = {};
    EXPECT_EQ(out.raw().ops.output->show(out.raw().self, &frame, err, sizeof err), PROCAM_OK)
        << err;
    procam_image img{};
    EXPECT_EQ(cam.raw().ops.camera->capture(cam.raw().self, 1000, &img, err, sizeof err), PROCAM_OK)
        << err;
    const size_t n = static_cast<size_t>(img.stride) * img.height;
    return std::accumulate(img.data, img.data + n, 0.0) / static_cast<double>(n);
  };
  const double black = meanWith(0), white = meanWith(255);
  EXPECT_GT(white, black + 10.0) << "black " << black << " white " << white;
}

TEST(SimDrivers, UnknownDeviceIsRefusedWithTheSceneName) {
  auto r = simRegistry();
  auto desc = simDevice(PROCAM_FAMILY_TILT, "gyro");
  auto match = r.bestMatch(desc);
  ASSERT_TRUE(match);
  auto dev = createDevice(match->driver, desc, {});
  ASSERT_FALSE(dev);
  EXPECT_NE(dev.error().message.find("has no such device 'gyro'"), std::string::npos)
      << dev.error().message;
}

TEST(SimDrivers, WorldGivesTheFramesShownAtATime) {
  auto scene = sim::Scene::parse(handheldWithLatency(0.3), "handheld+latency", {});
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(scene->cameras().at(0).latency_s, 0.3);
  sim::mock::SimWorld world(std::move(*scene));
  auto frame = [](int v) { return cv::Mat(2, 2, CV_8UC1, cv::Scalar(v)); };
  auto valueAt = [&](double t) {
    auto shown = world.shownAt(t);
    return shown.count("proj") ? int(shown.at("proj").at<uint8_t>(0, 0)) : -1;
  };
  const double before = world.now();
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  world.show("proj", frame(1));
  const double t1 = world.now();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  world.show("proj", frame(2));
  const double t2 = world.now();
  EXPECT_EQ(valueAt(before), -1);  // nothing shown yet
  EXPECT_EQ(valueAt(t1), 1);
  EXPECT_EQ(valueAt(t2), 2);
  EXPECT_EQ(int(world.shown().at("proj").at<uint8_t>(0, 0)), 2);
  // Shown faster than the history lasts: the frame cap bounds it, and earlier
  // times get the oldest frame kept.
  for (int i = 3; i < 103; ++i) world.show("proj", frame(i));
  EXPECT_EQ(valueAt(t1), 103 - int(sim::mock::SimWorld::kMaxKeptFrames));
  EXPECT_EQ(valueAt(world.now()), 102);
  // Frames older than the largest latency (0.3 s + 0.25 s slack) are dropped,
  // except the one that was on then.
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  world.show("proj", frame(200));
  EXPECT_EQ(valueAt(t2), 102);
  EXPECT_EQ(valueAt(world.now()), 200);
}

TEST(SimDrivers, WorldQueuesAFrameToGoOnLater) {
  auto scene = sim::Scene::parse(handheldHeldStill(), "handheld still", {});
  ASSERT_TRUE(scene) << scene.error().message;
  sim::mock::SimWorld world(std::move(*scene));
  auto frame = [](int v) { return cv::Mat(2, 2, CV_8UC1, cv::Scalar(v)); };
  auto valueNow = [&] {
    auto shown = world.shown();
    return shown.count("proj") ? int(shown.at("proj").at<uint8_t>(0, 0)) : -1;
  };
  world.show("proj", frame(1));
  const std::uint64_t shows = world.showCount();
  const double at = world.now() + 0.08;
  world.show("proj", frame(2), at);
  // Asked for before the queued one: goes on after it, not before.
  world.show("proj", frame(3), at - 0.05);
  EXPECT_EQ(valueNow(), 1);
  EXPECT_EQ(world.showCount(), shows);  // nothing new on the wall yet
  EXPECT_EQ(int(world.shownAt(at - 1e-6).at("proj").at<uint8_t>(0, 0)), 1);
  EXPECT_EQ(int(world.shownAt(at).at("proj").at<uint8_t>(0, 0)), 3);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(valueNow(), 3);
  EXPECT_EQ(world.showCount(), shows + 2);
}

// A scene file of the held-still handheld projector, `vsync` as given; removed with the
// object. The world registry keys worlds by scene: one file per test.
struct SceneFile {
  std::filesystem::path path;
  SceneFile(const std::string& tag, bool vsync) {
    path = std::filesystem::temp_directory_path() /
           ("procam_" + tag + "_" + std::to_string(::getpid()) + ".toml");
    std::ofstream out(path);
    out << replaced(handheldHeldStill(), "[[projectors]]\n",
                    std::string("[[projectors]]\nvsync = ") + (vsync ? "true" : "false") + "\n");
  }
  ~SceneFile() { std::filesystem::remove(path); }
};

// Renders a white frame on the output (identity homography) to go on no earlier than
// `not_before_ns`; returns when render returned (CLOCK_MONOTONIC ns).
uint64_t renderAt(Device& out, uint64_t not_before_ns, uint64_t version) {
  uint32_t w = 0, h = 0;
  double hz = 0;
  EXPECT_EQ(out.raw().ops.output->get_mode(out.raw().self, &w, &h, &hz), PROCAM_OK);
  procam_render_setup setup{};
  setup.output_width = setup.content_width = w;
  setup.output_height = setup.content_height = h;
  setup.path = PROCAM_RENDER_HOMOGRAPHY;
  setup.homography[0] = setup.homography[4] = setup.homography[8] = 1;
  char err[256] = {};
  EXPECT_EQ(out.raw().ops.output->configure(out.raw().self, &setup, err, sizeof err), PROCAM_OK)
      << err;
  std::vector<uint8_t> px(static_cast<size_t>(w) * h * 4, 255);
  procam_image image{w, h, w * 4, PROCAM_PIXEL_RGBA8, px.data(), 0};
  procam_content content{};
  content.image = &image;
  content.version = version;
  EXPECT_EQ(out.raw().ops.output->present_at(out.raw().self, not_before_ns), PROCAM_OK);
  int drawn = 0;
  EXPECT_EQ(
      out.raw().ops.output->render(out.raw().self, &content, &drawn, nullptr, err, sizeof err),
      PROCAM_OK)
      << err;
  EXPECT_EQ(drawn, 1);
  return monotonicNowNs();
}

TEST(SimDrivers, OutputPresentsAFrameAtTheTimeAskedFor) {
  const SceneFile file("present_at", false);
  auto r = simRegistry();
  Device out = open(r, simDevice(PROCAM_FAMILY_OUTPUT, "proj", file.path.string()));
  ASSERT_GE(out.raw().ops.output->version, 4u);
  ASSERT_NE(out.raw().ops.output->present_at, nullptr);
  ASSERT_NE(out.raw().ops.output->get_timing, nullptr);
  uint64_t ready = 0, shown = 0, period = 1;
  // Not asked: on the wall when drawn.
  renderAt(out, 0, 1);
  ASSERT_EQ(out.raw().ops.output->get_timing(out.raw().self, &ready, &shown, &period), PROCAM_OK);
  EXPECT_EQ(period, 0u);
  EXPECT_GT(ready, 0u);
  EXPECT_GE(shown, ready);  // as it is handed to the world, microseconds later
  EXPECT_LT(shown - ready, 1'000'000u);
  // Asked for 250 ms ahead (a 1280x720 frame draws in milliseconds): queued, render
  // returns before it goes on, on the wall at the time asked for.
  const uint64_t asked = monotonicNowNs() + 250'000'000;
  const uint64_t returned = renderAt(out, asked, 2);
  ASSERT_EQ(out.raw().ops.output->get_timing(out.raw().self, &ready, &shown, &period), PROCAM_OK);
  EXPECT_LT(ready, asked);
  EXPECT_NEAR(static_cast<double>(shown), static_cast<double>(std::max(asked, ready)),
              2.0);  // ns rounding through the world's clock
  EXPECT_LT(returned, shown);
  // A time already past: when drawn. The request was for that frame only.
  renderAt(out, 1, 3);
  ASSERT_EQ(out.raw().ops.output->get_timing(out.raw().self, &ready, &shown, &period), PROCAM_OK);
  EXPECT_GE(shown + 2, asked);  // after the frame queued before it (ns rounding)
}

TEST(SimDrivers, OutputWithVsyncPresentsAtItsVblanks) {
  const SceneFile file("vsync", true);
  auto r = simRegistry();
  Device out = open(r, simDevice(PROCAM_FAMILY_OUTPUT, "proj", file.path.string()));
  uint64_t ready = 0, first = 0, period = 0;
  renderAt(out, 0, 1);
  ASSERT_EQ(out.raw().ops.output->get_timing(out.raw().self, &ready, &first, &period), PROCAM_OK);
  EXPECT_NEAR(static_cast<double>(period), 1e9 / 60, 1.0);
  EXPECT_GE(first, ready);
  EXPECT_LT(first - ready, period + 2);
  // Asked for 240 ms after the first vblank (14.4 periods): the first vblank at or after
  // that, on the same 60 Hz grid, when drawn by then (a frame draws in milliseconds).
  uint64_t shown = 0;
  const uint64_t asked = first + 240'000'000;
  renderAt(out, asked, 2);
  ASSERT_EQ(out.raw().ops.output->get_timing(out.raw().self, &ready, &shown, &period), PROCAM_OK);
  const double periods = static_cast<double>(shown - first) / static_cast<double>(period);
  EXPECT_NEAR(periods, std::round(periods), 1e-6);  // on the grid, up to ns rounding
  if (ready < asked) {
    EXPECT_NEAR(periods, 15.0, 1e-6);
  }
  EXPECT_GE(shown + 2, std::max(ready, asked));  // ns rounding
}

TEST(SimDrivers, CameraSeesTheOutputAfterItsLatency) {
  // A scene file of this test: the world registry keys worlds by scene.
  const auto file = std::filesystem::temp_directory_path() /
                    ("procam_latency_" + std::to_string(::getpid()) + ".toml");
  {
    std::ofstream out(file);
    out << handheldWithLatency(0.3);
  }
  auto r = simRegistry();
  Device out = open(r, simDevice(PROCAM_FAMILY_OUTPUT, "proj", file.string()));
  Device cam = open(r, simDevice(PROCAM_FAMILY_CAMERA, "cam", file.string()));
  std::filesystem::remove(file);
  uint32_t w = 0, h = 0;
  double hz = 0;
  ASSERT_EQ(out.raw().ops.output->get_mode(out.raw().self, &w, &h, &hz), PROCAM_OK);
  auto show = [&](uint8_t level) {
    std::vector<uint8_t> px(static_cast<size_t>(w) * h * 3, level);
    procam_image frame{w, h, w * 3, PROCAM_PIXEL_RGB8, px.data(), 0};
    char err[256] = {};
    EXPECT_EQ(out.raw().ops.output->show(out.raw().self, &frame, err, sizeof err), PROCAM_OK)
        << err;
  };
  auto mean = [&] {
    const auto called = std::chrono::steady_clock::now();
    procam_image img{};
    char err[256] = {};
    EXPECT_EQ(cam.raw().ops.camera->capture(cam.raw().self, 1000, &img, err, sizeof err), PROCAM_OK)
        << err;
    // Timestamps on CLOCK_MONOTONIC (steady_clock), within the call.
    const auto ns = [](std::chrono::steady_clock::time_point t) {
      return static_cast<uint64_t>(
          std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
    };
    EXPECT_GE(img.timestamp_ns + 1000, ns(called));
    EXPECT_LE(img.timestamp_ns, ns(std::chrono::steady_clock::now()));
    const size_t n = static_cast<size_t>(img.stride) * img.height;
    return std::accumulate(img.data, img.data + n, 0.0) / static_cast<double>(n);
  };
  show(0);
  std::this_thread::sleep_for(std::chrono::milliseconds(350));
  const double black = mean();
  show(255);
  const double still_black = mean();  // captured within 0.3 s of the switch
  std::this_thread::sleep_for(std::chrono::milliseconds(350));
  const double white = mean();
  EXPECT_GT(white, black + 10.0) << "black " << black << " white " << white;
  // The same black frame, up to the camera's noise (1 DN read noise, shot noise).
  EXPECT_NEAR(still_black, black, 2.0);
}

}  // namespace
}  // namespace procam::plugins
