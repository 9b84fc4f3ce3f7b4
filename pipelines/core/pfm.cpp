#include "core/pfm.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>

namespace procam {
namespace {

uint32_t littleEndian(uint32_t bits) {
  if constexpr (std::endian::native == std::endian::big) return __builtin_bswap32(bits);
  return bits;
}

}  // namespace

Result<std::string> encodePfm(const cv::Mat& image) {
  if (image.empty() || (image.type() != CV_32FC1 && image.type() != CV_32FC3))
    return fail(ErrorCode::kInvalidInput, "PFM: a CV_32FC1 or CV_32FC3 image is needed");
  const int n = image.channels();
  std::string out = std::string(n == 3 ? "PF" : "Pf") + "\n" + std::to_string(image.cols) + " " +
                    std::to_string(image.rows) + "\n-1.0\n";
  const std::size_t header = out.size();
  out.resize(header + image.total() * n * sizeof(float));
  char* p = out.data() + header;
  for (int row = image.rows - 1; row >= 0; --row) {  // the bottom row first
    const float* src = image.ptr<float>(row);
    for (int i = 0; i < image.cols * n; ++i, p += 4) {
      const uint32_t bits = littleEndian(std::bit_cast<uint32_t>(src[i]));
      std::memcpy(p, &bits, 4);
    }
  }
  return out;
}

Result<cv::Mat> decodePfm(std::string_view bytes, double max_pixels) {
  // The header: three whitespace-separated tokens after the magic, one byte of white space.
  std::istringstream in{std::string(bytes.substr(0, std::min<std::size_t>(bytes.size(), 256)))};
  std::string magic;
  long w = 0, h = 0;
  double scale = 0;
  if (!(in >> magic >> w >> h >> scale) || (magic != "PF" && magic != "Pf") || w <= 0 || h <= 0 ||
      scale == 0)
    return fail(ErrorCode::kParse, "PFM: malformed header");
  if (double(w) * double(h) > max_pixels) return fail(ErrorCode::kTooLarge, "PFM: too many pixels");
  const std::streamoff end_of_scale = in.tellg();
  if (end_of_scale < 0) return fail(ErrorCode::kParse, "PFM: no data after the header");
  const std::size_t header = std::size_t(end_of_scale) + 1;
  const int n = magic == "PF" ? 3 : 1;
  const std::size_t need = std::size_t(w) * std::size_t(h) * n * 4;
  if (bytes.size() < header + need) return fail(ErrorCode::kParse, "PFM: body shorter than header");
  cv::Mat out(int(h), int(w), n == 3 ? CV_32FC3 : CV_32FC1);
  const char* p = bytes.data() + header;
  const bool little = scale < 0;
  for (int row = int(h) - 1; row >= 0; --row) {
    float* dst = out.ptr<float>(row);
    for (long i = 0; i < w * n; ++i, p += 4) {
      uint32_t bits;
      std::memcpy(&bits, p, 4);
      if (little != (std::endian::native == std::endian::little)) bits = __builtin_bswap32(bits);
      dst[i] = std::bit_cast<float>(bits);
      if (!std::isfinite(dst[i])) return fail(ErrorCode::kParse, "PFM: a sample is not finite");
    }
  }
  return out;
}

}  // namespace procam
