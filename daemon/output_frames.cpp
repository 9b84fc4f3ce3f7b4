#include "output_frames.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "content/still_sources.hpp"
#include "content/test_pattern.hpp"
#include "render/cpu_renderer.hpp"
#include "render/frame_stats.hpp"

namespace procam::daemon {

namespace {

bool showsPattern(const FrameRequest& r) {
  return r.pattern != "off";
}

// Source pixel centres fitted into the frame's, centred, aspect kept.
Mat3 fitHomography(cv::Size source, cv::Size output) {
  const double s =
      std::min(double(output.width) / source.width, double(output.height) / source.height);
  // Pixel edges map to pixel edges: x_out + 0.5 = s (x_src + 0.5) + offset.
  const double ox = 0.5 * (output.width - s * source.width);
  const double oy = 0.5 * (output.height - s * source.height);
  Mat3 H;
  H << s, 0, ox + 0.5 * s - 0.5, 0, s, oy + 0.5 * s - 0.5, 0, 0, 1;
  return H;
}

// Nothing to show: a black image the size of the smallest content.
std::shared_ptr<const cv::Mat> blackImage() {
  static const auto black = std::make_shared<const cv::Mat>(2, 2, CV_8UC4, cv::Scalar::all(0));
  return black;
}

}  // namespace

procam_image rgbImage(const cv::Mat& rgb) {
  return procam_image{static_cast<uint32_t>(rgb.cols),
                      static_cast<uint32_t>(rgb.rows),
                      static_cast<uint32_t>(rgb.step[0]),
                      PROCAM_PIXEL_RGB8,
                      rgb.data,
                      0};
}

std::shared_ptr<const cv::Mat> patternImage(const std::string& name, cv::Size size) {
  content::RgbImage p = content::renderTestPattern(name, size.width, size.height);
  auto rgba = std::make_shared<cv::Mat>();
  cv::cvtColor(cv::Mat(p.height, p.width, CV_8UC3, p.pixels.data()), *rgba, cv::COLOR_RGB2RGBA);
  return rgba;
}

Result<DecodedContent> decodeContent(const ContentAccess& access, const std::string& path) {
  auto resolved = resolveContentPath(access, path);
  if (!resolved) return tl::unexpected(resolved.error());
  auto bytes = readContentFile(access, *resolved);
  if (!bytes) return tl::unexpected(bytes.error());
  auto source = content::decodeStillImage(*bytes, *resolved, access.limits.image_pixels);
  if (!source) return tl::unexpected(source.error());
  content::Frame frame;
  if (auto r = (*source)->read(frame); !r) return tl::unexpected(r.error());
  return DecodedContent{std::make_shared<const cv::Mat>(content::toRgba(frame)), *resolved};
}

cv::Size sourceSize(const FrameRequest& r) {
  if (!showsPattern(r) && r.content) return r.content->size();
  return r.output_size;
}

Result<PlannedFrame> planFrame(const FrameRequest& r) {
  if (r.output_size.width < 2 || r.output_size.height < 2) {
    return fail(ErrorCode::kInvalidInput, "output frame must be at least 2x2");
  }
  PlannedFrame out;
  out.setup.output_size = r.output_size;
  if (showsPattern(r)) {
    if (!r.pattern_image || r.pattern_image->size() != r.output_size) {
      return fail(ErrorCode::kInvalidInput, "pattern image missing or not of the output size");
    }
    out.image = r.pattern_image;
    out.source = "pattern:" + r.pattern;
  } else if (r.mesh3d && r.mesh3d->mesh) {
    out.setup.path = render::RenderPath::kPlanar3d;
    out.setup.planar3d = r.mesh3d->planar3d;
    out.mesh = r.mesh3d->mesh;
    out.source = "content";
    return out;
  } else if (r.content) {
    if (r.content->type() != CV_8UC4 || r.content->cols < 2 || r.content->rows < 2) {
      return fail(ErrorCode::kInvalidInput, "content must be RGBA of at least 2x2 pixels");
    }
    out.image = r.content;
    out.source = "content";
  } else {
    out.image = blackImage();
    out.source = "none";
  }
  out.setup.path = render::RenderPath::kHomography;
  out.setup.content_size = out.image->size();
  const bool own = out.source != "none" && r.homography;
  out.setup.homography = own ? *r.homography : fitHomography(out.image->size(), r.output_size);
  return out;
}

Result<OutputFrame> renderOutputFrame(const FrameRequest& r) {
  auto plan = planFrame(r);
  if (!plan) return tl::unexpected(plan.error());
  render::CpuRenderer renderer;
  if (auto ok = renderer.configure(plan->setup); !ok) return tl::unexpected(ok.error());
  if (auto ok = renderer.render({plan->image.get(), plan->mesh.get(), 1}); !ok) {
    return tl::unexpected(ok.error());
  }
  OutputFrame out;
  out.rgba = renderer.frame().clone();
  auto st = render::frameStats(out.rgba);
  if (!st) return tl::unexpected(st.error());
  out.stats = {
      plan->source, st->lit_fraction, st->mean_rgb, render::toString(plan->setup.path), {}, {}, -1};
  return out;
}

}  // namespace procam::daemon
