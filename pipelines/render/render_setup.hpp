#pragma once
// Everything a renderer needs to turn content into one projector's frame. Geometry
// (this struct) changes rarely; content changes every frame.
#include <array>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "render/final_stage.hpp"
#include "render/projective_mesh.hpp"
#include "render/render_path.hpp"
#include "render/warp_map.hpp"

namespace procam::render {

// 3D content for the planar 3D path: triangles with one RGBA colour per vertex.
struct ColoredMesh {
  std::vector<Vec3> vertices;
  std::vector<cv::Vec4b> colors;  // one per vertex
  std::vector<std::array<int, 3>> triangles;
};

struct RenderSetup {
  cv::Size output_size;   // projector framebuffer
  cv::Size content_size;  // content image = the viewer's desired image (not used by kPlanar3d)
  RenderPath path = RenderPath::kHomography;

  Mat3 homography = Mat3::Identity();  // kHomography: projector pixel ~ H * content pixel

  SurfaceMesh surface;              // kTwoPassMesh: display surface (world)
  Mat34 projector = Mat34::Zero();  // kTwoPassMesh: world -> projector pixels
  Mat34 viewer = Mat34::Zero();     // kTwoPassMesh: world -> content (desired image) pixels

  WarpGrid lookup;  // kLookupWarp: projector pixel -> content pixel

  // kPlanar3d: world -> homogeneous projector pixels with depth, (x w, y w, z w, w) and
  // z in [-1, 1] for visible depths: A'4x4 P_T of [Raskar02] eq. 4.10 in this project's pixel
  // convention (its clip-space form comes from glConventions()).
  Mat4 planar3d = Mat4::Identity();

  std::optional<WarpGrid> post_warp;  // §4.1.3: output pixel -> pixel of the rendered image
  FinalStage final_stage;             // §4.1.2: alpha mask and LUTs, always last
};

// Checks sizes, finiteness and that the path's inputs are present.
Result<void> validateSetup(const RenderSetup& setup);

// True when both setups draw the same frame from the same content (every field equal,
// masks and meshes compared by value): an output is configured again only when not.
bool sameSetup(const RenderSetup& a, const RenderSetup& b);

struct Content {
  Content() = default;
  Content(const cv::Mat* image_in, const ColoredMesh* mesh_in, uint64_t version_in,
          std::function<bool()> stop_in = {})
      : image(image_in), mesh(mesh_in), version(version_in), stop(std::move(stop_in)) {}

  const cv::Mat* image = nullptr;     // CV_8UC4 of content_size (image paths)
  const ColoredMesh* mesh = nullptr;  // kPlanar3d
  uint64_t version = 0;               // changes whenever the content changes
  // Asked between steps of a long drawing (a large mesh); true stops it with kCancelled.
  // Called from the drawing threads: must be thread-safe. Empty: never stop.
  std::function<bool()> stop;
};

// Skips frames that would come out identical: nothing re-renders unless the geometry
// was reconfigured or the content version changed (ARCHITECTURE.md: no work when nothing moved).
class FrameGate {
 public:
  void geometryChanged() { dirty_ = true; }
  bool needsRender(uint64_t content_version) const {
    return dirty_ || !has_frame_ || content_version != last_version_;
  }
  void rendered(uint64_t content_version) {
    dirty_ = false;
    has_frame_ = true;
    last_version_ = content_version;
  }

 private:
  bool dirty_ = true;
  bool has_frame_ = false;
  uint64_t last_version_ = 0;
};

}  // namespace procam::render
