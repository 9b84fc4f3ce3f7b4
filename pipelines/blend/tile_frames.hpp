#pragma once
// The framebuffer each projector of a display shows, drawn offline (procam-render): the
// content through the projector's homography (planar) or lookup warp (curved), blended
// ([Raskar02] eq. 4.3 weights in linear light, §4.1.2) or geometry only.
//  - 8 bit, blended: the daemon's own frame, drawn by the CPU reference renderer with the
//    same render setup (homography, 8-bit alpha mask, weight table).
//  - 16 bit, or geometry only: every framebuffer pixel's centre mapped into the content
//    and sampled bilinearly in double precision (render/bilinear.hpp's convention), so a
//    16-bit ramp keeps its codes; blended, each channel is scaled by
//    (gain weight)^(1 / gamma) with the unquantized weight.
#include <functional>
#include <opencv2/core.hpp>
#include <optional>

#include "blend/curved_display.hpp"
#include "blend/tiled_blend.hpp"
#include "core/error.hpp"
#include "render/render_setup.hpp"

namespace procam::blend {

struct TileFrameOptions {
  int bit_depth = 8;           // 8 or 16
  bool geometry_only = false;  // no weights, no response correction
};

// The content position a framebuffer pixel (x, y) shows under a share's geometry
// (kHomography: its inverse; kLookupWarp: render::gridSource), nullopt where none. The
// function refers to `geometry`'s grid: keep it alive. kInvalidInput for another path or
// a singular homography.
Result<std::function<std::optional<Vec2>(double, double)>> shareContent(
    const render::RenderSetup& geometry);

// `content`: CV_8U or CV_16U with 1, 3 or 4 channels (OpenCV's BGR(A) order). Returns a
// CV_8U or CV_16U image of projector t's framebuffer size with 1 channel for grey
// content, else 3 (BGR); black outside the content's image. `geometry`: the share's path
// (kHomography with its homography, or kLookupWarp with its lookup grid). kInvalidInput
// for other content or paths, an index out of range, a blend made without weights, a
// singular homography or a bit depth other than 8 or 16.
Result<cv::Mat> shareFrame(const cv::Mat& content, const render::RenderSetup& geometry,
                           const BlendTables& blend, std::size_t t,
                           const TileFrameOptions& options);

// A planar display's tile (its homography), and a curved display's share (its lookup warp).
Result<cv::Mat> tileFrame(const cv::Mat& content, const TiledBlend& blend, std::size_t tile,
                          const TileFrameOptions& options);
Result<cv::Mat> curvedFrame(const cv::Mat& content, const CurvedBlend& blend, std::size_t t,
                            const TileFrameOptions& options);

// `content` (as above) as CV_64FC1 or CV_64FC3 in [0, 1], alpha dropped.
Result<cv::Mat> unitContent(const cv::Mat& content);

// Channel values of a unitContent image at content pixel (x, y) (centres at integers),
// bilinear with the outer half pixel clamped to the edge; false outside the image's
// footprint ([-0.5, W - 0.5) x [-0.5, H - 0.5), render/bilinear.hpp).
bool sampleContent(const cv::Mat& unit, double x, double y, double* out);

}  // namespace procam::blend
