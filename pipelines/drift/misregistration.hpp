#pragma once
// How far the projected content has moved from where the rig model puts it, in
// projector pixels, from one camera frame of the content itself: the camera frame is
// resampled onto the projector's framebuffer grid through the rig's mapping
// (projector_camera_map.hpp) and compared with the frame shown, tile by tile, by phase
// correlation (translation from the normalised cross-power spectrum; gain, offset and
// a monotone response do not move its peak). Shifts are then screened by RANSAC on
// one homography of the framebuffer ([Johnson07] registers projectors from content
// correspondences the same way): a moved planar projector moves its content by a
// collineation. Pure.
#include <opencv2/core.hpp>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "projector_camera_map.hpp"

namespace procam::drift {

struct MisregistrationOptions {
  int tile = 48;  // work pixels per side; a tile's shift may differ from the whole view's by a
                  // quarter of it
  // A tile whose shown content varies less than this (standard deviation, on the 0..255
  // scale of its light) has nothing to register: plain.
  double min_texture = 6.0;
  // A tile whose texture runs one way (an edge alone: the border of a plain image) fixes
  // its shift across it only, not along it: plain too. The smaller eigenvalue of the
  // tile's windowed gradient structure tensor must be at least this share of the larger
  // ([ShiTomasi94]; 0.1 lets the weak direction's noise be at most about 3x the strong one's).
  double min_isotropy = 0.1;
  // Phase-correlation peak (0..1) below which a tile's shift is not trusted.
  double min_response = 0.08;
  // Fewer registered tiles than this (or under `min_textured_share` of the tiles
  // the camera sees being textured): too plain to tell.
  int min_tiles = 8;
  double min_textured_share = 0.15;
  double ransac_px = 1.5;  // framebuffer pixels
  // Gaussian sigma, work pixels, applied to the shown frame's light before it is compared:
  // the camera sees the frame through the projector's pixel footprint, its own lens and
  // pixels and the resampling onto the grid (reference_blur.hpp finds it). 0 to 8.
  double reference_blur_px = 0;
};

inline constexpr double kMaxReferenceBlurPx = 8.0;

// One tile: the content drawn at framebuffer point `drawn` (the tile's centre) lands on
// the surface where the rig model puts framebuffer point `seen_at`; the phase
// correlation's peak.
struct TileShift {
  Vec2 drawn = Vec2::Zero();
  Vec2 seen_at = Vec2::Zero();
  double response = 0;
  bool inlier = false;
  Vec2 shift() const { return seen_at - drawn; }
};

struct Misregistration {
  int tiles_seen = 0;      // tiles the camera sees whole
  int tiles_textured = 0;  // of those, with content to register
  int tiles_used = 0;      // registered and consistent with one collineation
  bool too_plain = false;  // not enough texture: nothing below is meaningful
  // The shift field: one collineation of the framebuffer fitted to the inlier tiles
  // (drawn -> seen_at), and its shifts at their centres, framebuffer pixels.
  Mat3 drawn_to_seen = Mat3::Identity();
  double rms_px = 0;
  double max_px = 0;
  double tile_rms_px = 0;  // the tiles' scatter about it (the measurement's noise)
  // used / textured tiles times their mean peak: 0 (nothing) .. 1 (every tile sharp).
  double confidence = 0;
  std::vector<TileShift> tiles;  // every registered tile, inliers marked
};

// Marks the tiles that one collineation of the framebuffer explains (RANSAC within
// options.ransac_px) and sets `m`'s shift field from them: drawn_to_seen, rms_px, max_px,
// tile_rms_px, tiles_used, confidence (over m.tiles_textured) and the tiles; too_plain
// also when fewer than options.min_tiles agree.
void fitShiftField(std::vector<TileShift> tiles, const MisregistrationOptions& options,
                   Misregistration& m);

// `frame_light`: the light of the frame on the output at the grid's work size (shownLight;
// CV_32F, 0..255 for full white), blurred by options.reference_blur_px before use; `camera`: the
// camera's frame (CV_32F, any scale); `map`: from projectorCameraMap for the same grid; `usable`
// (optional, CV_8U of the grid): tiles with any zero pixel are left out (where another projector
// adds its light: a blended overlap). kInvalidInput for mismatched sizes or types, or options out
// of range.
Result<Misregistration> measureMisregistration(const cv::Mat& frame_light, const cv::Mat& camera,
                                               const cv::Mat& map, const WorkGrid& grid,
                                               const MisregistrationOptions& options = {},
                                               const cv::Mat& usable = {});

}  // namespace procam::drift
