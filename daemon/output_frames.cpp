#include "output_frames.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "content/still_sources.hpp"
#include "content/test_pattern.hpp"
#include "render/cpu_renderer.hpp"

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

FrameStats statsOf(const cv::Mat& rgb) {
  FrameStats st;
  cv::Mat maxc;
  std::vector<cv::Mat> ch;
  cv::split(rgb, ch);
  cv::max(ch[0], ch[1], maxc);
  cv::max(maxc, ch[2], maxc);
  st.lit_fraction = double(cv::countNonZero(maxc)) / double(rgb.total());
  const cv::Scalar m = cv::mean(rgb);
  st.mean_rgb = {m[0], m[1], m[2]};
  return st;
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

Result<std::shared_ptr<const cv::Mat>> decodeContent(const std::string& path) {
  auto source = content::openStillImage(path);
  if (!source) return tl::unexpected(source.error());
  content::Frame frame;
  if (auto r = (*source)->read(frame); !r) return tl::unexpected(r.error());
  return std::make_shared<const cv::Mat>(content::toRgba(frame));
}

cv::Size sourceSize(const FrameRequest& r) {
  if (!showsPattern(r) && r.content) return r.content->size();
  return r.output_size;
}

Result<OutputFrame> renderOutputFrame(const FrameRequest& r) {
  if (r.output_size.width < 2 || r.output_size.height < 2) {
    return fail(ErrorCode::kInvalidInput, "output frame must be at least 2x2");
  }
  OutputFrame out;
  cv::Mat source;
  if (showsPattern(r)) {
    content::RgbImage p =
        content::renderTestPattern(r.pattern, r.output_size.width, r.output_size.height);
    cv::cvtColor(cv::Mat(p.height, p.width, CV_8UC3, p.pixels.data()), source, cv::COLOR_RGB2RGBA);
    out.stats.source = "pattern:" + r.pattern;
  } else if (r.mesh3d && r.mesh3d->mesh) {
    out.stats.source = "content";
  } else if (r.content) {
    if (r.content->type() != CV_8UC4 || r.content->cols < 2 || r.content->rows < 2) {
      return fail(ErrorCode::kInvalidInput, "content must be RGBA of at least 2x2 pixels");
    }
    source = *r.content;
    out.stats.source = "content";
  } else {
    out.rgb = cv::Mat(r.output_size, CV_8UC3, cv::Scalar::all(0));
    out.stats.source = "none";
    return out;
  }
  render::RenderSetup setup;
  setup.output_size = r.output_size;
  render::Content content{&source, nullptr, 1};
  if (source.empty()) {
    setup.path = render::RenderPath::kPlanar3d;
    setup.planar3d = r.mesh3d->planar3d;
    content = {nullptr, r.mesh3d->mesh.get(), 1};
  } else {
    setup.content_size = source.size();
    setup.path = render::RenderPath::kHomography;
    setup.homography = r.homography ? *r.homography : fitHomography(source.size(), r.output_size);
  }
  render::CpuRenderer renderer;
  if (auto ok = renderer.configure(setup); !ok) return tl::unexpected(ok.error());
  if (auto ok = renderer.render(content); !ok) {
    return tl::unexpected(ok.error());
  }
  cv::Mat rgba;
  if (auto ok = renderer.readFrame(rgba); !ok) return tl::unexpected(ok.error());
  cv::cvtColor(rgba, out.rgb, cv::COLOR_RGBA2RGB);
  const std::string source_name = out.stats.source;
  out.stats = statsOf(out.rgb);
  out.stats.source = source_name;
  return out;
}

}  // namespace procam::daemon
