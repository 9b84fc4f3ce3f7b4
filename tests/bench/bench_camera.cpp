// Camera paths bench: the cost of turning what a device sends into a pipeline frame (the
// one conversion of drivers/camera/convert.hpp) per source format and size, with the
// number of copies each path makes; the replay driver's per-frame cost (PNG decode); and,
// when the aravis driver is built and arv-fake-gv-camera-0.8 is installed, the frame rate
// of a live GigE session over loopback at 640x480 Mono8. Writes convert.csv and
// aravis.csv to --out DIR.
//
//   bench_camera [--out DIR] [--frames N] [--seconds S]
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "camera/convert.hpp"
#include "camera/replay/replay_camera.hpp"
#if PROCAM_CAMERA_ARAVIS
#include "camera/aravis/aravis_camera.hpp"
#endif

extern char** environ;

using namespace procam::camera;
namespace fs = std::filesystem;

namespace {

double nowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct Row {
  std::string path;
  int width, height;
  double ms;  // median per frame
  int copies;
};

// Median time of `frames` conversions of one source image.
Row timeConvert(const char* label, SourceFormat f, procam_pixel_format want, bool zero_copy,
                const std::vector<uint8_t>& bytes, int w, int h, int stride, int frames) {
  cv::Mat storage;
  Frame out;
  std::vector<double> t;
  for (int i = 0; i < frames; ++i) {
    const double t0 = nowMs();
    auto ok =
        convertFrame({f, bytes.data(), bytes.size(), uint32_t(w), uint32_t(h), uint32_t(stride)},
                     want, zero_copy, storage, out);
    t.push_back(nowMs() - t0);
    if (!ok) {
      std::fprintf(stderr, "%s: %s\n", label, ok.error().message.c_str());
      return {label, w, h, -1, -1};
    }
  }
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return {label, w, h, t[t.size() / 2], out.copies};
}

std::vector<uint8_t> ramp(int w, int h, int bytes_per_pixel) {
  std::vector<uint8_t> v(std::size_t(w) * h * bytes_per_pixel);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = uint8_t((i * 7 + i / 640) & 0xff);
  return v;
}

#if PROCAM_CAMERA_ARAVIS
std::string findFake() {
  for (const char* dir : {"/usr/bin", "/usr/local/bin"}) {
    const std::string p = std::string(dir) + "/arv-fake-gv-camera-0.8";
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

// Frames per second of a live GigE session over loopback, asking for `fps`.
void benchAravis(const fs::path& out, double seconds) {
  const std::string binary = findFake();
  if (binary.empty()) {
    std::printf("aravis: arv-fake-gv-camera-0.8 not installed, skipped\n");
    return;
  }
  std::ofstream csv(out / "aravis.csv");
  csv << "asked_fps,width,height,frames,seconds,fps,failed,capture_ms_median,copies\n";
  for (double asked : {25.0, 100.0, 1000.0}) {
    pid_t pid = -1;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    const char* argv[] = {binary.c_str(), "-i", "127.0.0.1", nullptr};
    posix_spawn(&pid, binary.c_str(), &actions, nullptr, const_cast<char**>(argv), environ);
    posix_spawn_file_actions_destroy(&actions);
    AravisOptions o;
    o.id = "127.0.0.1";
    o.width = 640;
    o.height = 480;
    o.pixel_format = "Mono8";
    o.fps = asked;
    AravisCamera cam(o);
    procam::Result<void> ok = procam::fail(procam::ErrorCode::kNoDevice, "not started");
    for (int i = 0; i < 100 && !ok; ++i) {
      ok = cam.start();
      if (!ok) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (!ok) {
      std::printf("aravis %.0f fps: %s\n", asked, ok.error().message.c_str());
    } else {
      cam.capture(2000);  // the first frame includes the stream's start
      std::vector<double> t;
      int copies = 0;
      const double start = nowMs();
      while (nowMs() - start < seconds * 1000) {
        const double t0 = nowMs();
        auto f = cam.capture(2000);
        if (!f) break;
        t.push_back(nowMs() - t0);
        copies = (*f)->copies;
      }
      const double elapsed = (nowMs() - start) / 1000;
      std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
      const double fps = double(t.size()) / elapsed;
      std::printf("aravis 640x480 Mono8 asked %.0f fps: %.1f fps (%zu frames, %llu failed)\n",
                  asked, fps, t.size(), (unsigned long long)cam.failedFrames());
      csv << asked << ",640,480," << t.size() << "," << elapsed << "," << fps << ","
          << cam.failedFrames() << "," << (t.empty() ? 0 : t[t.size() / 2]) << "," << copies
          << "\n";
      cam.stop();
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
  }
}
#endif

}  // namespace

int main(int argc, char** argv) {
  fs::path out = "bench-out/bench_camera";
  int frames = 50;
  double seconds = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--out")) out = argv[i + 1];
    if (!std::strcmp(argv[i], "--frames")) frames = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--seconds")) seconds = std::atof(argv[i + 1]);
  }
  fs::create_directories(out);
  std::vector<Row> rows;
  for (auto [w, h] : {std::pair{640, 480}, std::pair{1280, 1024}}) {
    const auto grey = ramp(w, h, 1), y16 = ramp(w, h, 2), yuyv = ramp(w, h, 2), rgb = ramp(w, h, 3);
    std::vector<uint8_t> jpeg;
    cv::imencode(".jpg", cv::Mat(h, w, CV_8UC3, const_cast<uint8_t*>(rgb.data())), jpeg);
    rows.push_back(timeConvert("GREY->gray8 (wrapped)", SourceFormat::kGrey, PROCAM_PIXEL_GRAY8,
                               true, grey, w, h, w, frames));
    rows.push_back(timeConvert("GREY->gray8 (copied)", SourceFormat::kGrey, PROCAM_PIXEL_GRAY8,
                               false, grey, w, h, w, frames));
    rows.push_back(timeConvert("Y16->gray16 (wrapped)", SourceFormat::kY16, PROCAM_PIXEL_GRAY16,
                               true, y16, w, h, 2 * w, frames));
    rows.push_back(timeConvert("Y16->gray8", SourceFormat::kY16, PROCAM_PIXEL_GRAY8, true, y16, w,
                               h, 2 * w, frames));
    rows.push_back(timeConvert("YUYV->rgb8", SourceFormat::kYuyv, PROCAM_PIXEL_RGB8, true, yuyv, w,
                               h, 2 * w, frames));
    rows.push_back(timeConvert("YUYV->gray8", SourceFormat::kYuyv, PROCAM_PIXEL_GRAY8, true, yuyv,
                               w, h, 2 * w, frames));
    rows.push_back(timeConvert("BGR24->rgb8", SourceFormat::kBgr24, PROCAM_PIXEL_RGB8, true, rgb, w,
                               h, 3 * w, frames));
    rows.push_back(timeConvert("MJPEG->rgb8", SourceFormat::kMjpeg, PROCAM_PIXEL_RGB8, true, jpeg,
                               w, h, 0, frames));
    rows.push_back(timeConvert("MJPEG->gray8", SourceFormat::kMjpeg, PROCAM_PIXEL_GRAY8, true, jpeg,
                               w, h, 0, frames));

    // Replay: a PNG decoded per frame (speed 0: as fast as asked).
    const fs::path dir =
        fs::temp_directory_path() / ("procam-bench-replay-" + std::to_string(getpid()));
    fs::create_directories(dir);
    {
      std::ofstream index(dir / "index.csv");
      for (int i = 0; i < 4; ++i) {
        cv::imwrite((dir / ("f" + std::to_string(i) + ".png")).string(),
                    cv::Mat(h, w, CV_8UC1, const_cast<uint8_t*>(grey.data())));
        index << "f" << i << ".png," << i * 0.033 << "\n";
      }
    }
    ReplayCamera replay({dir.string(), 0.0, true, std::nullopt});
    if (replay.start()) {
      std::vector<double> t;
      int copies = 0;
      for (int i = 0; i < frames; ++i) {
        const double t0 = nowMs();
        auto f = replay.capture(0);
        t.push_back(nowMs() - t0);
        if (f) copies = (*f)->copies;
      }
      std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
      rows.push_back({"replay PNG->gray8", w, h, t[t.size() / 2], copies});
    }
    fs::remove_all(dir);
  }
  std::ofstream csv(out / "convert.csv");
  csv << "path,width,height,ms_per_frame,copies\n";
  for (const Row& r : rows) {
    csv << '"' << r.path << "\"," << r.width << "," << r.height << "," << r.ms << "," << r.copies
        << "\n";
    std::printf("%-24s %4dx%-4d %8.3f ms  copies %d\n", r.path.c_str(), r.width, r.height, r.ms,
                r.copies);
  }
#if PROCAM_CAMERA_ARAVIS
  benchAravis(out, seconds);
#endif
  return 0;
}
