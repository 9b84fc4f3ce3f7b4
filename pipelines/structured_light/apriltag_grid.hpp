#pragma once
// Single-frame sparse correspondences: a grid of tag36h11 AprilTags shown by the
// projector (or printed on a board) and detected in one capture. Used by the planar
// fast path, the handheld keystone's camera and drift checks during display.
// Corners are in ARCHITECTURE.md's pixel-centre convention on both sides.
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::sl {

struct TagGridOptions {
  int width = 0, height = 0;  // image size in pixels (projector framebuffer or board)
  int module_px = 0;          // pixels per tag module (a tag36h11 is 10 modules wide
                              // with its white border); 0: fit about 8 tags across
  int gap_modules = 2;        // white modules between neighbouring tags
};

struct TagPlacement {
  int id = 0;
  // Outer corners of the black border in the detector's order: bottom-left,
  // bottom-right, top-right, top-left of the upright tag (image y down).
  std::array<Vec2, 4> corners;
};

struct TagGrid {
  TagGridOptions options;
  int module_px = 0;
  std::vector<TagPlacement> tags;  // ids 0..n-1, row-major
};

// kInvalidInput when not even a 2x2 grid fits.
Result<TagGrid> makeTagGrid(const TagGridOptions& options);

// The grid image, CV_8UC1 (tags black on white).
Result<cv::Mat> renderTagGrid(const TagGrid& grid);

struct TagCorrespondence {
  int id = 0;
  int corner = 0;  // 0..3 as in TagPlacement::corners
  Vec2 image;      // detected, pixel-centre convention
  Vec2 pattern;    // the same corner in the grid image
};

struct TagDetectOptions {
  float decimate = 1.0f;     // libapriltag quad_decimate (1 = full resolution)
  double min_margin = 30.0;  // decision margin below which a detection is dropped
};

// Tags of the grid found in an 8-bit grey image; ids outside the grid are ignored.
Result<std::vector<TagCorrespondence>> detectTagGrid(const TagGrid& grid, const cv::Mat& image,
                                                     const TagDetectOptions& options = {});

}  // namespace procam::sl
