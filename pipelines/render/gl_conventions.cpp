#include "render/gl_conventions.hpp"

namespace procam::render {

GlConventions glConventions(int width, int height, GlOrigin origin) {
  const double w = width > 0 ? width : 1;
  const double h = height > 0 ? height : 1;
  GlConventions c;
  // Pixel centre x maps to NDC (2x + 1)/W - 1: pixel -0.5 is the left edge (-1), W - 0.5 the right.
  c.clip_from_pixel = Mat4::Identity();
  c.clip_from_pixel(0, 0) = 2.0 / w;
  c.clip_from_pixel(0, 3) = 1.0 / w - 1.0;
  if (origin == GlOrigin::kRow0AtGlBottom) {
    c.clip_from_pixel(1, 1) = 2.0 / h;
    c.clip_from_pixel(1, 3) = 1.0 / h - 1.0;
  } else {
    c.clip_from_pixel(1, 1) = -2.0 / h;
    c.clip_from_pixel(1, 3) = 1.0 - 1.0 / h;
  }
  // Texel centre x sits at s = (x + 0.5) / W.
  c.tex_from_pixel << 1.0 / w, 0, 0.5 / w, 0, 1.0 / h, 0.5 / h, 0, 0, 1;
  return c;
}

}  // namespace procam::render
