#include "support/render_abi.hpp"

#include <cmath>
#include <cstring>
#include <string>

namespace procam::plugins {
namespace {

// The renderer's containers are read and written through the ABI in place.
static_assert(sizeof(Vec3) == 3 * sizeof(double) && sizeof(Vec2) == 2 * sizeof(double));
static_assert(sizeof(std::array<int, 3>) == 3 * sizeof(int32_t) && sizeof(int) == sizeof(int32_t));
static_assert(sizeof(cv::Vec4b) == 4);
static_assert(sizeof(std::array<render::Lut, 3>) == 3 * 256);

template <int R, int C, class M>
void rowMajor(const M& m, double* out) {
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) out[r * C + c] = m(r, c);
}

template <int R, int C, class M>
bool fromRowMajor(const double* in, M& m) {
  for (int r = 0; r < R; ++r) {
    for (int c = 0; c < C; ++c) {
      if (!std::isfinite(in[r * C + c])) return false;
      m(r, c) = in[r * C + c];
    }
  }
  return true;
}

procam_warp_grid gridView(const render::WarpGrid& g) {
  procam_warp_grid v{};
  v.cols = static_cast<uint32_t>(g.cols);
  v.rows = static_cast<uint32_t>(g.rows);
  v.origin[0] = g.origin.x();
  v.origin[1] = g.origin.y();
  v.step[0] = g.step.x();
  v.step[1] = g.step.y();
  v.source = g.source.empty() ? nullptr : g.source.front().data();
  return v;
}

tl::unexpected<Error> bad(const std::string& what) {
  return fail(ErrorCode::kInvalidInput, "render setup: " + what);
}

Result<render::WarpGrid> gridFromAbi(const procam_warp_grid& v, cv::Size output, const char* name) {
  // A grid finer than one node per output pixel gains nothing: at most one node more
  // than the output has pixels along each side.
  const uint64_t nodes = uint64_t(v.cols) * v.rows;
  if (v.cols < 2 || v.rows < 2 || v.cols > uint32_t(output.width) + 1 ||
      v.rows > uint32_t(output.height) + 1 || !v.source) {
    return bad(std::string(name) +
               " needs 2 to (output size + 1) node columns and rows and their coordinates");
  }
  render::WarpGrid g;
  g.cols = static_cast<int>(v.cols);
  g.rows = static_cast<int>(v.rows);
  g.origin = Vec2(v.origin[0], v.origin[1]);
  g.step = Vec2(v.step[0], v.step[1]);
  if (!g.origin.allFinite() || !g.step.allFinite() || g.step.minCoeff() <= 0) {
    return bad(std::string(name) + ": origin and positive step must be finite");
  }
  g.source.resize(nodes);
  for (uint64_t i = 0; i < nodes; ++i) {
    g.source[i] = Vec2(v.source[2 * i], v.source[2 * i + 1]);
    if (!g.source[i].allFinite()) return bad(std::string(name) + ": non-finite coordinate");
  }
  return g;
}

bool sizeOk(uint32_t w, uint32_t h, uint32_t min) {
  return w >= min && h >= min && w <= kMaxOutputSide && h <= kMaxOutputSide;
}

}  // namespace

RenderSetupView::RenderSetupView(const render::RenderSetup& s) {
  procam_render_setup& v = view_;
  v.output_width = static_cast<uint32_t>(s.output_size.width);
  v.output_height = static_cast<uint32_t>(s.output_size.height);
  v.content_width = static_cast<uint32_t>(std::max(0, s.content_size.width));
  v.content_height = static_cast<uint32_t>(std::max(0, s.content_size.height));
  switch (s.path) {
    case render::RenderPath::kHomography:
      v.path = PROCAM_RENDER_HOMOGRAPHY;
      break;
    case render::RenderPath::kPlanar3d:
      v.path = PROCAM_RENDER_PLANAR_3D;
      break;
    case render::RenderPath::kTwoPassMesh:
      v.path = PROCAM_RENDER_TWO_PASS_MESH;
      break;
    case render::RenderPath::kLookupWarp:
      v.path = PROCAM_RENDER_LOOKUP_WARP;
      break;
    case render::RenderPath::kShaderLamps:
      // No ABI path: such frames are computed per pixel and shown by the homography path.
      // No enumerator has 0: a driver refuses a setup that carries it.
      v.path = static_cast<procam_render_path>(0);
      break;
  }
  rowMajor<3, 3>(s.homography, v.homography);
  rowMajor<4, 4>(s.planar3d, v.planar3d);
  rowMajor<3, 4>(s.projector, v.projector);
  rowMajor<3, 4>(s.viewer, v.viewer);
  v.n_surface_vertices = s.surface.vertices.size();
  v.surface_vertices = s.surface.vertices.empty() ? nullptr : s.surface.vertices.front().data();
  v.n_surface_triangles = s.surface.triangles.size();
  v.surface_triangles = s.surface.triangles.empty()
                            ? nullptr
                            : reinterpret_cast<const int32_t*>(s.surface.triangles.data());
  if (s.lookup.cols >= 2) v.lookup = gridView(s.lookup);
  if (s.post_warp) v.post_warp = gridView(*s.post_warp);
  const render::FinalStage& f = s.final_stage;
  if (!f.alpha.empty()) {
    v.alpha = f.alpha.data;
    v.alpha_stride = static_cast<uint32_t>(f.alpha.step[0]);
  }
  v.weight_lut = f.weight_lut.data();
  v.output_lut = f.output_lut.front().data();
}

Result<render::RenderSetup> setupFromAbi(const procam_render_setup& v) {
  render::RenderSetup s;
  if (!sizeOk(v.output_width, v.output_height, 1)) return bad("output size out of range");
  s.output_size = cv::Size(int(v.output_width), int(v.output_height));
  uint32_t path = 0;  // read as bits: a foreign value is not a valid enumerator
  std::memcpy(&path, &v.path, sizeof path);
  switch (path) {
    case PROCAM_RENDER_HOMOGRAPHY:
      s.path = render::RenderPath::kHomography;
      if (!fromRowMajor<3, 3>(v.homography, s.homography)) return bad("non-finite homography");
      break;
    case PROCAM_RENDER_PLANAR_3D:
      s.path = render::RenderPath::kPlanar3d;
      if (!fromRowMajor<4, 4>(v.planar3d, s.planar3d)) return bad("non-finite planar 3D matrix");
      break;
    case PROCAM_RENDER_TWO_PASS_MESH: {
      s.path = render::RenderPath::kTwoPassMesh;
      if (!fromRowMajor<3, 4>(v.projector, s.projector) ||
          !fromRowMajor<3, 4>(v.viewer, s.viewer)) {
        return bad("non-finite projector or viewer matrix");
      }
      if (v.n_surface_vertices > kMaxMeshVertices || v.n_surface_triangles > kMaxMeshTriangles ||
          (v.n_surface_vertices && !v.surface_vertices) ||
          (v.n_surface_triangles && !v.surface_triangles)) {
        return bad("surface mesh too large or missing");
      }
      s.surface.vertices.resize(v.n_surface_vertices);
      for (size_t i = 0; i < v.n_surface_vertices; ++i) {
        s.surface.vertices[i] = Vec3(v.surface_vertices[3 * i], v.surface_vertices[3 * i + 1],
                                     v.surface_vertices[3 * i + 2]);
        if (!s.surface.vertices[i].allFinite()) return bad("non-finite surface vertex");
      }
      s.surface.triangles.resize(v.n_surface_triangles);
      for (size_t t = 0; t < v.n_surface_triangles; ++t) {
        for (int k = 0; k < 3; ++k) {
          const int32_t i = v.surface_triangles[3 * t + k];
          if (i < 0 || size_t(i) >= v.n_surface_vertices) return bad("surface index out of range");
          s.surface.triangles[t][k] = i;
        }
      }
      break;
    }
    case PROCAM_RENDER_LOOKUP_WARP: {
      s.path = render::RenderPath::kLookupWarp;
      auto g = gridFromAbi(v.lookup, s.output_size, "lookup warp");
      if (!g) return tl::unexpected(g.error());
      s.lookup = std::move(*g);
      break;
    }
    default:
      return bad("unknown render path " + std::to_string(path));
  }
  if (s.path != render::RenderPath::kPlanar3d) {
    if (!sizeOk(v.content_width, v.content_height, 2)) return bad("content size out of range");
    s.content_size = cv::Size(int(v.content_width), int(v.content_height));
  }
  if (v.post_warp.cols != 0) {
    auto g = gridFromAbi(v.post_warp, s.output_size, "post-render warp");
    if (!g) return tl::unexpected(g.error());
    s.post_warp = std::move(*g);
  }
  if (v.alpha) {
    if (v.alpha_stride < v.output_width) return bad("alpha mask stride below the output width");
    const cv::Mat view(s.output_size, CV_8UC1, const_cast<uint8_t*>(v.alpha), v.alpha_stride);
    s.final_stage.alpha = view.clone();
  }
  if (v.weight_lut) std::memcpy(s.final_stage.weight_lut.data(), v.weight_lut, 256);
  if (v.output_lut) {
    for (int c = 0; c < 3; ++c)
      std::memcpy(s.final_stage.output_lut[c].data(), v.output_lut + 256 * c, 256);
  }
  if (auto ok = render::validateSetup(s); !ok) return tl::unexpected(ok.error());
  return s;
}

ContentView::ContentView(const cv::Mat* rgba, const render::ColoredMesh* mesh, uint64_t version) {
  // One colour per vertex is the renderers' invariant; a broken mesh is handed over empty.
  if (mesh && mesh->colors.size() != mesh->vertices.size()) mesh = nullptr;
  view_.version = version;
  if (rgba && !rgba->empty()) {
    image_ = procam_image{static_cast<uint32_t>(rgba->cols),
                          static_cast<uint32_t>(rgba->rows),
                          static_cast<uint32_t>(rgba->step[0]),
                          PROCAM_PIXEL_RGBA8,
                          rgba->data,
                          0};
    view_.image = &image_;
  }
  if (mesh) {
    view_.n_mesh_vertices = mesh->vertices.size();
    view_.mesh_vertices = mesh->vertices.empty() ? nullptr : mesh->vertices.front().data();
    view_.mesh_colors = mesh->colors.empty() ? nullptr : mesh->colors.front().val;
    view_.n_mesh_triangles = mesh->triangles.size();
    view_.mesh_triangles = mesh->triangles.empty()
                               ? nullptr
                               : reinterpret_cast<const int32_t*>(mesh->triangles.data());
  }
}

Result<render::Content> contentFromAbi(const procam_content& c, const render::RenderSetup& setup,
                                       cv::Mat& image_header, MeshCache& cache) {
  if (setup.path == render::RenderPath::kPlanar3d) {
    if (cache.version != c.version) {
      const size_t nv = c.n_mesh_vertices, nt = c.n_mesh_triangles;
      if (nv > kMaxMeshVertices || nt > kMaxMeshTriangles || !nv || !nt || !c.mesh_vertices ||
          !c.mesh_colors || !c.mesh_triangles) {
        return fail(ErrorCode::kInvalidInput,
                    "content: the planar 3D path needs a bounded, non-empty coloured mesh");
      }
      render::ColoredMesh m;
      m.vertices.resize(nv);
      m.colors.resize(nv);
      for (size_t i = 0; i < nv; ++i) {
        m.vertices[i] =
            Vec3(c.mesh_vertices[3 * i], c.mesh_vertices[3 * i + 1], c.mesh_vertices[3 * i + 2]);
        if (!m.vertices[i].allFinite())
          return fail(ErrorCode::kInvalidInput, "content: bad vertex");
        std::memcpy(m.colors[i].val, c.mesh_colors + 4 * i, 4);
      }
      m.triangles.resize(nt);
      for (size_t t = 0; t < nt; ++t) {
        for (int k = 0; k < 3; ++k) {
          const int32_t i = c.mesh_triangles[3 * t + k];
          if (i < 0 || size_t(i) >= nv) {
            return fail(ErrorCode::kInvalidInput, "content: mesh index out of range");
          }
          m.triangles[t][k] = i;
        }
      }
      cache.mesh = std::move(m);
      cache.version = c.version;
    }
    return render::Content{nullptr, &cache.mesh, c.version};
  }
  const procam_image* im = c.image;
  if (!im || !im->data || im->format != PROCAM_PIXEL_RGBA8 ||
      int(im->width) != setup.content_size.width || int(im->height) != setup.content_size.height ||
      im->stride < 4ull * im->width) {
    return fail(ErrorCode::kInvalidInput, "content: an RGBA8 image of the setup's content size");
  }
  image_header = cv::Mat(int(im->height), int(im->width), CV_8UC4, im->data, im->stride);
  return render::Content{&image_header, nullptr, c.version};
}

Result<procam_frame_stats> abiFrameStats(const cv::Mat& frame) {
  auto s = render::frameStats(frame);
  if (!s) return tl::unexpected(s.error());
  procam_frame_stats out{};
  out.lit_fraction = s->lit_fraction;
  for (int k = 0; k < 3; ++k) out.mean_rgb[k] = s->mean_rgb[k];
  return out;
}

bool outputRenders(const procam_device& d) {
  return d.family == PROCAM_FAMILY_OUTPUT && d.ops.output && d.ops.output->version >= 2 &&
         d.ops.output->configure && d.ops.output->render;
}

bool outputStops(const procam_device& d) {
  return outputRenders(d) && d.ops.output->version >= 3 && d.ops.output->render_stoppable;
}

bool outputPresentsAt(const procam_device& d) {
  return outputRenders(d) && d.ops.output->version >= 4 && d.ops.output->present_at &&
         d.ops.output->get_timing;
}

std::optional<PresentTiming> outputTiming(const procam_device& d) {
  if (!outputPresentsAt(d)) return std::nullopt;
  PresentTiming t;
  if (d.ops.output->get_timing(d.self, &t.ready_ns, &t.shown_ns, &t.period_ns) != PROCAM_OK) {
    return std::nullopt;
  }
  const bool period_ok =
      t.period_ns == 0 || (t.period_ns >= 1'000'000 && t.period_ns <= 1'000'000'000);
  if (t.ready_ns == 0 || t.shown_ns < t.ready_ns || !period_ok) return std::nullopt;
  return t;
}

}  // namespace procam::plugins
