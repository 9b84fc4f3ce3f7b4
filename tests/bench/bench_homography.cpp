// Homography bench: procamd's fit (normalised DLT, then Levenberg-Marquardt on the
// dst-side error) against cv::findHomography with method 0, which is OpenCV's
// normalised DLT followed by its own LM refinement (10 iterations, n > 4), on the
// same data. n = 4, 20, 100, 1000 points, σ = 0.2 px in dst, 1000 trials each.
//
// Accuracy is reported relative to Hartley & Zisserman's bounds for the ML estimate
// (Result 5.2, d = 8, N = 2n, per coordinate):
//   residual  ε_res = σ √(1 − 4/n)      (data vs fitted transfer)
//   estimate  ε_est = σ √(4/n)          (fitted transfer vs noise-free truth)
// as sqrt(mean over trials of the squared per-coordinate RMS) / bound: 1 means the
// estimator attains the bound. Time ratio = procamd time / OpenCV time (best of
// several repetitions of all trials). Writes bench_homography.csv and, when gnuplot
// exists, bench_homography.png to --out DIR.
//
//   bench_homography [--out DIR] [--trials N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/calib3d.hpp>
#include <random>
#include <string>
#include <vector>

#include "geometry/homography.hpp"
#include "unit/geometry/synthetic_views.hpp"

using namespace procam;

namespace {

constexpr double kSigma = 0.2;
constexpr double kWidth = 1920, kHeight = 1080;

struct Trial {
  Mat3 H;
  Points2 src, dst, truth;
  std::vector<cv::Point2d> cv_src, cv_dst;
};

// Plane-induced homography between two random views, src points uniform in the image.
std::vector<Trial> makeTrials(int n, int trials, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, kSigma);
  std::vector<Trial> out;
  while (int(out.size()) < trials) {
    auto view = [&](double yaw) {
      const Vec3 eye(4 * std::sin(yaw), -4 * std::cos(yaw), 1.5 + 0.5 * u(rng));
      return testing::makeCamera(eye, Vec3(0.2 * u(rng), 0.2 * u(rng), 0), 1200);
    };
    const auto a = view(0.3 * u(rng)), b = view(0.3 + 0.4 * u(rng));
    Trial t;
    t.H = testing::planeHomography(a.projectionMatrix(), b.projectionMatrix());
    for (int i = 0; i < n; ++i) {
      const Vec2 s = testing::uniformPixel(rng, kWidth, kHeight);
      const auto d = geom::applyHomography(t.H, s);
      if (!d) break;
      t.src.push_back(s);
      t.truth.push_back(*d);
      t.dst.push_back(*d + Vec2(noise(rng), noise(rng)));
      t.cv_src.emplace_back(s.x(), s.y());
      t.cv_dst.emplace_back(t.dst.back().x(), t.dst.back().y());
    }
    if (int(t.src.size()) == n) out.push_back(std::move(t));
  }
  return out;
}

struct Accuracy {
  double res2 = 0, est2 = 0;  // sums over trials of per-coordinate mean squares
  std::vector<double> est;    // per-trial per-coordinate RMS estimate error
  int ok = 0, failed = 0;

  double medianEst() {
    if (est.empty()) return NAN;
    std::nth_element(est.begin(), est.begin() + est.size() / 2, est.end());
    return est[est.size() / 2];
  }
};

void score(Accuracy& acc, const Trial& t, const std::optional<Mat3>& H) {
  if (!H) {
    ++acc.failed;
    return;
  }
  double res = 0, est = 0;
  for (std::size_t i = 0; i < t.src.size(); ++i) {
    const auto p = geom::applyHomography(*H, t.src[i]);
    if (!p) {
      ++acc.failed;
      return;
    }
    res += (*p - t.dst[i]).squaredNorm();
    est += (*p - t.truth[i]).squaredNorm();
  }
  const double coords = 2.0 * double(t.src.size());
  acc.res2 += res / coords;
  acc.est2 += est / coords;
  acc.est.push_back(std::sqrt(est / coords));
  ++acc.ok;
}

std::optional<Mat3> procamFit(const Trial& t, bool refine) {
  geom::HomographyOptions options;
  options.refine = refine;
  auto fit = geom::fitHomography(t.src, t.dst, options);
  if (!fit) return std::nullopt;
  return fit->H;
}

std::optional<Mat3> opencvFit(const Trial& t) {
  try {
    const cv::Mat H = cv::findHomography(t.cv_src, t.cv_dst, 0);
    if (H.empty()) return std::nullopt;
    Mat3 out;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out(r, c) = H.at<double>(r, c);
    return out;
  } catch (const cv::Exception&) {
    return std::nullopt;
  }
}

using Fit = std::function<std::optional<Mat3>(const Trial&)>;

// Best of `reps` timed passes over all trials, in microseconds per fit; the last
// pass is scored.
double timeAndScore(const std::vector<Trial>& trials, const Fit& fit, Accuracy& acc, int reps) {
  double best = INFINITY;
  for (int r = 0; r < reps; ++r) {
    std::vector<std::optional<Mat3>> results(trials.size());
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < trials.size(); ++i) results[i] = fit(trials[i]);
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(
        best, std::chrono::duration<double, std::micro>(t1 - t0).count() / double(trials.size()));
    if (r + 1 == reps) {
      for (std::size_t i = 0; i < trials.size(); ++i) score(acc, trials[i], results[i]);
    }
  }
  return best;
}

double ratio(double mean_square, double bound) {
  return bound > 0 ? std::sqrt(mean_square) / bound : NAN;
}

void plot(const std::filesystem::path& out) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) return;
  const std::string csv = (out / "bench_homography.csv").string();
  std::ofstream gp(out / "bench_homography.gp");
  gp << "set terminal pngcairo size 1300,520 noenhanced\n"
     << "set output '" << (out / "bench_homography.png").string() << "'\n"
     << "set datafile separator ','\n"
     << "set multiplot layout 1,2 title 'Homography fit, sigma = 0.2 px in dst, 1000 trials per "
        "n'\n"
     << "set logscale xy\nset xlabel 'points n'\nset ylabel 'time per fit (us)'\n"
     << "set key top left\n"
     << "plot '" << csv << "' skip 1 using 1:4 with linespoints title 'procamd DLT+LM', "
     << "'' skip 1 using 1:5 with linespoints title 'procamd DLT only', "
     << "'' skip 1 using 1:6 with linespoints title 'cv::findHomography method 0 (DLT+LM)'\n"
     << "set ylabel 'RMS error / ML bound (1 = bound attained)'\nset key top left\n"
     << "plot '" << csv << "' skip 1 using 1:8 with linespoints title 'procamd residual/eps_res', "
     << "'' skip 1 using 1:9 with linespoints title 'OpenCV residual/eps_res', "
     << "'' skip 1 using 1:10 with linespoints title 'procamd estimate/eps_est', "
     << "'' skip 1 using 1:11 with linespoints title 'OpenCV estimate/eps_est', "
     << "'' skip 1 using 1:12 with linespoints title 'procamd DLT only estimate/eps_est', "
     << "1 with lines dt 2 lc 'black' title 'ML bound'\n"
     << "unset multiplot\n";
  gp.close();
  const std::string cmd = "gnuplot '" + (out / "bench_homography.gp").string() + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = "bench-out";
  int trials = 1000;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (a == "--trials" && i + 1 < argc) {
      trials = std::max(10, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_homography [--out DIR] [--trials N]\n");
      return 2;
    }
  }
  std::filesystem::create_directories(out);
  std::ofstream csv(out / "bench_homography.csv");
  csv << "n,trials,sigma_px,procam_us,procam_dlt_us,opencv_us,time_ratio,"
         "procam_res_ratio,opencv_res_ratio,procam_est_ratio,opencv_est_ratio,"
         "procam_dlt_est_ratio,procam_est_median_ratio,opencv_est_median_ratio,"
         "procam_failures,opencv_failures\n";
  std::printf("%5s %9s %9s %9s %7s | %-15s | %-22s | %-22s\n", "n", "procam_us", "dlt_us",
              "opencv_us", "ratio", "res/eps_res", "est/eps_est (rms)", "est/eps_est (median)");
  std::printf("%5s %9s %9s %9s %7s | %7s %7s | %7s %7s %6s | %7s %7s\n", "", "", "", "", "",
              "procam", "opencv", "procam", "opencv", "dlt", "procam", "opencv");
  for (int n : {4, 20, 100, 1000}) {
    const auto data = makeTrials(n, trials, 1000 + std::uint64_t(n));
    const int reps = n >= 1000 ? 3 : 5;
    Accuracy pc, dlt, cv;
    const double t_cv = timeAndScore(data, opencvFit, cv, reps);
    const double t_pc = timeAndScore(
        data, [](const Trial& t) { return procamFit(t, true); }, pc, reps);
    const double t_dlt = timeAndScore(
        data, [](const Trial& t) { return procamFit(t, false); }, dlt, reps);
    const double eps_res = kSigma * std::sqrt(1 - 4.0 / n);
    const double eps_est = kSigma * std::sqrt(4.0 / n);
    auto mean = [](double sum, const Accuracy& a) { return a.ok ? sum / a.ok : NAN; };
    const double r_res_pc = ratio(mean(pc.res2, pc), eps_res);
    const double r_res_cv = ratio(mean(cv.res2, cv), eps_res);
    const double r_est_pc = ratio(mean(pc.est2, pc), eps_est);
    const double r_est_cv = ratio(mean(cv.est2, cv), eps_est);
    const double r_est_dlt = ratio(mean(dlt.est2, dlt), eps_est);
    const double m_est_pc = pc.medianEst() / eps_est;
    const double m_est_cv = cv.medianEst() / eps_est;
    csv << n << ',' << trials << ',' << kSigma << ',' << t_pc << ',' << t_dlt << ',' << t_cv << ','
        << t_pc / t_cv << ',' << r_res_pc << ',' << r_res_cv << ',' << r_est_pc << ',' << r_est_cv
        << ',' << r_est_dlt << ',' << m_est_pc << ',' << m_est_cv << ',' << pc.failed << ','
        << cv.failed << '\n';
    std::printf("%5d %9.2f %9.2f %9.2f %7.2f | %7.4f %7.4f | %7.4f %7.4f %6.3f | %7.4f %7.4f\n", n,
                t_pc, t_dlt, t_cv, t_pc / t_cv, r_res_pc, r_res_cv, r_est_pc, r_est_cv, r_est_dlt,
                m_est_pc, m_est_cv);
    if (pc.failed || cv.failed) {
      std::printf("      failures: procamd %d, OpenCV %d\n", pc.failed, cv.failed);
    }
  }
  csv.close();
  plot(out);
  std::printf("wrote %s\n", (out / "bench_homography.csv").string().c_str());
  return 0;
}
