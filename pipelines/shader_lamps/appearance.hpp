#pragma once
// The appearance shader lamps give the object: the radiance L(x, θ, φ) the viewer should
// see at a surface point ([Raskar02] eq. 5.1, split as §5.2.4 does into a
// view-independent diffuse part and a view-dependent specular part). Relative units: a
// white diffuse point under the full virtual light has L = 1; the frame's white level
// scales it to light.
#include <opencv2/core.hpp>
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::lamps {

struct Material {
  Vec3 albedo_rgb = Vec3::Ones();  // multiplies the texture, linear
  // Linear RGB texture, CV_32FC3, sampled bilinearly at the model's texture coordinates
  // (u right, v up; the image's first row is v = 1). Empty: the albedo alone.
  cv::Mat texture;
  Vec3 specular_rgb = Vec3::Zero();  // Blinn-Phong, needs a viewer
  double shininess = 32;
  // Virtual light: the direction towards a distant light, lighting `1 - ambient` of the
  // diffuse part as max(0, n · l); none: the object is evenly lit (L = albedo · texture).
  std::optional<Vec3> light_dir;
  double ambient = 0.3;
};

// kInvalidInput for a texture that is not CV_32FC3 or is larger than 16384 a side, or
// non-finite or negative colours, a shininess outside [1, 10000], an ambient outside
// [0, 1] or a light direction that is not a finite non-zero vector.
Result<void> checkMaterial(const Material& m);

// L at a point with unit shading normal `n` and texture coordinate `uv`, seen from
// `eye` (the tracked or sweet-spot viewer; none: no specular part). The specular part's
// light is the virtual light, or a light at the eye when there is none.
Vec3 desiredRadiance(const Material& m, const Vec3& point, const Vec3& n, const Vec2& uv,
                     const std::optional<Vec3>& eye);

// The texture's linear RGB at `uv` (clamped to its edge), or white without one.
Vec3 textureAt(const cv::Mat& texture, const Vec2& uv);

}  // namespace procam::lamps
