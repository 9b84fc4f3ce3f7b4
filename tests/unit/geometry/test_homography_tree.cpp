// Tests for pipelines/geometry/homography_tree: projectors on a wall registered through
// camera views that each see a block of them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "geometry/homography_tree.hpp"
#include "unit/geometry/synthetic_views.hpp"
#include "unit/geometry/synthetic_wall.hpp"

namespace procam::geom {
namespace {

using testing::SyntheticWall;

// Projector -> wall collineations from the tree: the reference view (view 0) is the
// calibrated camera whose collineation with the wall is known.
std::vector<Mat3> onTheWall(const SyntheticWall& wall, const geom::CameraModel& reference,
                            const HomographyTree& tree) {
  const Mat3 image_to_wall = testing::wallToImage(wall, reference).inverse();
  std::vector<Mat3> out;
  for (const Mat3& P : tree.projector_to_reference) out.push_back(image_to_wall * P);
  return out;
}

TEST(HomographyTree, ExactMatchesGiveEveryProjectorThroughTheChain) {
  std::mt19937 rng(3);
  const SyntheticWall wall = testing::syntheticWall(3, 3, rng);
  const auto views = testing::blockViews(wall, 2, rng);
  ASSERT_EQ(views.size(), 4u);
  const auto matches = testing::viewMatches(wall, views, 32, 0.0, rng);
  for (bool refine : {false, true}) {
    auto tree =
        solveHomographyTree(matches, views.size(), wall.projectors.size(), {.refine = refine});
    ASSERT_TRUE(tree) << tree.error().message;
    // The far corner's projector is two views down the chain.
    EXPECT_EQ(tree->chain_views.front(), 1);
    EXPECT_GE(tree->chain_views.back(), 2);
    const Mat3 to_ref = testing::wallToImage(wall, views[0]);
    for (std::size_t p = 0; p < wall.projectors.size(); ++p) {
      const Mat3 truth = to_ref * wall.projectorToWall(p);
      // Exact data: double precision times the chain's conditioning, ~1e-7 px.
      EXPECT_LT(testing::maxTransferDifference(tree->projector_to_reference[p], truth, 1280, 800),
                1e-6)
          << "projector " << p << (refine ? ", refined" : ", chained");
    }
    EXPECT_LT(tree->rms_px, 1e-7);
  }
}

// A 4x4 wall seen by nine cameras, each on a 2x2 block, 0.1 px of noise on every node
// (a sampled node's scatter under the reference capture conditions): the seams meet
// [Chen02]'s scale of result (24 projectors, 0.55 px) and procamd's own target, 0.3 px
// RMS and 1 px at most, and the refinement beats the chain it starts from.
TEST(HomographyTree, GlobalRefinementKeepsSixteenProjectorsSeamless) {
  std::mt19937 rng(16);
  const SyntheticWall wall = testing::syntheticWall(4, 4, rng);
  const auto views = testing::blockViews(wall, 2, rng);
  ASSERT_EQ(views.size(), 9u);
  const double noise = 0.1;
  const auto matches = testing::viewMatches(wall, views, 8, noise, rng);
  auto chained = solveHomographyTree(matches, views.size(), 16, {.refine = false});
  auto refined = solveHomographyTree(matches, views.size(), 16);
  ASSERT_TRUE(chained) << chained.error().message;
  ASSERT_TRUE(refined) << refined.error().message;
  EXPECT_TRUE(refined->converged);
  const auto chain_seam = testing::seamError(wall, onTheWall(wall, views[0], *chained));
  const auto seam = testing::seamError(wall, onTheWall(wall, views[0], *refined));
  int deepest = 0;
  for (int d : refined->chain_views) deepest = std::max(deepest, d);
  std::printf(
      "[ figures  ] 16 projectors, 9 views (chains up to %d views), %zu links, %zu matches: "
      "residual %.4f px RMS (chain %.4f), seams over %ld points RMS %.4f px max %.4f px "
      "(chain: RMS %.4f max %.4f), %d iterations\n",
      deepest, refined->links, refined->matches, refined->rms_px, refined->chain_rms_px,
      seam.points, seam.rms_px, seam.max_px, chain_seam.rms_px, chain_seam.max_px,
      refined->iterations);
  EXPECT_GE(deepest, 3);
  EXPECT_GT(seam.points, 100000);
  EXPECT_LE(seam.rms_px, 0.3);
  EXPECT_LE(seam.max_px, 1.0);
  EXPECT_LT(seam.rms_px, chain_seam.rms_px);
  // The residual of a maximum-likelihood fit is the noise: sqrt(2) sigma per 2D match,
  // less a fraction for the fitted parameters (192 against ~1.7 million coordinates);
  // over ~870 000 matches its own sampling spread is ~1e-4 px.
  EXPECT_NEAR(refined->rms_px, noise * std::sqrt(2.0), 0.003);
  EXPECT_LT(refined->rms_px, refined->chain_rms_px);
}

TEST(HomographyTree, RejectsWhatCannotBeChained) {
  std::mt19937 rng(5);
  const SyntheticWall wall = testing::syntheticWall(3, 1, rng);
  const auto views = testing::blockViews(wall, 2, rng);  // two views
  auto matches = testing::viewMatches(wall, views, 32, 0.05, rng);
  ASSERT_TRUE(solveHomographyTree(matches, views.size(), 3));
  // A fourth projector nobody saw.
  auto unseen = solveHomographyTree(matches, views.size(), 4);
  ASSERT_FALSE(unseen);
  EXPECT_EQ(unseen.error().code, ErrorCode::kDegenerate);
  EXPECT_NE(unseen.error().message.find("projector 3"), std::string::npos);
  // The second view's sighting of the middle projector lost (and any of the right-hand
  // one by the first view): the right-hand projector is seen, but by an unlinked view.
  std::vector<ViewProjectorMatches> split;
  for (const auto& m : matches)
    if ((m.view == 0 && m.projector < 2) || (m.view == 1 && m.projector == 2)) split.push_back(m);
  auto cut = solveHomographyTree(split, views.size(), 3);
  ASSERT_FALSE(cut);
  EXPECT_EQ(cut.error().code, ErrorCode::kDegenerate);
  // Bad input.
  auto bad = matches;
  bad[0].view_px[0].x() = NAN;
  EXPECT_EQ(solveHomographyTree(bad, views.size(), 3).error().code, ErrorCode::kInvalidInput);
  bad = matches;
  bad[0].view_px.pop_back();
  EXPECT_EQ(solveHomographyTree(bad, views.size(), 3).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(solveHomographyTree(matches, 1, 3).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(solveHomographyTree(matches, views.size(), 3, {.reference_view = 2}).error().code,
            ErrorCode::kInvalidInput);
  // Collinear matches: the link's own collineation is undetermined.
  bad = matches;
  for (auto& p : bad[0].projector_px) p.y() = 400;
  EXPECT_FALSE(solveHomographyTree(bad, views.size(), 3));
}

}  // namespace
}  // namespace procam::geom
