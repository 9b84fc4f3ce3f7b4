#pragma once
// A display as VESA MPCDI ([MPCDI] in README), 2D media profile: one buffer
// (the content, its pixel size) and one region per projector covering all of it, each
// with its files — a geometry warp (PFM, one sample per framebuffer pixel centre: the
// content position it shows, normalized to [0, 1] from the content's top-left outer
// corner; (-1, -1) where the content does not reach), an alpha map (16-bit PNG: a = (gain
// w)^(1/gamma), the eq. 4.3 weight w and brightness gain in the projector's own gamma, which the
// map declares as gammaEmbedded; 0 where the content does not reach) and a beta map (8-bit PNG, all
// 0: no black-level offset). A player that multiplies the content's codes by a, or one that
// linearizes with gammaEmbedded and re-applies the projector's gamma, draws the frames
// procam-render draws. In memory: the caller writes the package (a zip with mpcdi.xml first).
#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <vector>

#include "blend/curved_display.hpp"
#include "blend/tiled_blend.hpp"
#include "core/error.hpp"
#include "render/render_setup.hpp"

namespace procam::blend {

// A region id that is also a safe file stem: 1-128 of [A-Za-z0-9._-], not starting with '.'.
bool isSafeRegionId(const std::string& id);

struct MpcdiFile {
  std::string name;  // path inside the package
  std::string bytes;
};

// `names`: one region id per projector, [A-Za-z0-9._-]; `blend` made with its weights;
// `geometry`: each projector's share (tile_frames.hpp shareContent: a homography or a
// lookup warp); `date` as MPCDI writes it ("YYYY-MM-DD HH:MM:SS"). mpcdi.xml is the
// first file. A curved display's warp holds the viewer's content for each pixel, so
// its package is right for the viewer it was made for.
Result<std::vector<MpcdiFile>> mpcdi2d(const BlendTables& blend,
                                       std::span<const render::RenderSetup> geometry,
                                       const std::vector<std::string>& names, cv::Size content,
                                       const std::string& date);
// A planar display's tiles, and a curved display's shares.
Result<std::vector<MpcdiFile>> mpcdi2d(const TiledBlend& blend,
                                       const std::vector<std::string>& names, cv::Size content,
                                       const std::string& date);
Result<std::vector<MpcdiFile>> mpcdi2d(const CurvedBlend& blend,
                                       const std::vector<std::string>& names, cv::Size content,
                                       const std::string& date);

// One region read back from a package written by mpcdi2d (or another 2D-profile writer
// using one full-buffer region per projector and the files above).
struct MpcdiRegion {
  std::string id;
  cv::Size size;  // framebuffer
  cv::Mat warp;   // CV_32FC3 of `size`: u, v (normalized, top-left), unused
  cv::Mat alpha;  // CV_64FC1 of `size`, 0..1 as stored (gamma embedded)
  double gamma_embedded = 1;
};
struct MpcdiDisplay {
  cv::Size buffer;
  std::vector<MpcdiRegion> regions;
};

// kParse for a package that is not such an MPCDI 2D document (missing or malformed
// mpcdi.xml, a region without its files, sizes that disagree).
Result<MpcdiDisplay> readMpcdi2d(const std::vector<MpcdiFile>& files);

// The frame a player draws for `region` from `content` (8 or 16 bit, 1, 3 or 4
// channels): the content sampled bilinearly at the warp's position, times the alpha
// code. 16-bit, 1 or 3 channels (BGR).
Result<cv::Mat> mpcdiFrame(const MpcdiRegion& region, const cv::Mat& content);

}  // namespace procam::blend
