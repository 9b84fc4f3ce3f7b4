#pragma once
// What a projector output is asked to draw: the alignment pattern (when one is chosen),
// 3D content (a mesh through the planar 3D path) or the content image, pre-warped by the
// keystone homography (or fitted into the frame), as a render setup (geometry) plus content
// that the output renders itself (procam_plugin.h, output operations version 2). Pure.
#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "content_access.hpp"
#include "core/error.hpp"
#include "core/types.hpp"
#include "procamd/procam_plugin.h"
#include "render/render_setup.hpp"

namespace procam::daemon {

// 3D content for one output: drawn through the planar 3D path (RenderPath::kPlanar3d).
struct Mesh3d {
  std::shared_ptr<const render::ColoredMesh> mesh;
  Mat4 planar3d = Mat4::Identity();  // RenderSetup::planar3d
};

struct FrameRequest {
  cv::Size output_size;
  std::string pattern = "off";                   // not "off": shown instead of the content
  std::shared_ptr<const cv::Mat> pattern_image;  // RGBA of the pattern (patternImage())
  std::shared_ptr<const cv::Mat> content;        // CV_8UC4 RGBA; null: none
  // Content pixels -> framebuffer pixels; none: the source is fitted into the
  // frame, centred, aspect kept (identity when the sizes agree).
  std::optional<Mat3> homography;
  std::optional<Mesh3d> mesh3d;  // shown instead of `content` when set
};

// A few numbers about a frame, reported in status so that a client can tell what
// an output shows without reading it back.
struct FrameStats {
  std::string source;                // "pattern:NAME", "content" or "none"
  double lit_fraction = 0;           // pixels with any channel above 0
  std::array<double, 3> mean_rgb{};  // 0..255
  // The frame these numbers describe: its render path and, for content drawn for a
  // viewer, the viewer's world -> content pixel matrix (status reports them together).
  std::string path;
  std::optional<Mat34> viewer;
  std::optional<Mat3> homography;  // content -> framebuffer pixels (homography path)
  int tile = -1;                   // its tile of a display across outputs, if any
};

// One output's frame as the output renders it: the geometry and the content.
struct PlannedFrame {
  render::RenderSetup setup;
  std::shared_ptr<const cv::Mat> image;             // RGBA (image paths)
  std::shared_ptr<const render::ColoredMesh> mesh;  // planar 3D path
  std::string source;                               // as FrameStats::source
};

// The RGBA image of a test pattern at an output's size.
std::shared_ptr<const cv::Mat> patternImage(const std::string& name, cv::Size size);

// The plugin ABI's view of an RGB8 frame shown 1:1 (no copy: `rgb` must outlive it).
procam_image rgbImage(const cv::Mat& rgb);

// The size of the image the homography applies to: the output size for a
// pattern or nothing, the content's size otherwise.
cv::Size sourceSize(const FrameRequest& request);

struct DecodedContent {
  std::shared_ptr<const cv::Mat> image;  // RGBA (grey and 16-bit images converted)
  std::string path;                      // resolved under a content root
};
// An image file a client named, read through `access` (content_access.hpp), its
// size checked from its header before it is decoded: kForbidden outside the
// roots, kTooLarge over a limit, kIo when it cannot be read or decoded.
Result<DecodedContent> decodeContent(const ContentAccess& access, const std::string& path);

// kInvalidInput for empty sizes, content of the wrong type or a pattern without its image.
Result<PlannedFrame> planFrame(const FrameRequest& request);

struct OutputFrame {
  cv::Mat rgba;  // CV_8UC4, output size
  FrameStats stats;
};

// The frame drawn by the CPU reference renderer (tests, and outputs that do not render).
Result<OutputFrame> renderOutputFrame(const FrameRequest& request);

}  // namespace procam::daemon
