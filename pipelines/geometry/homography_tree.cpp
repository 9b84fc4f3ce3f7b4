#include "geometry/homography_tree.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <queue>
#include <string>

#include "geometry/homography.hpp"
#include "geometry/normalization.hpp"

namespace procam::geom {
namespace {

using Sim2 = detail::Similarity<2>;

struct Link {
  std::size_t view = 0, projector = 0;
  std::vector<Vec2> projector_px, view_px;
  Mat3 H = Mat3::Identity();  // projector -> view pixels, this pair's own fit
};

// Residual statistics, view pixels, of projector -> reference `P` and view -> reference
// `G` over every match of the links.
void residuals(const std::vector<Link>& links, const std::vector<Mat3>& P,
               const std::vector<Mat3>& G, double& rms, double& max) {
  double sq = 0;
  std::size_t n = 0;
  max = 0;
  for (const Link& l : links) {
    const Mat3 M = G[l.view].inverse() * P[l.projector];
    for (std::size_t i = 0; i < l.projector_px.size(); ++i) {
      const Vec3 h = M * l.projector_px[i].homogeneous();
      const double e = (h.hnormalized() - l.view_px[i]).norm();
      sq += e * e;
      max = std::max(max, e);
      ++n;
    }
  }
  rms = n ? std::sqrt(sq / double(n)) : 0;
}

// Every collineation's 8 free entries: H = H0 (I + D) with D(2,2) = 0, so the scale
// stays fixed and the parameters start at zero around the current estimate.
constexpr int kFree = 8;
inline int row(int k) {
  return k / 3;
}
inline int col(int k) {
  return k % 3;
}

// One view's sighting of one projector in normalised coordinates.
struct Sample {
  Vec3 x;  // projector point, homogeneous, normalised
  Vec2 y;  // view point, normalised
};
struct Block {
  std::size_t projector = 0;
  int view_param = -1;  // index of the view's parameter block; -1 for the reference view
  double to_px = 1;     // normalised view units -> view pixels
  double weight = 1;    // each sample stands for weight^2 matches
  std::vector<Sample> samples;
};

// Levenberg-Marquardt on the normal equations: each residual touches one projector's
// and at most one view's 8 parameters, so JᵀJ is accumulated per link in 16x16 pieces
// instead of forming the dense Jacobian (a 16-projector wall's has ~30k rows).
struct Refinement {
  std::vector<Mat3>& P;  // projector -> reference, normalised frames
  std::vector<Mat3>& Q;  // reference -> view, normalised frames (per view block)
  const std::vector<Block>& blocks;
  int iterations = 0;
  bool converged = false;

  std::size_t parameters() const { return kFree * (P.size() + Q.size()); }
  std::size_t viewOffset(int v) const { return kFree * (P.size() + std::size_t(v)); }

  double cost(const std::vector<Mat3>& p, const std::vector<Mat3>& q) const {
    double sum = 0;
    for (const Block& b : blocks) {
      const Mat3 M = b.view_param < 0 ? p[b.projector] : Mat3(q[b.view_param] * p[b.projector]);
      for (const Sample& s : b.samples) {
        const Vec3 h = M * s.x;
        sum += ((h.hnormalized() - s.y) * (b.to_px * b.weight)).squaredNorm();
      }
    }
    return sum;
  }

  void normalEquations(Eigen::MatrixXd& A, Eigen::VectorXd& g) const {
    const std::size_t n = parameters();
    A.setZero(n, n);
    g.setZero(n);
    for (const Block& b : blocks) {
      const bool has_view = b.view_param >= 0;
      const Mat3 Qv = has_view ? Q[b.view_param] : Mat3::Identity();
      const Mat3 QP = Qv * P[b.projector];
      Eigen::Matrix<double, 16, 16> local = Eigen::Matrix<double, 16, 16>::Zero();
      Eigen::Matrix<double, 16, 1> grad = Eigen::Matrix<double, 16, 1>::Zero();
      Eigen::Matrix<double, 2, 16> J;
      for (const Sample& s : b.samples) {
        const Vec3 Px = P[b.projector] * s.x;
        const Vec3 h = Qv * Px;
        const Vec2 y = h.hnormalized();
        // d(hnormalized)/dh, scaled to view pixels.
        Eigen::Matrix<double, 2, 3> dpi;
        dpi << 1, 0, -y.x(), 0, 1, -y.y();
        dpi *= b.to_px * b.weight / h.z();
        for (int k = 0; k < kFree; ++k) {
          // h = Q (I + E) P (I + D) x at D = E = 0: dh/dD_ij = (Q P)[:, i] x_j and
          // dh/dE_ij = Q[:, i] (P x)_j.
          J.col(k) = dpi * (QP.col(row(k)) * s.x(col(k)));
          J.col(kFree + k) = has_view ? Vec2(dpi * (Qv.col(row(k)) * Px(col(k)))) : Vec2::Zero();
        }
        const Vec2 r = (y - s.y) * (b.to_px * b.weight);
        local.noalias() += J.transpose() * J;
        grad.noalias() += J.transpose() * r;
      }
      const std::size_t po = kFree * b.projector;
      A.block<kFree, kFree>(po, po) += local.topLeftCorner<kFree, kFree>();
      g.segment<kFree>(po) += grad.head<kFree>();
      if (has_view) {
        const std::size_t vo = viewOffset(b.view_param);
        A.block<kFree, kFree>(vo, vo) += local.bottomRightCorner<kFree, kFree>();
        A.block<kFree, kFree>(po, vo) += local.topRightCorner<kFree, kFree>();
        A.block<kFree, kFree>(vo, po) += local.bottomLeftCorner<kFree, kFree>();
        g.segment<kFree>(vo) += grad.tail<kFree>();
      }
    }
  }

  static Mat3 updated(const Mat3& H, const Eigen::VectorXd& step, std::size_t offset) {
    Mat3 D = Mat3::Zero();
    for (int k = 0; k < kFree; ++k) D(row(k), col(k)) = step(Eigen::Index(offset) + k);
    return detail::canonicalCollineation(H * (Mat3::Identity() + D));
  }

  void run(int max_iterations) {
    double current = cost(P, Q);
    double lambda = 1e-3;
    Eigen::MatrixXd A;
    Eigen::VectorXd g;
    for (iterations = 0; iterations < max_iterations;) {
      normalEquations(A, g);
      ++iterations;
      bool accepted = false, tried = false;
      while (!accepted && lambda < 1e12) {
        Eigen::MatrixXd damped = A;
        damped.diagonal() += lambda * A.diagonal().cwiseMax(1e-12);
        const Eigen::VectorXd step = damped.ldlt().solve(-g);
        if (!step.allFinite()) {
          lambda *= 10;
          continue;
        }
        tried = true;
        std::vector<Mat3> p(P.size()), q(Q.size());
        for (std::size_t i = 0; i < P.size(); ++i) p[i] = updated(P[i], step, kFree * i);
        for (std::size_t v = 0; v < Q.size(); ++v) q[v] = updated(Q[v], step, viewOffset(int(v)));
        const double next = cost(p, q);
        if (next < current) {
          const double gain = (current - next) / std::max(current, 1e-300);
          P = std::move(p);
          Q = std::move(q);
          current = next;
          lambda = std::max(lambda / 10, 1e-12);
          accepted = true;
          if (gain < 1e-10 || step.norm() < 1e-12) {
            converged = true;
            return;
          }
        } else {
          lambda *= 10;
        }
      }
      if (!accepted) {
        // No step lowers the cost: at the minimum to working precision, unless no
        // finite step could be solved for at all (the equations were not).
        converged = tried;
        return;
      }
    }
  }
};

}  // namespace

Result<HomographyTree> solveHomographyTree(std::span<const ViewProjectorMatches> matches,
                                           std::size_t views, std::size_t projectors,
                                           const HomographyTreeOptions& options) {
  if (options.reference_view >= views)
    return fail(ErrorCode::kInvalidInput, "homography tree: the reference view is out of range");
  if (projectors == 0) return fail(ErrorCode::kInvalidInput, "homography tree: no projectors");
  // Join the entries of each view/projector pair.
  std::map<std::pair<std::size_t, std::size_t>, Link> joined;
  for (const ViewProjectorMatches& m : matches) {
    if (m.view >= views || m.projector >= projectors)
      return fail(ErrorCode::kInvalidInput, "homography tree: a view or projector out of range");
    if (m.projector_px.size() != m.view_px.size())
      return fail(ErrorCode::kInvalidInput, "homography tree: match lists of different lengths");
    if (!detail::allFiniteAndBounded<2>(m.projector_px) ||
        !detail::allFiniteAndBounded<2>(m.view_px))
      return fail(ErrorCode::kInvalidInput, "homography tree: non-finite coordinates");
    Link& l = joined[{m.view, m.projector}];
    l.view = m.view;
    l.projector = m.projector;
    l.projector_px.insert(l.projector_px.end(), m.projector_px.begin(), m.projector_px.end());
    l.view_px.insert(l.view_px.end(), m.view_px.begin(), m.view_px.end());
  }
  auto view_name = [&](std::size_t v) {
    return v < options.view_names.size() ? options.view_names[v] : "view " + std::to_string(v);
  };
  auto projector_name = [&](std::size_t p) {
    return p < options.projector_names.size() ? options.projector_names[p]
                                              : "projector " + std::to_string(p);
  };
  const std::size_t min_matches = std::max<std::size_t>(options.min_matches, 4);
  std::vector<Link> links;
  for (auto& [key, l] : joined) {
    if (l.projector_px.size() < min_matches) continue;
    auto fit = fitHomography(l.projector_px, l.view_px);
    if (!fit) {
      return fail(fit.error().code, "homography tree: " + view_name(l.view) + " seeing " +
                                        projector_name(l.projector) + ": " + fit.error().message);
    }
    l.H = fit->H;
    links.push_back(std::move(l));
  }

  // The tree: Prim's maximum spanning tree by match count from the reference view, so
  // each collineation is chained through the best-seen links.
  const std::size_t nodes = views + projectors;  // views first, then projectors
  std::vector<std::vector<std::size_t>> touching(nodes);
  for (std::size_t i = 0; i < links.size(); ++i) {
    touching[links[i].view].push_back(i);
    touching[views + links[i].projector].push_back(i);
  }
  std::vector<Mat3> P(projectors, Mat3::Identity()), G(views, Mat3::Identity());
  std::vector<int> depth(nodes, -1);
  std::priority_queue<std::pair<std::size_t, std::size_t>> frontier;  // (matches, link)
  auto reach = [&](std::size_t node) {
    for (std::size_t i : touching[node]) frontier.push({links[i].projector_px.size(), i});
  };
  depth[options.reference_view] = 0;
  reach(options.reference_view);
  while (!frontier.empty()) {
    const Link& l = links[frontier.top().second];
    frontier.pop();
    const std::size_t pn = views + l.projector;
    if (depth[l.view] >= 0 && depth[pn] < 0) {
      P[l.projector] = detail::canonicalCollineation(G[l.view] * l.H);
      depth[pn] = depth[l.view] + 1;
      reach(pn);
    } else if (depth[pn] >= 0 && depth[l.view] < 0) {
      G[l.view] = detail::canonicalCollineation(P[l.projector] * l.H.inverse());
      depth[l.view] = depth[pn];
      reach(l.view);
    }
  }
  HomographyTree out;
  for (std::size_t p = 0; p < projectors; ++p) {
    if (depth[views + p] < 0) {
      return fail(ErrorCode::kDegenerate, "homography tree: " + projector_name(p) +
                                              " is seen (with at least " +
                                              std::to_string(min_matches) + " matches) by no " +
                                              (options.view_names.empty() ? "view" : "camera") +
                                              " linked to " + view_name(options.reference_view));
    }
    out.chain_views.push_back(depth[views + p]);
  }
  out.links = links.size();
  for (const Link& l : links) out.matches += l.projector_px.size();
  residuals(links, P, G, out.chain_rms_px, out.chain_max_px);
  out.rms_px = out.chain_rms_px;
  out.max_px = out.chain_max_px;

  if (options.refine && !links.empty()) {
    // Hartley frames: every projector's and view's points, the reference's for the
    // common frame, so every entry of the normal equations has a similar scale.
    std::vector<Sim2> tp(projectors), tv(views);
    std::vector<std::vector<Vec2>> ppts(projectors), vpts(views);
    for (const Link& l : links) {
      ppts[l.projector].insert(ppts[l.projector].end(), l.projector_px.begin(),
                               l.projector_px.end());
      vpts[l.view].insert(vpts[l.view].end(), l.view_px.begin(), l.view_px.end());
    }
    for (std::size_t p = 0; p < projectors; ++p) {
      auto t = detail::hartley<2>(ppts[p]);
      if (!t)
        return fail(ErrorCode::kDegenerate,
                    "homography tree: " + projector_name(p) + ": " + t.error().message);
      tp[p] = *t;
    }
    std::vector<int> view_param(views, -1);
    std::vector<Mat3> Qn;
    for (std::size_t v = 0; v < views; ++v) {
      if (vpts[v].empty()) continue;
      auto t = detail::hartley<2>(vpts[v]);
      if (!t)
        return fail(ErrorCode::kDegenerate,
                    "homography tree: " + view_name(v) + ": " + t.error().message);
      tv[v] = *t;
    }
    const Mat3 Tref = tv[options.reference_view].matrix();
    const Mat3 TrefInv = tv[options.reference_view].inverseMatrix();
    std::vector<Mat3> Pn(projectors);
    for (std::size_t p = 0; p < projectors; ++p)
      Pn[p] = detail::canonicalCollineation(Tref * P[p] * tp[p].inverseMatrix());
    for (std::size_t v = 0; v < views; ++v) {
      if (v == options.reference_view || depth[v] < 0) continue;
      view_param[v] = int(Qn.size());
      Qn.push_back(detail::canonicalCollineation(tv[v].matrix() * G[v].inverse() * TrefInv));
    }
    std::vector<Block> blocks;
    for (const Link& l : links) {
      Block b;
      b.projector = l.projector;
      b.view_param = view_param[l.view];
      b.to_px = 1 / tv[l.view].scale;
      // The link's matches enter through its own fit: with y_i = H x_i + e_i and H the
      // link's least-squares collineation, sum |f(x_i) - y_i|^2 = sum |f(x_i) - H x_i|^2
      // + const to first order (the cross term is the link fit's own normal equations).
      // So `keep` of its points, each standing for n / keep, carry what all n would,
      // without the noise of the ones left out.
      const std::size_t n = l.projector_px.size();
      const std::size_t keep = std::min(n, std::max<std::size_t>(options.refine_matches, 4));
      b.weight = std::sqrt(double(n) / double(keep));
      const std::size_t stride = n / keep;
      for (std::size_t k = 0; k < keep; ++k) {
        // One point per stride, its place in the stride varied so that rows of nodes
        // are not sampled in the same column.
        const std::size_t i =
            std::min(n - 1, k * n / keep + (k * 7919) % std::max<std::size_t>(stride, 1));
        const Vec2 fitted = (l.H * l.projector_px[i].homogeneous()).hnormalized();
        b.samples.push_back(
            {tp[l.projector].apply(l.projector_px[i]).homogeneous(), tv[l.view].apply(fitted)});
      }
      blocks.push_back(std::move(b));
    }
    Refinement lm{Pn, Qn, blocks};
    lm.run(options.max_iterations);
    out.iterations = lm.iterations;
    out.converged = lm.converged;
    for (std::size_t p = 0; p < projectors; ++p)
      P[p] = detail::canonicalCollineation(TrefInv * Pn[p] * tp[p].matrix());
    for (std::size_t v = 0; v < views; ++v) {
      if (view_param[v] >= 0)
        G[v] =
            detail::canonicalCollineation(TrefInv * Qn[view_param[v]].inverse() * tv[v].matrix());
    }
    residuals(links, P, G, out.rms_px, out.max_px);
  }
  for (const Mat3& H : P) {
    if (!H.allFinite())
      return fail(ErrorCode::kNoConvergence, "homography tree: non-finite result");
  }
  out.projector_to_reference = std::move(P);
  out.view_to_reference = std::move(G);
  return out;
}

}  // namespace procam::geom
