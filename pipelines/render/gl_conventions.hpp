#pragma once
// The one place where this project's pixel conventions (ARCHITECTURE.md: x right, y down,
// pixel centres at integer coordinates) meet OpenGL's (normalised device coordinates
// in [-1, 1], texture coordinates in [0, 1] with texel centres at half-integers).
#include "core/types.hpp"

namespace procam::render {

// Which end of the GL framebuffer holds the image's top row.
enum class GlOrigin {
  kRow0AtGlBottom,  // offscreen FBO read with glReadPixels: memory row 0 = GL y 0 = image row 0
  kRow0AtGlTop,     // window surfaces scanned out top-down (KMS): image row 0 = GL y H-1
};

struct GlConventions {
  // Homogeneous pixel coordinates (x*w, y*w, z*w, w), z in [-1, 1], to GL clip coordinates.
  Mat4 clip_from_pixel = Mat4::Identity();
  // Homogeneous source-image pixel coordinates (x, y, 1) to GL texture coordinates (s, t, 1);
  // texture row 0 is uploaded from image row 0, so no flip is involved here.
  Mat3 tex_from_pixel = Mat3::Identity();
};

// width, height: the framebuffer (for clip_from_pixel) and the texture (for
// tex_from_pixel) when both are the same size; call twice otherwise.
GlConventions glConventions(int width, int height, GlOrigin origin);

}  // namespace procam::render
