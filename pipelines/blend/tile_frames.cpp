#include "blend/tile_frames.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "render/bilinear.hpp"
#include "render/cpu_renderer.hpp"

namespace procam::blend {
namespace {

// The daemon's frame: CPU reference renderer, the share's geometry and final stage.
Result<cv::Mat> rendererFrame(const cv::Mat& content, render::RenderSetup setup,
                              const BlendTables& blend, std::size_t t, bool geometry_only) {
  cv::Mat rgba;
  const int code = content.channels() == 1   ? cv::COLOR_GRAY2RGBA
                   : content.channels() == 3 ? cv::COLOR_BGR2RGBA
                                             : cv::COLOR_BGRA2RGBA;
  cv::cvtColor(content, rgba, code);
  setup.output_size = blend.alpha[t].size();
  setup.content_size = content.size();
  if (!geometry_only) {
    setup.final_stage.alpha = blend.alpha[t];
    setup.final_stage.weight_lut = blend.weight_lut[t];
  }
  render::CpuRenderer cpu;
  if (auto ok = cpu.configure(setup); !ok) return tl::unexpected(ok.error());
  if (auto drawn = cpu.render({&rgba, nullptr, 1}); !drawn) return tl::unexpected(drawn.error());
  cv::Mat out;
  cv::cvtColor(cpu.frame(), out,
               content.channels() == 1 ? cv::COLOR_RGBA2GRAY : cv::COLOR_RGBA2BGR);
  return out;
}

}  // namespace

bool sampleContent(const cv::Mat& img, double x, double y, double* out) {
  if (!render::insideFootprint(x, y, img.cols, img.rows)) return false;
  x = std::clamp(x, 0.0, double(img.cols - 1));
  y = std::clamp(y, 0.0, double(img.rows - 1));
  const int x0 = std::min(int(x), std::max(img.cols - 2, 0));
  const int y0 = std::min(int(y), std::max(img.rows - 2, 0));
  const int x1 = std::min(x0 + 1, img.cols - 1), y1 = std::min(y0 + 1, img.rows - 1);
  const double fx = x - x0, fy = y - y0;
  const int n = img.channels();
  const double* r0 = img.ptr<double>(y0);
  const double* r1 = img.ptr<double>(y1);
  for (int c = 0; c < n; ++c) {
    const double top = r0[x0 * n + c] * (1 - fx) + r0[x1 * n + c] * fx;
    const double bottom = r1[x0 * n + c] * (1 - fx) + r1[x1 * n + c] * fx;
    out[c] = top * (1 - fy) + bottom * fy;
  }
  return true;
}

Result<cv::Mat> unitContent(const cv::Mat& content) {
  if (content.empty() || (content.depth() != CV_8U && content.depth() != CV_16U) ||
      (content.channels() != 1 && content.channels() != 3 && content.channels() != 4))
    return fail(ErrorCode::kInvalidInput, "content: 8 or 16 bit, 1, 3 or 4 channels");
  cv::Mat src;
  if (content.channels() == 4) {
    cv::cvtColor(content, src, cv::COLOR_BGRA2BGR);
  } else {
    src = content;
  }
  cv::Mat unit;
  src.convertTo(unit, CV_MAKETYPE(CV_64F, src.channels()),
                1.0 / (content.depth() == CV_8U ? 255 : 65535));
  return unit;
}

Result<std::function<std::optional<Vec2>(double, double)>> shareContent(
    const render::RenderSetup& geometry) {
  if (geometry.path == render::RenderPath::kLookupWarp) {
    return [&grid = geometry.lookup](double x, double y) {
      return render::gridSource(grid, Vec2(x, y));
    };
  }
  if (geometry.path != render::RenderPath::kHomography)
    return fail(ErrorCode::kInvalidInput, "a share is drawn by homography or lookup warp");
  const Eigen::FullPivLU<Mat3> lu(geometry.homography);
  if (!lu.isInvertible()) return fail(ErrorCode::kInvalidInput, "the homography is singular");
  const Mat3 inverse = lu.inverse();
  return [inverse](double x, double y) -> std::optional<Vec2> {
    const Vec3 p = inverse * Vec3(x, y, 1);
    if (!(p.z() > 0)) return std::nullopt;
    return Vec2(p.x() / p.z(), p.y() / p.z());
  };
}

Result<cv::Mat> shareFrame(const cv::Mat& content, const render::RenderSetup& geometry,
                           const BlendTables& blend, std::size_t t,
                           const TileFrameOptions& options) {
  if (content.empty() || (content.depth() != CV_8U && content.depth() != CV_16U) ||
      (content.channels() != 1 && content.channels() != 3 && content.channels() != 4))
    return fail(ErrorCode::kInvalidInput, "content: 8 or 16 bit, 1, 3 or 4 channels");
  if (options.bit_depth != 8 && options.bit_depth != 16)
    return fail(ErrorCode::kInvalidInput, "bit depth must be 8 or 16");
  if (t >= blend.alpha.size() || t >= blend.weight_lut.size() || t >= blend.gamma.size() ||
      t >= blend.gain.size())
    return fail(ErrorCode::kInvalidInput, "projector index out of range");
  auto to_content = shareContent(geometry);
  if (!to_content) return tl::unexpected(to_content.error());
  if (options.bit_depth == 8 && content.depth() == CV_8U) {
    return rendererFrame(content, geometry, blend, t, options.geometry_only);
  }
  if (!options.geometry_only && t >= blend.weights.size())
    return fail(ErrorCode::kInvalidInput, "the blend was made without its weights");
  const cv::Size size = blend.alpha[t].size();
  auto unit = unitContent(content);
  if (!unit) return tl::unexpected(unit.error());
  const cv::Mat& src = *unit;
  const int channels = src.channels();
  const double top = options.bit_depth == 8 ? 255 : 65535;
  cv::Mat out(size, CV_MAKETYPE(options.bit_depth == 8 ? CV_8U : CV_16U, channels),
              cv::Scalar::all(0));
  const double gamma = blend.gamma[t], gain = blend.gain[t];
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
    double v[3];
    for (int y = rows.start; y < rows.end; ++y) {
      for (int x = 0; x < size.width; ++x) {
        const auto p = (*to_content)(x, y);
        if (!p || !sampleContent(src, p->x(), p->y(), v)) continue;
        // Emitted light goes as code^gamma: (gain w)^(1/gamma) scales it by gain w.
        const double scale = options.geometry_only
                                 ? 1.0
                                 : std::pow(gain * blend.weights[t].at<float>(y, x), 1.0 / gamma);
        for (int c = 0; c < channels; ++c) {
          const double code = std::clamp(std::round(v[c] * scale * top), 0.0, top);
          if (options.bit_depth == 8) {
            out.ptr<uint8_t>(y)[x * channels + c] = uint8_t(code);
          } else {
            out.ptr<uint16_t>(y)[x * channels + c] = uint16_t(code);
          }
        }
      }
    }
  });
  return out;
}

Result<cv::Mat> tileFrame(const cv::Mat& content, const TiledBlend& blend, std::size_t t,
                          const TileFrameOptions& options) {
  if (t >= blend.display.content_to_framebuffer.size())
    return fail(ErrorCode::kInvalidInput, "tile index out of range");
  render::RenderSetup geometry;
  geometry.path = render::RenderPath::kHomography;
  geometry.homography = blend.display.content_to_framebuffer[t];
  return shareFrame(content, geometry, blend, t, options);
}

Result<cv::Mat> curvedFrame(const cv::Mat& content, const CurvedBlend& blend, std::size_t t,
                            const TileFrameOptions& options) {
  if (t >= blend.display.lookup.size())
    return fail(ErrorCode::kInvalidInput, "projector index out of range");
  render::RenderSetup geometry;
  geometry.path = render::RenderPath::kLookupWarp;
  geometry.lookup = blend.display.lookup[t];
  return shareFrame(content, geometry, blend, t, options);
}

}  // namespace procam::blend
