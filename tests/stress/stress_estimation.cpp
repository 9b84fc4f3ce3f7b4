// Stress: homography, projection matrix, its decomposition and undistortion on
// random and adversarial input (collinear / near-collinear / coplanar points,
// duplicates, 1e4 px offsets, 4K coordinates, points near infinity, huge and tiny
// scales, NaN/Inf). Every call must return a finite result that matches the known
// truth within tolerance, or a typed error; where the input admits no unique answer
// the error is required.
//
// Tolerances: exact data through a normalised DLT + LM has relative error about
// condition · eps; with the default max_condition = 1e8 that is < 1e-7, checked at
// 1e-6 of the data's spread. Noisy data (σ per coordinate, n >= 8): to first order
// the ML estimate's error at the data points is the projection of the noise onto an
// 8-dim subspace, so |error_i|² <= σ² χ²(8); we allow 8σ (tail ~1e-10). The residual
// satisfies n·rms²/σ² ~ χ²(2n-8); we allow rms <= 3.5σ (tail < 1e-15 for n >= 8).
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "geometry/homography.hpp"
#include "geometry/projection_matrix.hpp"
#include "stress/stress_random.hpp"
#include "unit/geometry/synthetic_views.hpp"

namespace procam::geom {
namespace {

using stress::Rng;

// Fewer cases under AddressSanitizer (about 10x slower); >= 1e5 in total otherwise.
#if defined(__SANITIZE_ADDRESS__)
constexpr int kCaseDivisor = 5;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr int kCaseDivisor = 5;
#else
constexpr int kCaseDivisor = 1;
#endif
#else
constexpr int kCaseDivisor = 1;
#endif

constexpr double kRelTol = 1e-6;

// Counts cases and reports the first few failures with their description.
struct Tally {
  const char* name;
  long cases = 0, solved = 0, refused = 0, failures = 0;
  void fail(const std::string& what) {
    if (++failures <= 10) ADD_FAILURE() << name << ": " << what;
  }
  ~Tally() {
    std::printf("[stress] %s: %ld cases (%ld solved, %ld typed errors)\n", name, cases, solved,
                refused);
  }
};

std::string describe(const Error& e) {
  return std::string(toString(e.code)) + " (" + e.message + ")";
}

// Similarity S(x) = s x + o applied to a point set and the induced change of H.
struct Frame {
  double s = 1;
  Vec2 o = Vec2::Zero();
  Vec2 apply(const Vec2& x) const { return s * x + o; }
  Mat3 matrix() const {
    Mat3 T = Mat3::Identity();
    T.topLeftCorner<2, 2>() *= s;
    T.topRightCorner<2, 1>() = o;
    return T;
  }
};

struct HomographyCase {
  Mat3 H;  // truth, dst ~ H src
  Points2 src, dst;
};

// Two random cameras viewing the plane z = 0; n points on the plane in [-1,1]².
HomographyCase randomPlaneCase(Rng& rng, int n, bool uhd) {
  auto view = [&] {
    const Vec3 eye = rng.uniform(2, 10) *
                     Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0.3, 1)).normalized();
    return testing::makeCamera(eye, Vec3(rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 0),
                               rng.uniform(500, 3000), uhd ? 3840 : 1920, uhd ? 2160 : 1080);
  };
  const CameraModel a = view(), b = view();
  HomographyCase c;
  c.H = testing::planeHomography(a.projectionMatrix(), b.projectionMatrix());
  while (int(c.src.size()) < n) {
    const Vec3 X(rng.uniform(-1, 1), rng.uniform(-1, 1), 0);
    auto pa = a.project(X);
    auto pb = b.project(X);
    if (!pa || !pb) continue;
    c.src.push_back(*pa);
    c.dst.push_back(*pb);
  }
  return c;
}

void transform(HomographyCase& c, const Frame& fs, const Frame& fd) {
  for (Vec2& p : c.src) p = fs.apply(p);
  for (Vec2& p : c.dst) p = fd.apply(p);
  c.H = fd.matrix() * c.H * fs.matrix().inverse();
}

double spread(const Points2& pts) {
  Vec2 c = Vec2::Zero();
  for (const Vec2& p : pts) c += p / double(pts.size());
  double s = 0;
  for (const Vec2& p : pts) s += (p - c).norm() / double(pts.size());
  return s;
}

// Structural sanity of any returned homography fit.
bool saneFit(const HomographyFit& f, std::string& why) {
  if (!f.H.allFinite() || !std::isfinite(f.condition) || !std::isfinite(f.rms)) {
    why = "non-finite result";
    return false;
  }
  if (std::abs(f.H.norm() - 1) > 1e-12 || f.H(2, 2) < 0) {
    why = "H not normalised";
    return false;
  }
  return true;
}

// Max transfer difference at the data points and midpoints of consecutive ones, each
// relative to the dst spread plus that point's distance from the dst centroid.
double relativeTransferError(const Mat3& H, const HomographyCase& c, const Points2& truth_dst) {
  Vec2 centroid = Vec2::Zero();
  for (const Vec2& p : truth_dst) centroid += p / double(truth_dst.size());
  const double s = spread(truth_dst);
  double worst = 0;
  for (std::size_t i = 0; i < c.src.size(); ++i) {
    const Vec2 mid = 0.5 * (c.src[i] + c.src[(i + 1) % c.src.size()]);
    for (const Vec2& p : {c.src[i], mid}) {
      auto want = applyHomography(c.H, p);
      auto got = applyHomography(H, p);
      if (!want) continue;
      if (!got) return INFINITY;
      worst = std::max(worst, (*got - *want).norm() / (s + (*want - centroid).norm()));
    }
  }
  return worst;
}

// Exact data: solved and correct, or a typed error (when must_solve is false).
void checkExact(Tally& t, const HomographyCase& c, bool must_solve, const char* label) {
  ++t.cases;
  // Every fourth case with four points goes through the closed-form 4-point solve.
  const bool four = c.src.size() == 4 && t.cases % 4 == 0;
  Result<HomographyFit> fit = fail(ErrorCode::kInvalidInput, "unset");
  if (four) {
    auto H = homographyFrom4({c.src[0], c.src[1], c.src[2], c.src[3]},
                             {c.dst[0], c.dst[1], c.dst[2], c.dst[3]});
    if (H)
      fit = HomographyFit{*H, 1, 0, 0};
    else
      fit = tl::unexpected(H.error());
  } else {
    fit = (t.cases % 3 == 0) ? fitHomographyDlt(c.src, c.dst) : fitHomography(c.src, c.dst);
  }
  if (!fit) {
    ++t.refused;
    if (must_solve) t.fail(std::string(label) + ": refused " + describe(fit.error()));
    return;
  }
  ++t.solved;
  std::string why;
  if (!saneFit(*fit, why)) return t.fail(std::string(label) + ": " + why);
  const double err = relativeTransferError(fit->H, c, c.dst);
  if (!(err <= kRelTol)) {
    std::ostringstream os;
    os << label << ": relative transfer error " << err << " (condition " << fit->condition << ", n "
       << c.src.size() << ")";
    t.fail(os.str());
  }
}

// A typed error is the only acceptable outcome.
template <class R>
void requireError(Tally& t, const R& r, std::initializer_list<ErrorCode> allowed,
                  const char* label) {
  ++t.cases;
  if (r) return t.fail(std::string(label) + ": returned a result for invalid input");
  ++t.refused;
  for (ErrorCode code : allowed) {
    if (r.error().code == code) return;
  }
  t.fail(std::string(label) + ": unexpected error " + describe(r.error()));
}

TEST(StressEstimation, HomographyRandomExact) {
  Tally t{"homography random exact (normal, 4K, 1e4 offsets, scales)"};
  Rng rng(101);
  const int cases = 30000 / kCaseDivisor;
  for (int i = 0; i < cases; ++i) {
    const int n = rng.chance(0.3) ? 4 : rng.integer(5, 60);
    HomographyCase c = randomPlaneCase(rng, n, rng.chance(0.5));
    // Either 1e4 px offsets or rescaling (combined, offsets would swamp tiny scales
    // and the test data itself would lose its digits).
    Frame fs, fd;
    if (rng.chance(0.5)) {
      fs.o = 1e4 * Vec2(rng.uniform(-1, 1), rng.uniform(-1, 1));
      fd.o =
          rng.chance(0.5) ? Vec2(1e4 * Vec2(rng.uniform(-1, 1), rng.uniform(-1, 1))) : Vec2::Zero();
    } else if (rng.chance(0.4)) {
      fs.s = rng.logUniform(-8, 8);
      fd.s = rng.logUniform(-8, 8);
    }
    transform(c, fs, fd);
    // Random planar views can put three of four points nearly on a line; refusal
    // is then legitimate, a wrong answer is not.
    checkExact(t, c, false, "random");
  }
  // Refusals must stay rare for random views (they are only near-degenerate by chance).
  EXPECT_LT(t.refused, t.cases / 50);
}

TEST(StressEstimation, HomographyNoisy) {
  Tally t{"homography noisy (sigma 0.05..2 px)"};
  Rng rng(202);
  const int cases = 15000 / kCaseDivisor;
  for (int i = 0; i < cases; ++i) {
    ++t.cases;
    const int n = rng.integer(8, 200);
    // Points spread over a large part of both images: random src in a 4K frame.
    const double sigma = rng.logUniform(std::log10(0.05), std::log10(2.0));
    HomographyCase c = randomPlaneCase(rng, n, true);
    const Points2 truth = c.dst;
    std::normal_distribution<double> g(0, sigma);
    for (Vec2& p : c.dst) p += Vec2(g(rng.gen), g(rng.gen));
    auto fit = fitHomography(c.src, c.dst);
    if (!fit) {
      ++t.refused;
      t.fail("refused noisy general data: " + describe(fit.error()));
      continue;
    }
    ++t.solved;
    std::string why;
    if (!saneFit(*fit, why)) {
      t.fail(why);
      continue;
    }
    double worst = 0;
    for (int k = 0; k < n; ++k) {
      auto p = applyHomography(fit->H, c.src[k]);
      worst = p ? std::max(worst, (*p - truth[k]).norm()) : INFINITY;
    }
    // Near-degenerate random views amplify noise beyond the first-order bound; they
    // announce themselves through the condition number.
    if (fit->condition > 1e4) continue;
    if (!(worst <= 8 * sigma) || !(fit->rms <= 3.5 * sigma)) {
      std::ostringstream os;
      os << "n " << n << " sigma " << sigma << ": max error " << worst << ", rms " << fit->rms
         << ", condition " << fit->condition;
      t.fail(os.str());
    }
  }
}

TEST(StressEstimation, HomographyAdversarial) {
  Tally t{"homography adversarial"};
  Rng rng(303);
  const int rounds = 3000 / kCaseDivisor;
  const auto degenerate = {ErrorCode::kDegenerate, ErrorCode::kIllConditioned};
  for (int i = 0; i < rounds; ++i) {
    const int n = rng.integer(4, 40);
    const HomographyCase base = randomPlaneCase(rng, n, rng.chance(0.5));

    // All src points on one line (their images then lie on one line too).
    {
      HomographyCase c = base;
      const Vec2 a = c.src[0], d = Vec2(rng.uniform(-1, 1), rng.uniform(-1, 1)).normalized();
      for (Vec2& p : c.src) p = a + rng.uniform(-500, 500) * d;
      for (std::size_t k = 0; k < c.src.size(); ++k) {
        c.dst[k] = applyHomography(c.H, c.src[k]).value_or(Vec2(0, 0));
      }
      requireError(t, fitHomography(c.src, c.dst), degenerate, "collinear");
      if (n == 4) {
        requireError(t,
                     homographyFrom4({c.src[0], c.src[1], c.src[2], c.src[3]},
                                     {c.dst[0], c.dst[1], c.dst[2], c.dst[3]}),
                     degenerate, "collinear 4");
      }
    }
    // Near-collinear: every other point lifted off the line by 10^-k of the extent.
    {
      HomographyCase c = base;
      const Vec2 a = c.src[0], d = Vec2(rng.uniform(-1, 1), rng.uniform(-1, 1)).normalized();
      const Vec2 normal(-d.y(), d.x());
      const double lift = 1000 * rng.logUniform(-13, -1);
      for (std::size_t k = 0; k < c.src.size(); ++k) {
        c.src[k] =
            a + rng.uniform(-500, 500) * d + (k % 2 ? lift * rng.uniform(0.5, 1) : 0) * normal;
        c.dst[k] = applyHomography(c.H, c.src[k]).value_or(Vec2(0, 0));
      }
      checkExact(t, c, false, "near-collinear");
    }
    // Three of four points on a line.
    {
      std::array<Vec2, 4> s{base.src[0], base.src[1], Vec2::Zero(), base.src[3 % n]};
      s[2] = s[0] + rng.uniform(-2, 2) * (s[1] - s[0]);
      std::array<Vec2, 4> d;
      for (int k = 0; k < 4; ++k) d[k] = applyHomography(base.H, s[k]).value_or(Vec2(0, 0));
      requireError(t, homographyFrom4(s, d), degenerate, "three collinear");
      requireError(t, fitHomography(s, d), degenerate, "three collinear (fit)");
    }
    // Duplicates: with >= 4 distinct points in general position still exact; with
    // fewer than 4 distinct points an error.
    {
      HomographyCase c = base;
      const int copies = rng.integer(1, 20);
      for (int k = 0; k < copies; ++k) {
        const int j = rng.integer(0, n - 1);
        c.src.push_back(c.src[j]);
        c.dst.push_back(c.dst[j]);
      }
      checkExact(t, c, false, "duplicates");
      HomographyCase few;
      few.H = base.H;
      const int distinct = rng.integer(1, 3);
      for (int k = 0; k < 4 + copies; ++k) {
        few.src.push_back(base.src[k % distinct]);
        few.dst.push_back(base.dst[k % distinct]);
      }
      requireError(t, fitHomography(few.src, few.dst), degenerate, "few distinct");
    }
    // NaN / Inf anywhere.
    {
      HomographyCase c = base;
      Points2& side = rng.chance(0.5) ? c.src : c.dst;
      side[rng.integer(0, n - 1)][rng.integer(0, 1)] = rng.bad();
      requireError(t, fitHomography(c.src, c.dst), {ErrorCode::kInvalidInput}, "non-finite");
      requireError(t, fitHomographyDlt(c.src, c.dst), {ErrorCode::kInvalidInput}, "non-finite");
      if (n == 4) {
        requireError(t,
                     homographyFrom4({c.src[0], c.src[1], c.src[2], c.src[3]},
                                     {c.dst[0], c.dst[1], c.dst[2], c.dst[3]}),
                     {ErrorCode::kInvalidInput}, "non-finite 4");
      }
      requireError(t, refineHomography(Mat3::Constant(rng.bad()), base.src, base.dst),
                   {ErrorCode::kInvalidInput}, "non-finite H0");
    }
    // Huge coordinates: beyond 1e100 refused, 1e40..1e90 scale solved exactly or refused.
    {
      HomographyCase c = base;
      transform(c, Frame{rng.logUniform(101, 300), Vec2::Zero()}, Frame{});
      requireError(t, fitHomography(c.src, c.dst), {ErrorCode::kInvalidInput}, "huge");
      HomographyCase d = base;
      transform(d, Frame{rng.logUniform(40, 90), Vec2::Zero()},
                Frame{rng.logUniform(-90, -40), Vec2::Zero()});
      // Scale invariance: solvable exactly when the unscaled data are.
      checkExact(t, d, fitHomography(base.src, base.dst).has_value(), "scaled by 1e±40..90");
    }
    // A point near the vanishing line of H: its image is huge (up to ~1e15 px).
    {
      HomographyCase c = base;
      const Vec3 l = c.H.row(2).transpose();  // w = l · (x, y, 1) vanishes on this line
      const Vec2 normal = l.head<2>().normalized();
      const Vec2 foot = -l.z() * l.head<2>() / l.head<2>().squaredNorm();
      const Vec2 p = foot + rng.uniform(-1000, 1000) * Vec2(-normal.y(), normal.x()) +
                     1000 * rng.logUniform(-12, -1) * normal;
      auto q = applyHomography(c.H, p);
      if (q) {
        c.src.push_back(p);
        c.dst.push_back(*q);
        checkExact(t, c, false, "near infinity");
      }
    }
    // Sizes and counts.
    {
      const Points2 three(base.src.begin(), base.src.begin() + 3);
      requireError(t, fitHomography(three, three), {ErrorCode::kTooFewPoints}, "three points");
      const Points2 shorter(base.dst.begin(), base.dst.end() - 1);
      requireError(t, fitHomography(base.src, shorter),
                   {ErrorCode::kInvalidInput, ErrorCode::kTooFewPoints}, "size mismatch");
    }
  }
}

// --- projection matrix -----------------------------------------------------------

struct ProjectionCase {
  CameraModel cam;
  Points3 X;
  Points2 x;
};

CameraModel randomCamera(Rng& rng, const Vec3& look_at, bool uhd) {
  const Vec3 eye = look_at + rng.uniform(3, 15) * rng.unit();
  CameraModel cam = testing::makeCamera(eye, look_at + rng.inCube(0.3), rng.uniform(400, 4000),
                                        uhd ? 3840 : 1920, uhd ? 2160 : 1080);
  cam.K.cx += rng.uniform(-200, 200);
  cam.K.skew = rng.uniform(-2, 2);
  return cam;
}

// Points in an oriented box around `center` with extents (1, 1, thickness).
ProjectionCase randomProjectionCase(Rng& rng, int n, double thickness, const Vec3& center) {
  ProjectionCase c;
  c.cam = randomCamera(rng, center, rng.chance(0.5));
  const Mat3 R = rng.rotation();
  while (int(c.X.size()) < n) {
    const Vec3 X =
        center + R * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), thickness * rng.uniform(-1, 1));
    // Pixels from the 3x4 matrix directly: points behind the camera are valid data too.
    auto p = projectWith(c.cam.projectionMatrix(), X);
    if (!p) continue;
    c.X.push_back(X);
    c.x.push_back(*p);
  }
  return c;
}

double matrixDistance(const Mat34& A, const Mat34& B) {
  const Mat34 a = A / A.norm(), b = B / B.norm();
  return std::min((a - b).norm(), (a + b).norm());
}

// Decomposition against the true camera, tolerance relative to the sizes involved.
bool decompositionMatches(const KRt& got, const CameraModel& cam, double tol) {
  const double kscale = std::max({cam.K.fx, cam.K.fy, std::abs(cam.K.cx), std::abs(cam.K.cy)});
  const Mat3 dK = got.K.matrix() - cam.K.matrix();
  return got.K.fx > 0 && got.K.fy > 0 && dK.allFinite() && dK.norm() <= tol * kscale &&
         (got.pose.R - cam.pose.R).norm() <= tol * kscale / std::min(cam.K.fx, cam.K.fy) &&
         std::abs(got.pose.R.determinant() - 1) < 1e-9 &&
         (got.pose.t - cam.pose.t).norm() <=
             tol * kscale / std::min(cam.K.fx, cam.K.fy) * (1 + cam.pose.t.norm());
}

void checkProjection(Tally& t, const ProjectionCase& c, bool must_solve, const char* label) {
  ++t.cases;
  auto fit = fitProjectionMatrix(c.X, c.x);
  if (!fit) {
    ++t.refused;
    if (must_solve) t.fail(std::string(label) + ": refused " + describe(fit.error()));
    return;
  }
  ++t.solved;
  std::ostringstream os;
  os << label << " (n " << c.X.size() << ", condition " << fit->condition << "): ";
  if (!fit->P.allFinite() || !std::isfinite(fit->rms) || !std::isfinite(fit->condition)) {
    return t.fail(os.str() + "non-finite result");
  }
  const double dist = matrixDistance(fit->P, c.cam.projectionMatrix());
  if (!(dist <= kRelTol)) {
    os << "P differs from truth by " << dist;
    return t.fail(os.str());
  }
  auto krt = decomposeProjectionMatrix(fit->P);
  if (!krt) return t.fail(os.str() + "decomposition refused " + describe(krt.error()));
  if (!decompositionMatches(*krt, c.cam, 1e3 * kRelTol)) {
    os << "decomposition wrong: fx " << krt->K.fx << " vs " << c.cam.K.fx;
    t.fail(os.str());
  }
}

TEST(StressEstimation, ProjectionMatrix) {
  Tally t{"projection matrix (random, 4K, 1e4 offsets, coplanar, degenerate)"};
  Rng rng(404);
  const int rounds = 4000 / kCaseDivisor;
  const ProjectionOptions defaults;
  for (int i = 0; i < rounds; ++i) {
    const int n = rng.integer(6, 60);
    const Vec3 center = rng.chance(0.5) ? rng.inCube(1) : 1e4 * rng.unit();
    // General position (thick): always solved, correct.
    checkProjection(t, randomProjectionCase(rng, n, rng.uniform(0.2, 1), center), true, "general");
    // Thin slabs from 1e-7 to 1e-1: below coplanar_ratio/3 the spread ratio is certain
    // to be under the limit -> kCoplanar required; above, solved correctly or refused.
    const double thickness = rng.logUniform(-7, -1);
    const ProjectionCase slab = randomProjectionCase(rng, std::max(n, 12), thickness, center);
    if (thickness < defaults.coplanar_ratio / 3) {
      requireError(t, fitProjectionMatrix(slab.X, slab.x), {ErrorCode::kCoplanar}, "thin slab");
    } else {
      checkProjection(t, slab, false, "slab");
    }
    // Exactly coplanar and collinear.
    ProjectionCase flat = randomProjectionCase(rng, n, 0, center);
    requireError(t, fitProjectionMatrix(flat.X, flat.x), {ErrorCode::kCoplanar}, "coplanar");
    for (std::size_t k = 0; k < flat.X.size(); ++k) {
      flat.X[k] = center + rng.uniform(-1, 1) * Vec3(0.3, -0.5, 0.8);
      flat.x[k] = projectWith(flat.cam.projectionMatrix(), flat.X[k]).value_or(Vec2::Zero());
    }
    requireError(t, fitProjectionMatrix(flat.X, flat.x),
                 {ErrorCode::kCoplanar, ErrorCode::kDegenerate}, "collinear");
    // Fewer than 6 distinct points, duplicated up to n.
    ProjectionCase dup = randomProjectionCase(rng, 5, 1, center);
    for (int k = 0; k < n; ++k) {
      dup.X.push_back(dup.X[k % 5]);
      dup.x.push_back(dup.x[k % 5]);
    }
    requireError(t, fitProjectionMatrix(dup.X, dup.x), {ErrorCode::kDegenerate}, "duplicates");
    // Non-finite or huge input, too few points, mismatched sizes.
    ProjectionCase bad = randomProjectionCase(rng, n, 1, center);
    if (rng.chance(0.5)) {
      bad.X[rng.integer(0, n - 1)][rng.integer(0, 2)] = rng.bad();
    } else {
      bad.x[rng.integer(0, n - 1)][rng.integer(0, 1)] = rng.chance(0.5) ? rng.bad() : 1e200;
    }
    requireError(t, fitProjectionMatrix(bad.X, bad.x), {ErrorCode::kInvalidInput}, "non-finite");
    requireError(t, fitProjectionMatrix(std::span(bad.X).first(5), std::span(bad.x).first(5)),
                 {ErrorCode::kTooFewPoints, ErrorCode::kInvalidInput}, "five points");
  }
}

TEST(StressEstimation, Decomposition) {
  Tally t{"RQ decomposition (random cameras, scales, signs, singular)"};
  Rng rng(505);
  const int cases = 20000 / kCaseDivisor;
  for (int i = 0; i < cases; ++i) {
    CameraModel cam;
    cam.K.fx = rng.logUniform(1, 4.5);
    cam.K.fy = cam.K.fx * rng.uniform(0.5, 2);
    cam.K.cx = rng.uniform(-1e4, 1e4);
    cam.K.cy = rng.uniform(-1e4, 1e4);
    cam.K.skew = rng.uniform(-0.01, 0.01) * cam.K.fx;
    cam.pose.R = rng.rotation();
    cam.pose.t = rng.chance(0.5) ? rng.inCube(10) : 1e4 * rng.unit();
    const double scale = (rng.chance(0.5) ? -1 : 1) * rng.logUniform(-150, 150);
    ++t.cases;
    auto krt = decomposeProjectionMatrix(scale * cam.projectionMatrix());
    if (!krt) {
      ++t.refused;
      t.fail("valid camera refused: " + describe(krt.error()));
    } else if (++t.solved; !decompositionMatches(*krt, cam, 1e-9)) {
      std::ostringstream os;
      os << "fx " << krt->K.fx << " vs " << cam.K.fx << ", |dR| "
         << (krt->pose.R - cam.pose.R).norm() << ", |dt| " << (krt->pose.t - cam.pose.t).norm();
      t.fail(os.str());
    }
    // Rank-deficient left block (camera at infinity) and non-finite matrices.
    Mat34 singular = cam.projectionMatrix();
    const int c0 = rng.integer(0, 2), c1 = (c0 + 1) % 3, c2 = (c0 + 2) % 3;
    singular.col(c0) =
        rng.uniform(-2, 2) * singular.col(c1) + rng.uniform(-2, 2) * singular.col(c2);
    requireError(t, decomposeProjectionMatrix(singular), {ErrorCode::kDegenerate}, "singular");
    Mat34 nan = cam.projectionMatrix();
    nan(rng.integer(0, 2), rng.integer(0, 3)) = rng.bad();
    requireError(t, decomposeProjectionMatrix(nan), {ErrorCode::kInvalidInput}, "non-finite P");
  }
}

// --- undistortion ------------------------------------------------------------------

// Smallest derivative of the radial profile r (1 + k1 r² + k2 r⁴ + k3 r⁶) on [0, r].
double minRadialSlope(const Distortion& d, double r) {
  double lowest = 1;
  for (int i = 0; i <= 200; ++i) {
    const double s = r * i / 200, s2 = s * s;
    lowest = std::min(lowest, 1 + 3 * d.k1 * s2 + 5 * d.k2 * s2 * s2 + 7 * d.k3 * s2 * s2 * s2);
  }
  return lowest;
}

TEST(StressEstimation, Undistort) {
  Tally t{"undistort (random lenses, 4K cameras, beyond the fold, NaN)"};
  Rng rng(606);
  const int cases = 30000 / kCaseDivisor;
  for (int i = 0; i < cases; ++i) {
    Distortion d;
    d.k1 = rng.uniform(-0.5, 0.5);
    d.k2 = rng.uniform(-0.3, 0.3);
    d.k3 = rng.uniform(-0.1, 0.1);
    d.p1 = rng.uniform(-0.01, 0.01);
    d.p2 = rng.uniform(-0.01, 0.01);
    const double r = rng.uniform(0, 1.2);
    const double phi = rng.uniform(0, 2 * M_PI);
    const Vec2 u(r * std::cos(phi), r * std::sin(phi));
    const Vec2 distorted = d.apply(u);
    ++t.cases;
    auto back = d.remove(distorted);
    // Inside the monotone part of the radial profile (with margin for the small
    // tangential terms) u is the physical preimage and must be recovered. Beyond
    // the fold another in-range preimage is the physical ray; either way apply()
    // must reproduce the input.
    // Margin: the tangential terms change the Jacobian by at most ~8 max|p| r.
    const double reach = 1.05 * r + 0.05;
    const bool monotone =
        minRadialSlope(d, reach) > 0.05 + 12 * std::max(std::abs(d.p1), std::abs(d.p2)) * reach;
    if (!back) {
      ++t.refused;
      if (back.error().code != ErrorCode::kNoConvergence || monotone) {
        t.fail("refused: " + describe(back.error()) + " r " + std::to_string(r));
      }
    } else {
      ++t.solved;
      const double reproduce = (d.apply(*back) - distorted).norm();
      if (!back->allFinite() || !(reproduce <= 1e-9 * (1 + distorted.norm())) ||
          (monotone && !((*back - u).norm() <= 1e-9 * (1 + r)))) {
        std::ostringstream os;
        os << "r " << r << " -> error " << (*back - u).norm() << ", reproduce " << reproduce;
        t.fail(os.str());
      }
    }
    // A 4K camera with this lens (when monotone over the field): undistortPixel of
    // the projection equals the ideal projection.
    if (monotone && i % 3 == 0) {
      CameraModel cam = randomCamera(rng, Vec3::Zero(), true);
      cam.dist = d;
      CameraModel ideal = cam;
      ideal.dist = Distortion{};
      const Vec3 dir = cam.pose.R.transpose() * Vec3(u.x(), u.y(), 1);
      const Vec3 X = cam.pose.center() + rng.uniform(0.5, 50) * dir;
      auto px = cam.project(X);
      auto want = ideal.project(X);
      ++t.cases;
      if (!px || !want) {
        t.fail("projection failed in front of the camera");
        continue;
      }
      auto got = cam.undistortPixel(*px);
      if (!got || !((*got - *want).norm() <= 1e-9 * (cam.K.fx + want->norm()))) {
        t.fail("undistortPixel wrong or refused");
      } else {
        ++t.solved;
      }
    }
    if (i % 10 == 0) {
      requireError(t, d.remove(Vec2(rng.bad(), 0.1)), {ErrorCode::kInvalidInput}, "NaN point");
    }
  }
}

}  // namespace
}  // namespace procam::geom
