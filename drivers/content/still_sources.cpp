#include "still_sources.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "image_header.hpp"
#include "test_pattern.hpp"

namespace procam::content {

namespace {

class SingleFrame final : public ContentSource {
 public:
  SingleFrame(cv::Mat pixels, PixelFormat format) : pixels_(std::move(pixels)), format_(format) {}
  cv::Size size() const override { return pixels_.size(); }
  PixelFormat format() const override { return format_; }
  Result<ReadStatus> read(Frame& out) override {
    if (done_) return ReadStatus::kEnd;
    done_ = true;
    out.pixels = pixels_;
    out.format = format_;
    out.timestamp = std::chrono::nanoseconds{0};
    out.sequence = 1;
    return ReadStatus::kFrame;
  }

 private:
  cv::Mat pixels_;
  PixelFormat format_;
  bool done_ = false;
};

}  // namespace

std::unique_ptr<ContentSource> singleFrameSource(cv::Mat pixels, PixelFormat format) {
  return std::make_unique<SingleFrame>(std::move(pixels), format);
}

Result<std::unique_ptr<ContentSource>> openStillImage(const std::string& path,
                                                      std::uint64_t max_pixels) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return fail(ErrorCode::kIo, "cannot read an image from " + path + ": not a regular file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::kIo, "cannot read an image from " + path);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return decodeStillImage(bytes, path, max_pixels);
}

Result<std::unique_ptr<ContentSource>> decodeStillImage(std::string_view bytes,
                                                        const std::string& path,
                                                        std::uint64_t max_pixels) {
  auto header = readImageHeader(bytes);
  if (!header) return fail(ErrorCode::kIo, path + ": " + header.error().message);
  const std::uint64_t pixels =
      std::uint64_t(header->size.width) * std::uint64_t(header->size.height);
  if (pixels > max_pixels) {
    return fail(ErrorCode::kTooLarge, path + ": " + std::to_string(header->size.width) + "x" +
                                          std::to_string(header->size.height) +
                                          " pixels, over the " + std::to_string(max_pixels) +
                                          "-pixel limit");
  }
  if (bytes.size() > std::size_t(std::numeric_limits<int>::max())) {
    return fail(ErrorCode::kTooLarge, path + ": over 2 GiB");
  }
  cv::Mat image;
  try {
    const cv::Mat raw(1, int(bytes.size()), CV_8U, const_cast<char*>(bytes.data()));
    image = cv::imdecode(raw, cv::IMREAD_UNCHANGED);
    if (image.empty()) return fail(ErrorCode::kIo, "cannot read an image from " + path);
    if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257.0);
    if (image.depth() != CV_8U) return fail(ErrorCode::kIo, path + ": unsupported pixel type");
    if (image.cols < 2 || image.rows < 2) {
      return fail(ErrorCode::kIo, path + ": the image must be at least 2x2 pixels");
    }
    static const int kToRgba[] = {0, cv::COLOR_GRAY2RGBA, 0, cv::COLOR_BGR2RGBA,
                                  cv::COLOR_BGRA2RGBA};
    if (image.channels() != 1 && image.channels() != 3 && image.channels() != 4) {
      return fail(ErrorCode::kIo, path + ": unsupported channel count");
    }
    cv::Mat rgba;
    cv::cvtColor(image, rgba, kToRgba[image.channels()]);
    return singleFrameSource(std::move(rgba), PixelFormat::kRgba8);
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kIo, path + ": " + e.what());
  }
}

Result<std::unique_ptr<ContentSource>> openTestPattern(const std::string& name, cv::Size size) {
  static const char* kNames[] = {"grid", "crosshair", "white", "black"};
  if (std::find(std::begin(kNames), std::end(kNames), name) == std::end(kNames)) {
    return fail(ErrorCode::kInvalidInput,
                "unknown test pattern '" + name + "' (grid, crosshair, white, black)");
  }
  if (size.width < 2 || size.height < 2) {
    return fail(ErrorCode::kInvalidInput, "a test pattern must be at least 2x2 pixels");
  }
  RgbImage p = renderTestPattern(name, size.width, size.height);
  cv::Mat rgb = cv::Mat(p.height, p.width, CV_8UC3, p.pixels.data()).clone();
  return singleFrameSource(std::move(rgb), PixelFormat::kRgb8);
}

}  // namespace procam::content
