#pragma once
// A mesh as 3D content on a planar display for one projector and a viewer: placed in
// front of the surface, shaded, and with the single-pass A'4x4 P_T matrix that renders
// it ([Raskar02] §4.2.1-4.2.3, eq. 4.10; RenderPath::kPlanar3d).
//
// Placement: the plane's axes are u (horizontal, to the viewer's right) and v (world up
// projected onto the plane; world +Y when the plane is horizontal), n = u x v faces the
// viewer. The mesh's x, y, z map to u, v, n: its x-y bounds are centred on the centre of
// S (the rectangle bounding the projector's image on the plane, §4.2.1) and scaled
// uniformly so that the larger of its x, y extents is half of S's smaller side, and its
// z extent at most a quarter of the viewer's distance to the plane; the back of its
// bounds (min z) lies on the plane, so the object stands out of the surface toward the
// viewer.
//
// Colour: the mesh reader keeps no vertex colours, so every face is flat-shaded white
// with two-sided Lambert under a fixed light from the viewer's upper left
// (l ~ -0.3 u + 0.5 v + 0.8 n): intensity kAmbient + (1 - kAmbient) |n_face . l|.
#include <opencv2/core.hpp>

#include "content/mesh_content.hpp"
#include "core/error.hpp"
#include "keystone/head_tracked.hpp"
#include "render/render_setup.hpp"

namespace procam::content {

inline constexpr double kMeshAmbient = 0.25;

struct PlanarView {
  Mat34 projector = Mat34::Zero();  // world -> projector pixels
  cv::Size size;                    // projector framebuffer
  Vec3 plane_point = Vec3::Zero();  // a point of the display plane
  Vec3 plane_normal = Vec3::UnitZ();
  Vec3 eye = Vec3::Zero();  // the viewer
};

struct PlacedMesh {
  render::ColoredMesh mesh;          // world coordinates, three vertices per face
  Mat4 planar3d = Mat4::Identity();  // RenderSetup::planar3d
  keystone::DisplayRect S;
};

// kDegenerate when the viewer is on the plane or a corner ray of the projector misses
// it; kIllConditioned when eq. 4.9 cannot hold (see keystone::singlePassMatrix).
Result<PlacedMesh> placeMeshContent(const MeshContent& content, const PlanarView& view);

// The view-dependent part alone: RenderSetup::planar3d for the viewer `view.eye` with
// S kept (A does not depend on the viewer, [Raskar02] §4.2.2), so that a placed mesh is drawn
// for a moved viewer where it stands. Depth range of P_T: 0.1 to 2 times the viewer's
// distance to S's centre. kDegenerate when the viewer is on the plane or behind it.
Result<Mat4> planar3dForViewer(const PlanarView& view, const keystone::DisplayRect& S);

}  // namespace procam::content
