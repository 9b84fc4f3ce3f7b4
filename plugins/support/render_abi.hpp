#pragma once
// The render setup and content of the output ABI (procam_plugin.h, output operations
// version 2) on both sides of the boundary: the daemon's render::RenderSetup and content
// as C views (no copy of images or meshes), and what an output receives turned back into
// the renderer's types with every count bounded and every value checked. Nothing throws.
#include <procamd/procam_plugin.h>

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>

#include "core/error.hpp"
#include "render/frame_stats.hpp"
#include "render/render_setup.hpp"

namespace procam::plugins {

// Bounds on what an output accepts through the ABI (a setup is geometry, not content).
inline constexpr uint32_t kMaxOutputSide = 16384;
inline constexpr size_t kMaxMeshVertices = 8u << 20;
inline constexpr size_t kMaxMeshTriangles = 16u << 20;

// A C view of a setup, pointing into `setup` (no copy): keep it alive and unchanged
// while the view is in use.
class RenderSetupView {
 public:
  explicit RenderSetupView(const render::RenderSetup& setup);
  RenderSetupView(const RenderSetupView&) = delete;
  RenderSetupView& operator=(const RenderSetupView&) = delete;
  const procam_render_setup& get() const { return view_; }

 private:
  procam_render_setup view_{};
};

// The setup an output received; kInvalidInput for bad paths, sizes, counts, indices or
// non-finite values.
Result<render::RenderSetup> setupFromAbi(const procam_render_setup& setup);

// A C view of content: an RGBA image (CV_8UC4) or a coloured mesh; both must outlive it.
class ContentView {
 public:
  ContentView(const cv::Mat* rgba, const render::ColoredMesh* mesh, uint64_t version);
  ContentView(const ContentView&) = delete;
  ContentView& operator=(const ContentView&) = delete;
  const procam_content& get() const { return view_; }

 private:
  procam_image image_{};
  procam_content view_{};
};

// An output's copy of the last mesh content it received, by version.
struct MeshCache {
  render::ColoredMesh mesh;
  std::optional<uint64_t> version;
};

// What an output renders from content it received for `setup`: the image without a copy
// (`image_header` points at the caller's pixels, valid during the call), the mesh copied
// into `cache` only when its version changed. kInvalidInput when the content does not fit
// the setup's path and sizes or breaks a bound.
Result<render::Content> contentFromAbi(const procam_content& content,
                                       const render::RenderSetup& setup, cv::Mat& image_header,
                                       MeshCache& cache);

// The frame statistics of the ABI from an RGBA or RGB frame.
Result<procam_frame_stats> abiFrameStats(const cv::Mat& frame);

// Whether an output device renders by itself (output operations version 2).
bool outputRenders(const procam_device& device);
// True when the output's render can be stopped midway (output operations version 3).
bool outputStops(const procam_device& device);

// An output that holds a frame until a time the daemon asks for and says when its
// frames were drawn and shown (output operations version 4).
bool outputPresentsAt(const procam_device& device);
struct PresentTiming {
  uint64_t ready_ns = 0;   // the last frame's drawing ended (CLOCK_MONOTONIC)
  uint64_t shown_ns = 0;   // it went on screen
  uint64_t period_ns = 0;  // the display's refresh period when it presents at vblank, else 0
};
// nullopt for an output without the operation, one that does not answer, or times of
// 0, a shown time before the ready time or a period outside 1 ms .. 1 s.
std::optional<PresentTiming> outputTiming(const procam_device& device);

}  // namespace procam::plugins
