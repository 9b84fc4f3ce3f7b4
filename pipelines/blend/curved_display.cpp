#include "blend/curved_display.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "blend/coverage_raster.hpp"
#include "render/viewer_view.hpp"

namespace procam::blend {

Result<CurvedDisplay> solveCurvedDisplay(std::span<const SurfaceProjector> projectors,
                                         const Vec3& eye, cv::Size content,
                                         const CurvedDisplayOptions& options) {
  if (projectors.empty()) return fail(ErrorCode::kInvalidInput, "a display needs a projector");
  if (content.width < 1 || content.height < 1 || content.width > 65536 || content.height > 65536)
    return fail(ErrorCode::kInvalidInput, "content size out of range");
  if (!eye.allFinite()) return fail(ErrorCode::kInvalidInput, "the eye is not finite");
  if (options.lookup_step < 1 || options.lookup_step > 64)
    return fail(ErrorCode::kInvalidInput, "lookup step outside [1, 64]");
  auto found = surfaceProjectorRays(projectors);
  if (!found) return tl::unexpected(found.error());
  const std::vector<render::PixelRays>& rays = *found;
  // Surface points of every image: a lattice and every frame edge, where the surface is.
  std::vector<std::vector<Vec3>> points(projectors.size());
  Vec3 sum = Vec3::Zero();
  std::size_t count = 0;
  for (std::size_t m = 0; m < projectors.size(); ++m) {
    const cv::Size s = projectors[m].size;
    constexpr int kN = 48;
    for (int j = 0; j <= kN; ++j) {
      for (int i = 0; i <= kN; ++i) {
        const double x = -0.5 + s.width * double(i) / kN, y = -0.5 + s.height * double(j) / kN;
        if (auto hit = projectors[m].surface->intersect(rays[m].through(x, y))) {
          points[m].push_back(hit->point);
          sum += hit->point;
          ++count;
        }
      }
    }
  }
  if (count == 0) return fail(ErrorCode::kDegenerate, "no projector's image is on the surface");
  auto turned = render::uprightEyeRotation(sum / double(count) - eye);
  if (!turned) return tl::unexpected(turned.error());
  const Mat3 R = *turned;
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t m = 0; m < projectors.size(); ++m) {
    for (const Vec3& X : points[m]) {
      const Vec3 q = R * (X - eye);
      if (!(q.z() > 1e-9))
        return fail(ErrorCode::kDegenerate,
                    "part of projector " + std::to_string(m) + "'s image is behind the eye");
      const Vec2 p(q.x() / q.z(), -q.y() / q.z());
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  // A lattice cell's worth of margin: the images' edges may lie past the outer samples.
  const Vec2 pad = 0.05 * (hi - lo);
  lo -= pad;
  hi += pad;
  // Shown: the eye's ray through p meets a surface at a point some projector lights.
  const auto shown = [&](const Vec2& p) {
    const geom::Ray ray{eye, (R.transpose() * Vec3(p.x(), -p.y(), 1)).normalized()};
    for (std::size_t m = 0; m < projectors.size(); ++m) {
      const auto hit = projectors[m].surface->intersect(ray);
      if (!hit) continue;
      const auto pixel = rays[m].framebufferPixelOf(hit->point);
      if (!pixel) continue;
      const Vec2 u = *pixel;
      const cv::Size s = projectors[m].size;
      if (u.x() >= -0.5 && u.y() >= -0.5 && u.x() <= s.width - 0.5 && u.y() <= s.height - 0.5)
        return true;
    }
    return false;
  };
  const double aspect = double(content.width) / content.height;
  auto largest = largestRectInRegion(lo, hi, aspect, options.raster_cells, shown);
  if (!largest) {
    return fail(largest.error().code,
                "no display rectangle fits the projectors' images: " + largest.error().message);
  }
  CurvedDisplay out;
  out.eye = eye;
  out.rotation = R;
  out.rect = largest->rect;
  out.cell = largest->cell;
  out.union_area = largest->region_area;
  // The lookup warps draw no triangle with an unreached node, so a projector's drawn
  // image ends up to one lookup cell inside its mesh: where the union's border is a
  // mesh's edge, shrink about the centre until every point of the rectangle's border is
  // drawn by some projector (render::gridSource on its warp).
  auto drawn = [&](const CurvedDisplay& d, double x, double y) {
    const geom::Ray ray{eye, (R.transpose() * Vec3(x, -y, 1)).normalized()};
    for (std::size_t m = 0; m < projectors.size(); ++m) {
      const auto hit = projectors[m].surface->intersect(ray);
      if (!hit) continue;
      const auto pixel = rays[m].framebufferPixelOf(hit->point);
      if (pixel && render::gridSource(d.lookup[m], *pixel)) return true;
    }
    return false;
  };
  for (int iteration = 0; iteration < 40; ++iteration) {
    out.viewer = render::contentViewMatrix(R, eye, out.rect, content);
    if (!out.viewer.allFinite())
      return fail(ErrorCode::kDegenerate, "degenerate display rectangle");
    out.lookup.clear();
    for (std::size_t m = 0; m < projectors.size(); ++m) {
      auto grid = render::lookupGridForViewer(*projectors[m].surface, projectors[m].projector,
                                              projectors[m].size, out.viewer, options.lookup_step,
                                              projectors[m].post_warp);
      if (!grid) return tl::unexpected(grid.error());
      out.lookup.push_back(std::move(*grid));
    }
    bool inside = true;
    const keystone::AxisRect& r = out.rect;
    for (int i = 0; i <= 64 && inside; ++i) {
      const double a = -1 + 2.0 * i / 64;
      for (const Vec2& c : {Vec2(a, -1), Vec2(1, a), Vec2(-a, 1), Vec2(-1, -a)}) {
        // Half a content pixel in from the edge: the outermost pixel centres.
        const double x = r.centre.x() + c.x() * r.half_width * (1 - 1.0 / content.width);
        const double y = r.centre.y() + c.y() * r.half_height * (1 - 1.0 / content.height);
        if (!drawn(out, x, y)) {
          inside = false;
          break;
        }
      }
    }
    if (inside) return out;
    out.rect.half_width *= 0.99;
    out.rect.half_height *= 0.99;
  }
  return fail(ErrorCode::kNotFound,
              "no display rectangle is drawn whole by the projectors' lookup warps");
}

namespace {

// Eq. 4.3 weights over each projector's drawn image and the blend tables of a display.
Result<CurvedBlend> blendOf(std::span<const SurfaceProjector> projectors,
                            std::span<const std::optional<ProjectorResponse>> responses,
                            CurvedDisplay display, cv::Size content,
                            const CurvedDisplayOptions& options) {
  auto weights = curvedFeatherWeights(projectors, options.feather, display.lookup);
  if (!weights) return tl::unexpected(weights.error());
  std::vector<ContentOf> to_content;
  for (const render::WarpGrid& grid : display.lookup) {
    to_content.push_back([&grid](const Vec2& pixel) { return render::gridSource(grid, pixel); });
  }
  auto tables = blendTables(std::move(*weights), responses, to_content, content);
  if (!tables) return tl::unexpected(tables.error());
  CurvedBlend out;
  static_cast<BlendTables&>(out) = std::move(*tables);
  out.display = std::move(display);
  return out;
}

}  // namespace

Result<CurvedBlend> makeCurvedBlend(std::span<const SurfaceProjector> projectors,
                                    std::span<const std::optional<ProjectorResponse>> responses,
                                    const Vec3& eye, cv::Size content,
                                    const CurvedDisplayOptions& options) {
  if (!responses.empty() && responses.size() != projectors.size())
    return fail(ErrorCode::kInvalidInput, "one response per projector, or none");
  auto display = solveCurvedDisplay(projectors, eye, content, options);
  if (!display) return tl::unexpected(display.error());
  return blendOf(projectors, responses, std::move(*display), content, options);
}

Result<CurvedDisplay> solveDomeDisplay(std::span<const SurfaceProjector> projectors,
                                       const render::DomeMaster& master,
                                       const CurvedDisplayOptions& options) {
  if (projectors.empty()) return fail(ErrorCode::kInvalidInput, "a display needs a projector");
  const cv::Size content = master.content;
  if (content.width < 1 || content.height < 1 || content.width > 65536 || content.height > 65536)
    return fail(ErrorCode::kInvalidInput, "content size out of range");
  if (options.lookup_step < 1 || options.lookup_step > 64)
    return fail(ErrorCode::kInvalidInput, "lookup step outside [1, 64]");
  auto found = surfaceProjectorRays(projectors);
  if (!found) return tl::unexpected(found.error());
  const std::vector<render::PixelRays>& rays = *found;
  CurvedDisplay out;
  out.eye = master.eye;
  out.dome = master;
  for (const SurfaceProjector& p : projectors) {
    auto grid = render::lookupGridForDome(*p.surface, p.projector, p.size, master,
                                          options.lookup_step, p.post_warp);
    if (!grid) return tl::unexpected(grid.error());
    out.lookup.push_back(std::move(*grid));
  }
  // The part of the circle some projector draws: the eye's ray of each cell of a
  // 128 x 128 lattice over the circle meets a surface at a pixel a lookup warp draws.
  constexpr int kN = 128;
  long inside = 0, drawn = 0;
  const Vec2 c0 = master.centre();
  const double r = master.radius();
  for (int j = 0; j < kN; ++j) {
    for (int i = 0; i < kN; ++i) {
      const Vec2 c = c0 + r * Vec2(-1 + (2 * i + 1.0) / kN, -1 + (2 * j + 1.0) / kN);
      const auto d = master.direction(c);
      if (!d) continue;
      ++inside;
      for (std::size_t m = 0; m < projectors.size(); ++m) {
        const auto hit = projectors[m].surface->intersect({master.eye, *d});
        if (!hit) continue;
        const auto pixel = rays[m].framebufferPixelOf(hit->point);
        if (pixel && render::gridSource(out.lookup[m], *pixel)) {
          ++drawn;
          break;
        }
      }
    }
  }
  out.coverage = inside > 0 ? double(drawn) / inside : 0;
  if (drawn == 0)
    return fail(ErrorCode::kDegenerate, "no projector draws any of the dome master's circle");
  return out;
}

Result<CurvedBlend> makeDomeBlend(std::span<const SurfaceProjector> projectors,
                                  std::span<const std::optional<ProjectorResponse>> responses,
                                  const render::DomeMaster& master,
                                  const CurvedDisplayOptions& options) {
  if (!responses.empty() && responses.size() != projectors.size())
    return fail(ErrorCode::kInvalidInput, "one response per projector, or none");
  auto display = solveDomeDisplay(projectors, master, options);
  if (!display) return tl::unexpected(display.error());
  return blendOf(projectors, responses, std::move(*display), master.content, options);
}

nlohmann::json postWarpJson(const render::PostRenderWarp& warp) {
  const bool measured = warp.source == render::PostRenderWarp::Source::kMeasured;
  nlohmann::json j = {
      {"source", measured ? "measured" : "lens"}, {"rms_px", warp.rms_px}, {"max_px", warp.max_px}};
  if (measured) j["points"] = warp.points;
  return j;
}

}  // namespace procam::blend
