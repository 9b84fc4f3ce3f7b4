// Keystone bench: time per update (sample -> homography) against the OpenCV route
// (getPerspectiveTransform on the same corners), and corner error against
// accelerometer noise for ADXL345, MPU-6050 and LIS3DH, with and without the
// six-position calibration. Writes CSV files (and PNG plots when gnuplot exists) to
// --out DIR.
//
//   bench_keystone [--out DIR] [--trials N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "keystone/accel_calibration.hpp"
#include "keystone/display_error.hpp"
#include "keystone/keystone_solver.hpp"
#include "keystone/orientation.hpp"

using namespace procam;
using namespace procam::keystone;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

// Typical datasheet figures (noise density, zero-g offset magnitude, output rate).
struct Chip {
  const char* name;
  double noise_ug;   // micro-g per sqrt(Hz)
  double offset_mg;  // typical zero-g offset per axis
  double rate_hz;
};
const Chip kChips[] = {
    {"ADXL345", 290, 35, 100},   // 0.75 LSB rms x/y at 100 Hz, ±35 mg 0 g offset
    {"MPU-6050", 400, 50, 100},  // 400 ug/sqrt(Hz), ±50 mg
    {"LIS3DH", 220, 40, 100},    // 220 ug/sqrt(Hz) (normal mode), ±40 mg
};

KeystoneProblem baseProblem() {
  KeystoneProblem p;
  p.K = {2100, 2100, 959.5, 539.5, 0};  // the handheld rig's lens at 1920x1080
  p.width = p.content_width = 1920;
  p.height = p.content_height = 1080;
  return p;
}

double nsPer(std::chrono::steady_clock::duration d, int n) {
  return std::chrono::duration<double, std::nano>(d).count() / n;
}

void timing(const std::filesystem::path& out) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1, 1);
  const int n = 20000;
  std::vector<Vec3> samples;
  for (int i = 0; i < 256; ++i) {
    const Mat3 R = rotationFromAngles({45 * kDeg * U(rng), 20 * kDeg * U(rng), 0});
    samples.push_back(-(R * Vec3(0, 0, -1)));  // specific force, projector frame (g)
  }
  KeystoneProblem p = baseProblem();
  std::vector<std::array<Vec2, 4>> corners(samples.size());
  double checksum = 0;
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i) {
    const std::size_t k = std::size_t(i) % samples.size();
    p.R = *rotationFromDown(-samples[k]);
    auto s = solveKeystone(p);
    checksum += s->H(0, 0);
    corners[k] = s->corners;
  }
  const double ours = nsPer(std::chrono::steady_clock::now() - t0, n);

  // Homography step alone: ours (closed form K[r1 r3 r2] * content scaling, inside
  // solveKeystone) vs OpenCV's getPerspectiveTransform on the same four corners.
  const std::vector<cv::Point2f> content = {
      {-0.5f, -0.5f}, {1919.5f, -0.5f}, {1919.5f, 1079.5f}, {-0.5f, 1079.5f}};
  t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i) {
    const auto& c = corners[std::size_t(i) % corners.size()];
    std::vector<cv::Point2f> dst;
    for (const Vec2& v : c) dst.emplace_back(float(v.x()), float(v.y()));
    cv::Mat H = cv::getPerspectiveTransform(content, dst);
    checksum += H.at<double>(0, 0);
  }
  const double opencv = nsPer(std::chrono::steady_clock::now() - t0, n);
  std::ofstream csv(out / "bench_keystone_time.csv");
  csv << "method,ns_per_update,updates,ratio_to_opencv\n";
  csv << "procam solveKeystone (sample->homography)," << ours << "," << n << "," << ours / opencv
      << "\n";
  csv << "opencv getPerspectiveTransform (homography only)," << opencv << "," << n << ",1\n";
  std::printf(
      "time per update: procam %.0f ns (sample -> homography), OpenCV "
      "getPerspectiveTransform alone %.0f ns, ratio %.2f; goal < 5000 ns: %s   "
      "[checksum %.3g]\n",
      ours, opencv, ours / opencv, ours < 5000 ? "met" : "missed", checksum);
}

// Mean of `seconds` of white noise at the chip's rate: sigma / sqrt(N) per axis.
Vec3 averagedReading(const Vec3& truth_g, const Vec3& bias_g, const Chip& c, double seconds,
                     std::mt19937& rng) {
  const double sigma = c.noise_ug * 1e-6 * std::sqrt(c.rate_hz / 2);
  const double n = std::max(1.0, std::round(seconds * c.rate_hz));
  std::normal_distribution<double> N(0, sigma / std::sqrt(n));
  return truth_g + bias_g + Vec3(N(rng), N(rng), N(rng));
}

void noiseSweep(const std::filesystem::path& out, int trials) {
  std::ofstream csv(out / "bench_keystone_noise.csv");
  csv << "chip,noise_ug_per_rthz,offset_mg,calibrated,averaging_s,mean_corner_px,"
         "p95_corner_px,max_corner_px\n";
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (const Chip& c : kChips)
    for (bool calibrated : {false, true})
      for (double avg : {0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0}) {
        std::vector<double> errs;
        for (int t = 0; t < trials; ++t) {
          const Vec3 bias = c.offset_mg * 1e-3 * Vec3(U(rng), U(rng), U(rng));
          AccelCalibration cal;
          if (calibrated) {  // six still positions of 2 s each
            std::vector<Vec3> six;
            for (int a = 0; a < 3; ++a)
              for (double s : {1.0, -1.0})
                six.push_back(averagedReading(s * Vec3::Unit(a), bias, c, 2.0, rng));
            cal = calibrateSixPosition(six)->calibration;
          }
          KeystoneProblem p = baseProblem();
          const Mat3 R_true = rotationFromAngles({45 * kDeg * U(rng), 20 * kDeg * U(rng), 0});
          const Vec3 f_true = -(R_true * Vec3(0, 0, -1));
          const Vec3 f = cal.apply(averagedReading(f_true, bias, c, avg, rng));
          p.R = *rotationFromDown(-f);
          auto s = solveKeystone(p);
          if (!s) continue;
          errs.push_back(displayError(p.K, R_true, s->corners).max_corner_px);
        }
        std::sort(errs.begin(), errs.end());
        double mean = 0;
        for (double e : errs) mean += e / double(errs.size());
        csv << c.name << "," << c.noise_ug << "," << c.offset_mg << "," << calibrated << "," << avg
            << "," << mean << "," << errs[std::size_t(0.95 * double(errs.size() - 1))] << ","
            << errs.back() << "\n";
        if (avg == 2.0)
          std::printf("%-9s %s  2 s still: mean %.3f px, p95 %.3f px, max %.3f px\n", c.name,
                      calibrated ? "calibrated  " : "uncalibrated", mean,
                      errs[std::size_t(0.95 * double(errs.size() - 1))], errs.back());
      }
}

void plot(const std::filesystem::path& out) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) return;
  std::ofstream gp(out / "bench_keystone_noise.gp");
  gp << "set terminal pngcairo size 900,600\nset output '"
     << (out / "bench_keystone_noise.png").string()
     << "'\nset datafile separator ','\nset logscale xy\nset xlabel 'still averaging time (s)'\n"
        "set ylabel 'p95 corner error (projector px, 1920x1080)'\nset key outside\n"
        "set title 'keystone corner error vs accelerometer noise'\nplot ";
  int i = 0;
  for (const Chip& c : kChips)
    for (int cal : {0, 1}) {
      gp << (i++ ? ", " : "") << "'" << (out / "bench_keystone_noise.csv").string()
         << "' using ($4==" << cal << " && strcol(1) eq '" << c.name << "' ? $5 : 1/0):7 "
         << "with linespoints title '" << c.name << (cal ? " calibrated" : " raw") << "'";
    }
  gp << ", 0.5 with lines dt 2 title 'corner bound 0.5 px'\n";
  gp.close();
  const std::string cmd = "gnuplot '" + (out / "bench_keystone_noise.gp").string() + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = ".";
  int trials = 400;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--out")
      out = argv[i + 1];
    else if (a == "--trials")
      trials = std::max(10, std::atoi(argv[i + 1]));
  }
  std::filesystem::create_directories(out);
  timing(out);
  noiseSweep(out, trials);
  plot(out);
  std::printf("CSV written to %s\n", out.string().c_str());
  return 0;
}
