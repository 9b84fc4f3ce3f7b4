#pragma once
// Adaptive pattern count — skip what the scene does not need ([Raskar02] §4.1.4: a coarse
// 16x12 binary-coded pass). A coarse Gray pass decides whether the surface is planar
// (one camera sees a plane through the projector as a homography, [Raskar02] §3.2.5); a
// planar surface stops there with enough correspondences for that homography, and
// only a non-planar one gets the full-resolution set.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "structured_light/decoder.hpp"
#include "structured_light/pattern_set.hpp"

namespace procam::sl {

struct AdaptiveOptions {
  PatternOptions full;  // full set for non-planar surfaces (width/height = projector)
  int blocks_x = 16, blocks_y = 12;
  // Planar when the coarse correspondences fit one homography to within this
  // fraction of the block size, RMS in projector pixels (block centroids are biased
  // by perspective to second order, so this is not a pixel-level test).
  double planar_tolerance = 0.015;
  // ... and at least this many camera pixels (a coarse camera sees a block's centre
  // only to a fraction of its pixel), converted at the view's projector-per-camera
  // pixel scale.
  double camera_tolerance_px = 0.35;
  DecodeOptions decode;
  // Camera pixel -> undistorted pixel (lens distortion breaks the homography);
  // identity when empty.
  std::function<Vec2(const Vec2&)> undistort;
};

struct PlanarityTest {
  bool planar = false;
  Mat3 H = Mat3::Identity();  // camera (undistorted) -> projector
  double rms_px = 0;          // projector pixels
  double tolerance_px = 0;
  Points2 camera, projector;  // block correspondences used for the fit
};

struct AdaptiveResult {
  bool planar = false;
  int frames_used = 0;
  std::string reason;
  PlanarityTest coarse;
  std::optional<Decoded> full;  // only for non-planar surfaces
};

// The coarse set: Gray codes of blocks_x x blocks_y cells with inverses, white, black.
Result<PatternSet> coarsePatternSet(const AdaptiveOptions& options);

// Block centroids in the camera <-> block centres in the projector, then one
// homography. Blocks touching the image border or partly undecoded are left out.
// kTooFewPoints with fewer than 8 usable blocks.
Result<PlanarityTest> testPlanarity(const PatternSet& coarse, const Decoded& decoded,
                                    const AdaptiveOptions& options);

// Shows a pattern set and returns the captures (frame i of the set at index i).
using CaptureFn = std::function<Result<std::vector<cv::Mat>>(const PatternSet&)>;

Result<AdaptiveResult> scanAdaptive(const AdaptiveOptions& options, const CaptureFn& capture);

}  // namespace procam::sl
