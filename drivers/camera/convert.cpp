#include "camera/convert.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace procam::camera {

const char* toString(SourceFormat format) {
  switch (format) {
    case SourceFormat::kGrey:
      return "GREY";
    case SourceFormat::kY16:
      return "Y16";
    case SourceFormat::kYuyv:
      return "YUYV";
    case SourceFormat::kMjpeg:
      return "MJPEG";
    case SourceFormat::kRgb24:
      return "RGB24";
    case SourceFormat::kBgr24:
      return "BGR24";
  }
  return "unknown";
}

procam_pixel_format naturalPixel(SourceFormat format) {
  switch (format) {
    case SourceFormat::kGrey:
      return PROCAM_PIXEL_GRAY8;
    case SourceFormat::kY16:
      return PROCAM_PIXEL_GRAY16;
    default:
      return PROCAM_PIXEL_RGB8;
  }
}

std::optional<procam_pixel_format> parsePixel(const std::string& text) {
  if (text == "gray8") return PROCAM_PIXEL_GRAY8;
  if (text == "gray16") return PROCAM_PIXEL_GRAY16;
  if (text == "rgb8") return PROCAM_PIXEL_RGB8;
  return std::nullopt;
}

const char* toString(procam_pixel_format pixel) {
  switch (pixel) {
    case PROCAM_PIXEL_GRAY8:
      return "gray8";
    case PROCAM_PIXEL_GRAY16:
      return "gray16";
    case PROCAM_PIXEL_RGB8:
      return "rgb8";
    case PROCAM_PIXEL_RGBA8:
      return "rgba8";
  }
  return "unknown";
}

namespace {

int cvType(procam_pixel_format pixel) {
  switch (pixel) {
    case PROCAM_PIXEL_GRAY16:
      return CV_16UC1;
    case PROCAM_PIXEL_RGB8:
      return CV_8UC3;
    case PROCAM_PIXEL_RGBA8:
      return CV_8UC4;
    default:
      return CV_8UC1;
  }
}

uint32_t minStride(SourceFormat f, uint32_t width) {
  switch (f) {
    case SourceFormat::kGrey:
      return width;
    case SourceFormat::kY16:
    case SourceFormat::kYuyv:
      return 2 * width;
    default:
      return 3 * width;
  }
}

// The source's own pixels as a Mat header (no copy).
cv::Mat wrap(const SourceImage& s) {
  const int type = s.format == SourceFormat::kGrey   ? CV_8UC1
                   : s.format == SourceFormat::kY16  ? CV_16UC1
                   : s.format == SourceFormat::kYuyv ? CV_8UC2
                                                     : CV_8UC3;
  return cv::Mat(int(s.height), int(s.width), type, const_cast<uint8_t*>(s.data), s.stride);
}

}  // namespace

Result<void> convertFrame(const SourceImage& src, procam_pixel_format want, bool zero_copy,
                          cv::Mat& storage, Frame& out) {
  if (src.width == 0 || src.height == 0 || !src.data)
    return fail(ErrorCode::kInvalidInput, std::string("empty ") + toString(src.format) + " frame");
  out.pixel = want;
  if (src.format == SourceFormat::kMjpeg) {
    // imdecode gives BGR (or gray); one more pass to RGB is the conversion.
    const cv::Mat bytes(1, int(src.bytes), CV_8UC1, const_cast<uint8_t*>(src.data));
    if (want == PROCAM_PIXEL_GRAY16)
      return fail(ErrorCode::kInvalidInput, "MJPEG frames are 8-bit; gray16 is not possible");
    const int flags = want == PROCAM_PIXEL_GRAY8 ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR;
    cv::Mat decoded = cv::imdecode(bytes, flags);
    if (decoded.empty()) return fail(ErrorCode::kInvalidInput, "MJPEG frame does not decode");
    if (uint32_t(decoded.cols) != src.width || uint32_t(decoded.rows) != src.height)
      return fail(ErrorCode::kInvalidInput, "MJPEG frame is " + std::to_string(decoded.cols) + "x" +
                                                std::to_string(decoded.rows) + ", expected " +
                                                std::to_string(src.width) + "x" +
                                                std::to_string(src.height));
    if (want == PROCAM_PIXEL_RGB8)
      cv::cvtColor(decoded, storage, cv::COLOR_BGR2RGB);
    else
      storage = decoded;
    out.image = storage;
    out.copies = 1;
    return {};
  }
  const uint32_t row = minStride(src.format, src.width);
  if (src.stride < row || src.bytes < std::size_t(src.stride) * (src.height - 1) + row)
    return fail(ErrorCode::kInvalidInput,
                std::string(toString(src.format)) + " frame of " + std::to_string(src.bytes) +
                    " bytes is too short for " + std::to_string(src.width) + "x" +
                    std::to_string(src.height));
  const cv::Mat in = wrap(src);
  const procam_pixel_format natural = naturalPixel(src.format);
  if (want == natural && src.format != SourceFormat::kYuyv && src.format != SourceFormat::kBgr24) {
    if (zero_copy) {
      out.image = in;
      out.copies = 0;
    } else {
      in.copyTo(storage);
      out.image = storage;
      out.copies = 1;
    }
    return {};
  }
  storage.create(int(src.height), int(src.width), cvType(want));
  switch (src.format) {
    case SourceFormat::kGrey:
      if (want == PROCAM_PIXEL_RGB8)
        cv::cvtColor(in, storage, cv::COLOR_GRAY2RGB);
      else
        in.convertTo(storage, CV_16U, 257.0);  // 255 -> 65535: full scale stays full scale
      break;
    case SourceFormat::kY16:
      if (want == PROCAM_PIXEL_GRAY8) {
        in.convertTo(storage, CV_8U, 1.0 / 257.0);
      } else {
        cv::Mat gray8;
        in.convertTo(gray8, CV_8U, 1.0 / 257.0);
        cv::cvtColor(gray8, storage, cv::COLOR_GRAY2RGB);
      }
      break;
    case SourceFormat::kYuyv:
      if (want == PROCAM_PIXEL_RGB8) {
        cv::cvtColor(in, storage, cv::COLOR_YUV2RGB_YUYV);
      } else if (want == PROCAM_PIXEL_GRAY8) {
        // Y is limited range (16..235) like the RGB path assumes: stretch it the same way.
        cv::cvtColor(in, storage, cv::COLOR_YUV2GRAY_YUYV);
        storage.convertTo(storage, CV_8U, 255.0 / 219.0, -16.0 * 255.0 / 219.0);
      } else {
        return fail(ErrorCode::kInvalidInput, "YUYV frames are 8-bit; gray16 is not possible");
      }
      break;
    case SourceFormat::kRgb24:
    case SourceFormat::kBgr24: {
      const bool bgr = src.format == SourceFormat::kBgr24;
      if (want == PROCAM_PIXEL_RGB8)
        bgr ? cv::cvtColor(in, storage, cv::COLOR_BGR2RGB) : in.copyTo(storage);
      else if (want == PROCAM_PIXEL_GRAY8)
        cv::cvtColor(in, storage, bgr ? cv::COLOR_BGR2GRAY : cv::COLOR_RGB2GRAY);
      else
        return fail(ErrorCode::kInvalidInput, "8-bit colour frames cannot become gray16");
      break;
    }
    case SourceFormat::kMjpeg:
      break;
  }
  out.image = storage;
  out.copies = 1;
  return {};
}

}  // namespace procam::camera
