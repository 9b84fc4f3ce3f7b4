// IR tracking bench: blob detection (pipelines/tracking/blob_detector) at
// 640x480 and 1280x1024 against an OpenCV baseline in the same run (threshold +
// cv::connectedComponentsWithStats + intensity moments per component), and the ir_camera
// tracker end to end on a replay recording of the synthetic head trajectory
// (tests/unit/tracking/led_trajectory.hpp): capture-to-pose time per frame (PNG decode,
// blobs, pose, filter) and the compute part alone (blobs + LedTracker), and the lag of
// each filter behind the truth in frames. Writes blobs.csv and tracker.csv to --out DIR.
//
//   bench_tracking [--out DIR] [--frames N]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "tracker/plugin/tracker_plugin.hpp"
#include "tracking/blob_detector.hpp"
#include "tracking/led_tracker.hpp"
#include "unit/tracking/led_trajectory.hpp"

using namespace procam;
using namespace procam::tracking;
namespace fs = std::filesystem;

namespace {

constexpr double kRate = 60;  // Hz
constexpr double kFrame = 1 / kRate;

double nowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// The baseline: what an OpenCV user writes for the same blobs (threshold, components,
// weights value - threshold, centroid from the weighted moments of each box).
int opencvBlobs(const cv::Mat& img, double threshold, Points2& out) {
  cv::Mat mask, labels, stats, centroids;
  cv::Mat weights = cv::Mat::zeros(img.size(), CV_32F);
  cv::threshold(img, mask, threshold, 255, cv::THRESH_BINARY);
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  cv::subtract(img, cv::Scalar(threshold), weights, mask, CV_32F);
  out.clear();
  for (int i = 1; i < n; ++i) {
    const cv::Rect box(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                       stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT));
    cv::Mat w = weights(box).clone();
    w.setTo(0, labels(box) != i);
    const cv::Moments m = cv::moments(w, false);
    if (m.m00 > 0) out.emplace_back(box.x + m.m10 / m.m00, box.y + m.m01 / m.m00);
  }
  return static_cast<int>(out.size());
}

struct BlobRow {
  int width, height;
  double ours_ms, opencv_ms;
};

BlobRow benchBlobs(int width, int height, int frames) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> ux(20, width - 20), uy(20, height - 20);
  std::vector<cv::Mat> images;
  for (int k = 0; k < 8; ++k) {
    Points2 c;
    for (int i = 0; i < 5; ++i) c.emplace_back(ux(rng), uy(rng));
    cv::Mat img = synthetic::renderSpots(width, height, c);
    cv::Mat noise(height, width, CV_8UC1);
    cv::randu(noise, 0, 8);  // dark-frame noise below the threshold
    images.push_back(img + noise);
  }
  BlobOptions o;
  std::vector<double> ours, base;
  Points2 pts;
  for (int k = 0; k < frames; ++k) {
    const cv::Mat& img = images[static_cast<size_t>(k) % images.size()];
    double t0 = nowMs();
    auto blobs = detectBlobs(img, {}, o);
    ours.push_back(nowMs() - t0);
    t0 = nowMs();
    const int n = opencvBlobs(img, o.threshold, pts);
    base.push_back(nowMs() - t0);
    if (!blobs || blobs->size() != 5 || n != 5) std::fprintf(stderr, "blob count mismatch\n");
  }
  return {width, height, median(ours), median(base)};
}

// A replay recording of the trajectory (1280x1024 gray8 PNGs, 0.1 px blob noise).
fs::path record(int frames) {
  const fs::path dir =
      fs::temp_directory_path() / ("procam-bench-ir-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream index(dir / "index.csv");
  std::mt19937_64 rng(4);
  std::normal_distribution<double> n(0, 0.1);
  const geom::CameraModel cam = synthetic::capCamera();
  for (int k = 0; k < frames; ++k) {
    Points2 c;
    for (size_t i = 0; i < synthetic::kCapLeds.size(); ++i)
      c.push_back(*cam.project(synthetic::headAt(k * kFrame).led(i)) + Vec2(n(rng), n(rng)));
    const std::string name = "f" + std::to_string(k) + ".png";
    cv::imwrite((dir / name).string(), synthetic::renderSpots(cam.width, cam.height, c));
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "%.9f", k * kFrame);
    index << name << "," << stamp << "\n";
  }
  return dir;
}

std::string ledsOption() {
  std::string s;
  for (const Vec3& p : synthetic::kCapLeds)
    s += (s.empty() ? "" : ";") + std::to_string(p.x()) + "," + std::to_string(p.y()) + "," +
         std::to_string(p.z());
  return s;
}

// Median read() time of the ir_camera driver over the recording (replay at speed 0).
double benchDriverRead(const fs::path& dir, int frames) {
  const std::string d = dir.string(), leds = ledsOption();
  const procam_kv kv[] = {{"camera_driver", "replay"},
                          {"camera.dir", d.c_str()},
                          {"camera.speed", "0"},
                          {"fx", "4000"},
                          {"fy", "4000"},
                          {"cx", "639.5"},
                          {"cy", "511.5"},
                          {"camera_look_at", "0,0,2"},
                          {"camera_up", "0,1,0"},
                          {"leds", leds.c_str()}};
  const procam_config config{kv, sizeof kv / sizeof kv[0]};
  procam_device_desc desc{};
  desc.family = PROCAM_FAMILY_TRACKER;
  procam_device dev{};
  char err[256] = {};
  if (tracker::plugin::kIrCameraFactory.create(&desc, &config, &dev, err, sizeof err) !=
      PROCAM_OK) {
    std::fprintf(stderr, "ir_camera: %s\n", err);
    return -1;
  }
  std::vector<double> t;
  for (int k = 0; k < frames; ++k) {
    procam_pose_sample s{};
    const double t0 = nowMs();
    const int rc = dev.ops.tracker->read(dev.self, &s, err, sizeof err);
    t.push_back(nowMs() - t0);
    if (rc != PROCAM_OK) std::fprintf(stderr, "frame %d: %s\n", k, err);
  }
  dev.destroy(dev.self);
  return median(t);
}

struct FilterRow {
  const char* filter;
  double compute_ms;  // blobs + LedTracker::update, median per frame
  double pose_ms;     // LedTracker::update alone
  double lag_frames;  // filtered x behind the truth
  double raw_lag_frames;
};

FilterRow benchPipeline(const fs::path& dir, int frames, FilterKind kind) {
  LedTrackerOptions o;
  o.leds = synthetic::kCapLeds;
  o.filter.kind = kind;
  auto tracker = LedTracker::create(synthetic::capCamera(), o);
  std::vector<cv::Mat> images;
  for (int k = 0; k < frames; ++k)
    images.push_back(
        cv::imread((dir / ("f" + std::to_string(k) + ".png")).string(), cv::IMREAD_UNCHANGED));
  std::vector<double> t, tp, times, raw_x, filtered_x;
  for (int k = 0; k < frames; ++k) {
    const double t0 = nowMs();
    auto blobs = detectBlobs(images[static_cast<size_t>(k)], {}, {});
    Points2 c;
    for (const Blob& b : *blobs) c.push_back(b.center);
    const double t1 = nowMs();
    auto pose = tracker->update(c, k * kFrame);
    t.push_back(nowMs() - t0);
    tp.push_back(nowMs() - t1);
    if (!pose || k < 30) continue;
    times.push_back(k * kFrame);
    raw_x.push_back(pose->raw.x());
    filtered_x.push_back(pose->filtered.x());
  }
  auto truth_x = [](double s) { return synthetic::headAt(s).t.x(); };
  return {kind == FilterKind::kKalman ? "kalman" : "one_euro", median(t), median(tp),
          synthetic::lagBehind(times, filtered_x, truth_x) / kFrame,
          synthetic::lagBehind(times, raw_x, truth_x) / kFrame};
}

// A search frame (no previous pose) with the LEDs and `extra` weaker reflections: median
// time of LedTracker::update over `reps` frames of the trajectory.
double benchSearch(int extra, int reps) {
  LedTrackerOptions o;
  o.leds = synthetic::kCapLeds;
  auto tracker = LedTracker::create(synthetic::capCamera(), o);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> ux(0, 1279), uy(0, 1023);
  const geom::CameraModel cam = synthetic::capCamera();
  std::vector<double> t;
  for (int k = 0; k < reps; ++k) {
    Points2 c;
    for (size_t i = 0; i < synthetic::kCapLeds.size(); ++i)
      c.push_back(*cam.project(synthetic::headAt(k * 0.1).led(i)));
    for (int i = 0; i < extra; ++i) c.emplace_back(ux(rng), uy(rng));
    tracker->reset();
    const double t0 = nowMs();
    auto pose = tracker->update(c, k * 0.1);
    t.push_back(nowMs() - t0);
    if (!pose)
      std::fprintf(stderr, "search with %d extra blobs: %s\n", extra, pose.error().message.c_str());
  }
  return median(t);
}

}  // namespace

int main(int argc, char** argv) {
  fs::path out = "bench-out/bench_tracking";
  int frames = 300;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--out") && i + 1 < argc)
      out = argv[++i];
    else if (!std::strcmp(argv[i], "--frames") && i + 1 < argc)
      frames = std::max(60, std::atoi(argv[++i]));
  }
  fs::create_directories(out);

  std::ofstream blobs_csv(out / "blobs.csv");
  blobs_csv << "width,height,procam_ms,opencv_ms,ratio\n";
  std::printf("blob detection (5 LEDs, median per frame)\n");
  for (auto [w, h] : {std::pair{640, 480}, std::pair{1280, 1024}}) {
    const BlobRow r = benchBlobs(w, h, frames);
    std::printf("  %4dx%-4d  procam %.3f ms  opencv %.3f ms  ratio %.2f\n", w, h, r.ours_ms,
                r.opencv_ms, r.ours_ms / r.opencv_ms);
    blobs_csv << w << "," << h << "," << r.ours_ms << "," << r.opencv_ms << ","
              << r.ours_ms / r.opencv_ms << "\n";
  }

  const int track_frames = std::min(frames, 240);
  const fs::path dir = record(track_frames);
  std::ofstream tracker_csv(out / "tracker.csv");
  tracker_csv << "path,filter,ms_per_frame,pose_ms,lag_frames,raw_lag_frames\n";
  const double read_ms = benchDriverRead(dir, track_frames);
  std::printf(
      "ir_camera read() on replay 1280x1024 (PNG decode + blobs + pose + filter): %.2f ms\n",
      read_ms);
  tracker_csv << "driver_read,kalman," << read_ms << ",,,\n";
  for (FilterKind kind : {FilterKind::kKalman, FilterKind::kOneEuro}) {
    const FilterRow r = benchPipeline(dir, track_frames, kind);
    std::printf(
        "  %-8s blobs + LedTracker %.2f ms/frame (LedTracker %.2f ms), lag %.2f frames (raw "
        "%.2f)\n",
        r.filter, r.compute_ms, r.pose_ms, r.lag_frames, r.raw_lag_frames);
    tracker_csv << "compute," << r.filter << "," << r.compute_ms << "," << r.pose_ms << ","
                << r.lag_frames << "," << r.raw_lag_frames << "\n";
  }
  fs::remove_all(dir);

  std::printf("pose search without a previous pose (5 LEDs + reflections)\n");
  for (int extra : {0, 1, 3, 5, 10}) {
    const double ms = benchSearch(extra, extra >= 5 ? 3 : 10);
    std::printf("  %2d blobs: %.1f ms\n", 5 + extra, ms);
    tracker_csv << "search_" << 5 + extra << "_blobs,," << ms << ",,,\n";
  }
  return 0;
}
