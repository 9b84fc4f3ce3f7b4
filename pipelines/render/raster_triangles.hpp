#pragma once
// The CPU back-end of the planar 3D path ([Raskar02] §4.2.2-4.2.3): vertex-coloured triangles
// through A'4x4 P_T, drawn as the GL back-end's colour program draws them. Triangles are
// clipped in homogeneous coordinates to the depth range -w <= z <= w (which also keeps
// only w > 0: nothing behind the projector) and to a band one pixel outside the image,
// so no visible geometry is lost; pixel centres sit at integers (ARCHITECTURE.md), edges follow
// the top-left rule (raster.hpp), a float depth buffer keeps the nearest fragment
// (GL_LESS, cleared to the far plane) and colours are interpolated perspective-correctly,
// as GL's default smooth shading does.
#include <functional>
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "core/types.hpp"
#include "render/render_setup.hpp"

namespace procam::render {

// Clears `color` (CV_8UC4, (re)allocated to `size`) to transparent black and draws
// `mesh` through `pixel3d` (world -> (x w, y w, z w, w), RenderSetup::planar3d). `depth`
// is scratch (CV_32F, reused between calls). kInvalidInput for a colour count other than
// one per vertex or a vertex index out of range. `stop` (may be empty) is asked every
// kStopCheckTriangles triangles; once true the drawing ends with kCancelled and `color`
// holds a partial frame.
inline constexpr size_t kStopCheckTriangles = 4096;
Result<void> rasterizeColoredMesh(const ColoredMesh& mesh, const Mat4& pixel3d, cv::Size size,
                                  cv::Mat& color, cv::Mat& depth,
                                  const std::function<bool()>& stop = {});

}  // namespace procam::render
