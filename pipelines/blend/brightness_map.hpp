#pragma once
// A projector's brightness across its frame, as the reference camera sees full white
// minus black on the surface: the per-pixel luminance that Majumder's photometric
// matching needs ([Majumder05]; [Raskar02] §4.1.2 treats one number per projector). It
// holds the projector's own fall-off (cos θ / d² across the surface, lens vignetting),
// its brightness and the surface's albedo, on a grid of nodes `step` framebuffer pixels
// apart (node (i, j) at pixel (i step, j step), the last column and row on or past the
// frame's far edge), in the camera's units, so that projectors measured by one camera
// compare.
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::blend {

struct BrightnessMap {
  int step = 32;  // framebuffer pixels between nodes
  int width = 0;  // framebuffer size the nodes cover
  int height = 0;
  cv::Mat white;  // CV_32FC1 nodes: white minus black, > 0
};

// Node counts along a framebuffer side of `pixels` at `step`.
int brightnessNodes(int pixels, int step);

// From a camera's captures of the projector at full white and at black, and the
// projector pixel (u, v) each camera pixel decoded (`mask` non-zero where it did): the
// mean of white - black over the camera pixels that fall nearest to each node; nodes no
// camera pixel reached take their filled neighbours' mean, outward from the seen part.
// kInvalidInput for images of different sizes or types other than CV_8UC1/CV_16UC1
// (white, black), CV_32FC1 (u, v), CV_8UC1 (mask), a framebuffer outside [2, 16384] or a
// step outside [4, 256]; kTooFewPoints when fewer than 4 nodes are seen.
Result<BrightnessMap> measureBrightness(const cv::Mat& white, const cv::Mat& black,
                                        const cv::Mat& u, const cv::Mat& v, const cv::Mat& mask,
                                        cv::Size framebuffer, int step = 32);

// Bilinear between the nodes at a framebuffer pixel (clamped to the frame).
double brightnessAt(const BrightnessMap& map, const Vec2& pixel);

// rig.json form: {"step", "width", "height", "cols", "rows", "white": [row-major]}.
nlohmann::json brightnessToJson(const BrightnessMap& map);
// kInvalidInput for a record that is not that form: sizes out of the ranges above,
// a node count that does not match them, or a value that is not finite and > 0.
Result<BrightnessMap> brightnessFromJson(const nlohmann::json& j);

}  // namespace procam::blend
