#include "blend/tiled_blend.hpp"

#include <Eigen/LU>

#include "blend/feather.hpp"

namespace procam::blend {

Result<TiledBlend> makeTiledBlend(std::span<const DisplayTile> tiles,
                                  std::span<const std::optional<ProjectorResponse>> responses,
                                  cv::Size content, const TiledDisplayOptions& options) {
  if (!responses.empty() && responses.size() != tiles.size())
    return fail(ErrorCode::kInvalidInput, "one response per tile, or none");
  auto display = solveTiledDisplay(tiles, content.width, content.height, options);
  if (!display) return tl::unexpected(display.error());
  std::vector<FeatherTile> feather;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    feather.push_back({display->footprints[t], display->plane_to_framebuffer[t], tiles[t].width,
                       tiles[t].height});
  }
  auto weights = featherWeights(feather);
  if (!weights) return tl::unexpected(weights.error());
  std::vector<ContentOf> to_content;
  for (const Mat3& h : display->content_to_framebuffer) {
    const Mat3 inverse = h.inverse();
    to_content.push_back([inverse](const Vec2& pixel) -> std::optional<Vec2> {
      const Vec3 q = inverse * pixel.homogeneous();
      if (!(std::abs(q.z()) > 1e-12)) return std::nullopt;
      return Vec2(q.x() / q.z(), q.y() / q.z());
    });
  }
  auto tables = blendTables(std::move(*weights), responses, to_content, content);
  if (!tables) return tl::unexpected(tables.error());
  TiledBlend out;
  static_cast<BlendTables&>(out) = std::move(*tables);
  out.display = std::move(*display);
  return out;
}

}  // namespace procam::blend
