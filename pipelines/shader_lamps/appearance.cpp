#include "shader_lamps/appearance.hpp"

#include <algorithm>
#include <cmath>

namespace procam::lamps {

Result<void> checkMaterial(const Material& m) {
  if (!m.texture.empty() &&
      (m.texture.type() != CV_32FC3 || m.texture.cols > 16384 || m.texture.rows > 16384))
    return fail(ErrorCode::kInvalidInput,
                "a texture must be linear RGB floats, at most 16384 a side");
  if (!m.texture.empty() && !cv::checkRange(m.texture, true, nullptr, 0, 1e30))
    return fail(ErrorCode::kInvalidInput, "a texture has negative or non-finite colours");
  if (!m.albedo_rgb.allFinite() || (m.albedo_rgb.array() < 0).any() ||
      !m.specular_rgb.allFinite() || (m.specular_rgb.array() < 0).any())
    return fail(ErrorCode::kInvalidInput, "albedo and specular colours must be finite and >= 0");
  if (!(m.shininess >= 1 && m.shininess <= 10000))
    return fail(ErrorCode::kInvalidInput, "shininess must lie in [1, 10000]");
  if (!(m.ambient >= 0 && m.ambient <= 1))
    return fail(ErrorCode::kInvalidInput, "ambient must lie in [0, 1]");
  if (m.light_dir && (!m.light_dir->allFinite() || !(m.light_dir->norm() > 1e-9)))
    return fail(ErrorCode::kInvalidInput, "the light direction must be a non-zero vector");
  return {};
}

Vec3 textureAt(const cv::Mat& texture, const Vec2& uv) {
  if (texture.empty()) return Vec3::Ones();
  // Clamped to the texture's edge (and a coordinate that is not a number to its corner).
  const double u = std::isfinite(uv.x()) ? std::clamp(uv.x(), 0.0, 1.0) : 0.0;
  const double v = std::isfinite(uv.y()) ? std::clamp(uv.y(), 0.0, 1.0) : 0.0;
  const double x = u * texture.cols - 0.5, y = (1 - v) * texture.rows - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  const auto at = [&](double px, double py) {
    const int cx = std::clamp(static_cast<int>(px), 0, texture.cols - 1);
    const int cy = std::clamp(static_cast<int>(py), 0, texture.rows - 1);
    const cv::Vec3f& t = texture.at<cv::Vec3f>(cy, cx);
    return Vec3(t[0], t[1], t[2]);
  };
  return (1 - ay) * ((1 - ax) * at(fx, fy) + ax * at(fx + 1, fy)) +
         ay * ((1 - ax) * at(fx, fy + 1) + ax * at(fx + 1, fy + 1));
}

Vec3 desiredRadiance(const Material& m, const Vec3& point, const Vec3& n, const Vec2& uv,
                     const std::optional<Vec3>& eye) {
  Vec3 diffuse = m.albedo_rgb.cwiseProduct(textureAt(m.texture, uv));
  if (m.light_dir) {
    const double lambert = std::max(0.0, n.dot(m.light_dir->normalized()));
    diffuse *= m.ambient + (1 - m.ambient) * lambert;
  }
  if (!eye || m.specular_rgb.isZero()) return diffuse;
  const Vec3 to_eye = (*eye - point).normalized();
  const Vec3 to_light = m.light_dir ? Vec3(m.light_dir->normalized()) : to_eye;
  const Vec3 h = (to_eye + to_light).normalized();
  const double spec = std::pow(std::max(0.0, n.dot(h)), m.shininess);
  return diffuse + spec * m.specular_rgb;
}

}  // namespace procam::lamps
