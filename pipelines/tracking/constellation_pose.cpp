#include "tracking/constellation_pose.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <opencv2/calib3d.hpp>

namespace procam::tracking {
namespace {

Vec2 projectIdeal(const geom::Intrinsics& K, const Vec3& c) {
  return Vec2(K.fx * c.x() / c.z() + K.skew * c.y() / c.z() + K.cx, K.fy * c.y() / c.z() + K.cy);
}

// OpenCV PnP on ideal (undistorted) pixels with K and no distortion.
std::optional<geom::Pose> solvePnP(const cv::Mat& K, std::span<const Vec3> obj,
                                   std::span<const Vec2> img, int flags, const geom::Pose* guess) {
  std::vector<cv::Point3d> o;
  std::vector<cv::Point2d> p;
  for (const Vec3& v : obj) o.emplace_back(v.x(), v.y(), v.z());
  for (const Vec2& v : img) p.emplace_back(v.x(), v.y());
  cv::Mat rvec, tvec;
  if (guess) {
    cv::Mat R(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R.at<double>(r, c) = guess->R(r, c);
    cv::Rodrigues(R, rvec);
    tvec = (cv::Mat_<double>(3, 1) << guess->t.x(), guess->t.y(), guess->t.z());
  }
  // OpenCV reports some degenerate inputs by throwing; pipelines never throw.
  try {
    if (!cv::solvePnP(o, p, K, cv::noArray(), rvec, tvec, guess != nullptr, flags))
      return std::nullopt;
  } catch (const cv::Exception&) {
    return std::nullopt;
  }
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  geom::Pose pose;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.R(r, c) = R.at<double>(r, c);
    pose.t(r) = tvec.at<double>(r);
  }
  if (!pose.R.allFinite() || !pose.t.allFinite()) return std::nullopt;
  return pose;
}

struct Scored {
  geom::Pose pose;
  std::vector<int> blob_of_led;
  int matched = 0;
  double sq = 0;  // sum of squared reprojection errors of the matched LEDs
};

// Every LED projected with `pose`, greedily matched (closest pairs first) to a free blob
// within the gate.
Scored scoreByReprojection(const geom::Intrinsics& K, const geom::Pose& pose,
                           std::span<const Vec3> leds, std::span<const Vec2> blobs, double gate) {
  struct Pair {
    double d2;
    int led, blob;
  };
  std::vector<Pair> pairs;
  for (size_t i = 0; i < leds.size(); ++i) {
    const Vec3 c = pose.toDevice(leds[i]);
    if (c.z() <= 0) continue;
    const Vec2 q = projectIdeal(K, c);
    for (size_t j = 0; j < blobs.size(); ++j) {
      const double d2 = (q - blobs[j]).squaredNorm();
      if (d2 <= gate * gate) pairs.push_back({d2, static_cast<int>(i), static_cast<int>(j)});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d2 < b.d2; });
  Scored s{pose, std::vector<int>(leds.size(), -1), 0, 0};
  std::vector<char> used(blobs.size(), 0);
  for (const Pair& p : pairs) {
    if (s.blob_of_led[static_cast<size_t>(p.led)] >= 0 || used[static_cast<size_t>(p.blob)])
      continue;
    s.blob_of_led[static_cast<size_t>(p.led)] = p.blob;
    used[static_cast<size_t>(p.blob)] = 1;
    ++s.matched;
    s.sq += p.d2;
  }
  return s;
}

bool better(const Scored& a, const Scored& b) {
  return a.matched != b.matched ? a.matched > b.matched : a.sq < b.sq;
}

long permutations(long n, long k) {
  long r = 1;
  for (long i = 0; i < k; ++i) r *= n - i;
  return r;
}
long combinations(long n, long k) {
  long r = 1;
  for (long i = 0; i < k; ++i) r = r * (n - i) / (i + 1);
  return r;
}

// Strict gate on the RMS, then the world position and its covariance.
Result<ConstellationPose> finish(const geom::CameraModel& camera, std::span<const Vec3> leds,
                                 const Scored& best, const ConstellationOptions& o) {
  const double rms = std::sqrt(best.sq / best.matched);
  if (rms > o.max_reprojection_px)
    return fail(ErrorCode::kNotFound, "refined constellation pose fails the reprojection gate");
  ConstellationPose out;
  out.pose = best.pose;
  out.blob_of_led = best.blob_of_led;
  out.matched = best.matched;
  out.rms_px = rms;
  out.position_world = camera.pose.toWorld(best.pose.t);
  std::vector<int> used;
  for (size_t i = 0; i < leds.size(); ++i)
    if (out.blob_of_led[i] >= 0) used.push_back(static_cast<int>(i));
  const Mat3 cov_cam = positionCovariance(camera.K, best.pose, leds, o.pixel_sigma, used);
  out.covariance_world = camera.pose.R.transpose() * cov_cam * camera.pose.R;
  return out;
}

}  // namespace

Mat3 positionCovariance(const geom::Intrinsics& K, const geom::Pose& pose,
                        std::span<const Vec3> leds, double sigma, std::span<const int> used) {
  std::vector<int> idx(used.begin(), used.end());
  if (idx.empty()) {
    idx.resize(leds.size());
    std::iota(idx.begin(), idx.end(), 0);
  }
  // Parameters: a small rotation w (x_cam = exp(w) R x + t) and t; central differences.
  Eigen::MatrixXd J(2 * idx.size(), 6);
  const double h = 1e-7;
  for (int k = 0; k < 6; ++k) {
    geom::Pose plus = pose, minus = pose;
    if (k < 3) {
      const Mat3 dR = Eigen::AngleAxisd(h, Vec3::Unit(k)).toRotationMatrix();
      // Rotation about the constellation origin (t fixed), so the last three
      // parameters are the origin's position alone.
      plus.R = dR * pose.R;
      minus.R = dR.transpose() * pose.R;
    } else {
      plus.t(k - 3) += h;
      minus.t(k - 3) -= h;
    }
    for (size_t i = 0; i < idx.size(); ++i) {
      const Vec3& X = leds[static_cast<size_t>(idx[i])];
      J.block<2, 1>(2 * static_cast<Eigen::Index>(i), k) =
          (projectIdeal(K, plus.toDevice(X)) - projectIdeal(K, minus.toDevice(X))) / (2 * h);
    }
  }
  const Eigen::Matrix<double, 6, 6> info = J.transpose() * J;
  const Eigen::Matrix<double, 6, 6> cov =
      sigma * sigma * info.completeOrthogonalDecomposition().pseudoInverse();
  return cov.block<3, 3>(3, 3);
}

Result<ConstellationPose> estimateConstellationPose(const geom::CameraModel& camera,
                                                    std::span<const Vec3> leds,
                                                    std::span<const Vec2> blobs_distorted,
                                                    const ConstellationOptions& o,
                                                    const std::optional<geom::Pose>& previous) {
  if (leds.size() < 4 || blobs_distorted.size() < 4)
    return fail(ErrorCode::kTooFewPoints, "constellation pose needs >= 4 LEDs and >= 4 blobs");
  if (!(o.max_reprojection_px > 0) || !(o.hypothesis_gate_factor >= 1) || o.max_refinements < 1 ||
      o.min_leds < 4 || !(o.pixel_sigma >= 0))
    return fail(ErrorCode::kInvalidInput, "bad constellation options");
  Points2 blobs;
  for (const Vec2& b : blobs_distorted) {
    auto u = camera.undistortPixel(b);
    if (!u) return tl::unexpected(u.error());
    blobs.push_back(*u);
  }
  const geom::Intrinsics& Ki = camera.K;
  cv::Mat K = (cv::Mat_<double>(3, 3) << Ki.fx, Ki.skew, Ki.cx, 0, Ki.fy, Ki.cy, 0, 0, 1);

  const double loose_gate = o.hypothesis_gate_factor * o.max_reprojection_px;
  const int nl = static_cast<int>(leds.size()), nb = static_cast<int>(blobs.size());
  // Refine on the matched LEDs and re-match: with the loose gate, then the strict one.
  auto refine = [&](Scored s) -> std::optional<Scored> {
    for (const double gate : {loose_gate, o.max_reprojection_px, o.max_reprojection_px}) {
      Points3 obj_all;
      Points2 img_all;
      for (int i = 0; i < nl; ++i)
        if (const int j = s.blob_of_led[static_cast<size_t>(i)]; j >= 0) {
          obj_all.push_back(leds[static_cast<size_t>(i)]);
          img_all.push_back(blobs[static_cast<size_t>(j)]);
        }
      if (obj_all.size() < 4) return std::nullopt;
      auto refined = solvePnP(K, obj_all, img_all, cv::SOLVEPNP_ITERATIVE, &s.pose);
      if (!refined) return std::nullopt;
      s = scoreByReprojection(Ki, *refined, leds, blobs, gate);
    }
    if (s.matched < o.min_leds) return std::nullopt;
    return s;
  };

  // Tracking: the previous frame's pose, accepted when it explains every LED or blob.
  if (previous) {
    auto s = refine(scoreByReprojection(Ki, *previous, leds, blobs, loose_gate));
    if (s && s->matched == std::min(nl, nb)) return finish(camera, leds, *s, o);
  }

  const long hyp = combinations(nl, 4) * permutations(nb, 4);
  if (hyp > o.max_hypotheses)
    return fail(ErrorCode::kInvalidInput,
                "too many blob/LED hypotheses (" + std::to_string(hyp) + ")");
  // Near weak perspective (a 10 cm constellation 2 m away) a pose from four noisy blobs
  // extrapolates poorly to the other LEDs, so hypotheses are scored with a wider gate;
  // each distinct assignment that passes is then refined and judged with the strict one.
  std::map<std::vector<int>, Scored> by_assignment;  // best loose score per assignment
  std::array<Vec3, 4> obj;
  std::array<Vec2, 4> img;
  // Hypotheses: each 4-subset of LEDs against each ordered 4-tuple of blobs.
  for (int a = 0; a < nl; ++a)
    for (int b = a + 1; b < nl; ++b)
      for (int c = b + 1; c < nl; ++c)
        for (int d = c + 1; d < nl; ++d) {
          obj = {leds[a], leds[b], leds[c], leds[d]};
          for (int i = 0; i < nb; ++i)
            for (int j = 0; j < nb; ++j) {
              if (j == i) continue;
              for (int k = 0; k < nb; ++k) {
                if (k == i || k == j) continue;
                for (int l = 0; l < nb; ++l) {
                  if (l == i || l == j || l == k) continue;
                  img = {blobs[i], blobs[j], blobs[k], blobs[l]};
                  auto pose = solvePnP(K, obj, img, cv::SOLVEPNP_AP3P, nullptr);
                  if (!pose) continue;
                  Scored s = scoreByReprojection(Ki, *pose, leds, blobs, loose_gate);
                  if (s.matched < o.min_leds) continue;
                  auto [it, fresh] = by_assignment.try_emplace(s.blob_of_led, s);
                  if (!fresh && better(s, it->second)) it->second = std::move(s);
                }
              }
            }
        }

  // Only the strongest few are refined (LM per candidate is the costly step).
  std::vector<Scored> candidates;
  for (auto& [assignment, scored] : by_assignment) candidates.push_back(std::move(scored));
  std::sort(candidates.begin(), candidates.end(), better);
  if (candidates.size() > static_cast<size_t>(o.max_refinements))
    candidates.resize(static_cast<size_t>(o.max_refinements));
  std::optional<Scored> best;
  for (const Scored& c : candidates)
    if (auto s = refine(c); s && (!best || better(*s, *best))) best = std::move(s);
  if (!best)
    return fail(ErrorCode::kNotFound, "no blob-to-LED assignment reprojects within the gate");
  return finish(camera, leds, *best, o);
}

}  // namespace procam::tracking
