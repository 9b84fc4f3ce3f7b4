#include "image_header.hpp"

#include <cctype>
#include <cstdint>
#include <string>

namespace procam::content {

namespace {

uint32_t be16(std::string_view b, std::size_t at) {
  return (uint32_t(uint8_t(b[at])) << 8) | uint8_t(b[at + 1]);
}
uint32_t be32(std::string_view b, std::size_t at) {
  return (be16(b, at) << 16) | be16(b, at + 2);
}
uint32_t le16(std::string_view b, std::size_t at) {
  return (uint32_t(uint8_t(b[at + 1])) << 8) | uint8_t(b[at]);
}
uint32_t le32(std::string_view b, std::size_t at) {
  return (le16(b, at + 2) << 16) | le16(b, at);
}

tl::unexpected<Error> bad(const std::string& what) {
  return fail(ErrorCode::kInvalidInput, what);
}

Result<ImageHeader> sized(const char* format, int64_t w, int64_t h) {
  if (w <= 0 || h <= 0 || w > (1 << 30) || h > (1 << 30)) {
    return bad(std::string(format) + " header declares an impossible size");
  }
  return ImageHeader{format, cv::Size(int(w), int(h))};
}

// PNG: the IHDR chunk comes first (PNG spec §5.6, §11.2.2).
Result<ImageHeader> png(std::string_view b) {
  if (b.size() < 24 || b.substr(12, 4) != "IHDR") return bad("truncated PNG header");
  return sized("png", be32(b, 16), be32(b, 20));
}

// JPEG: markers up to the first start-of-frame (SOF0..SOF15 but DHT, JPG, DAC).
Result<ImageHeader> jpeg(std::string_view b) {
  std::size_t at = 2;
  while (at + 4 <= b.size()) {
    if (uint8_t(b[at]) != 0xFF) return bad("JPEG marker expected");
    const uint8_t marker = uint8_t(b[at + 1]);
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length
      at += 2;
      continue;
    }
    const uint32_t length = be16(b, at + 2);
    if (length < 2) return bad("JPEG segment length under 2");
    const bool sof =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      if (at + 9 > b.size()) break;
      return sized("jpeg", be16(b, at + 7), be16(b, at + 5));
    }
    if (marker == 0xD9 || marker == 0xDA) return bad("JPEG without a frame header");
    at += 2 + length;
  }
  return bad("truncated JPEG header");
}

// BMP: BITMAPINFOHEADER (or the 12-byte core header); height negative when top-down.
Result<ImageHeader> bmp(std::string_view b) {
  if (b.size() < 26) return bad("truncated BMP header");
  const uint32_t header = le32(b, 14);
  if (header == 12) return sized("bmp", le16(b, 18), le16(b, 20));
  const int32_t h = int32_t(le32(b, 22));
  return sized("bmp", int32_t(le32(b, 18)), h < 0 ? -int64_t(h) : h);
}

// PNM (P1..P6): width and height are the first two decimal fields after the
// magic, with #-comments and whitespace between.
Result<ImageHeader> pnm(std::string_view b) {
  std::size_t at = 2;
  int64_t value[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    for (;;) {
      while (at < b.size() && std::isspace(uint8_t(b[at]))) ++at;
      if (at < b.size() && b[at] == '#') {
        while (at < b.size() && b[at] != '\n') ++at;
        continue;
      }
      break;
    }
    std::size_t digits = 0;
    while (at < b.size() && std::isdigit(uint8_t(b[at])) && digits < 11) {
      value[k] = value[k] * 10 + (b[at] - '0');
      ++at;
      ++digits;
    }
    if (digits == 0 || digits == 11) return bad("PNM header without a size");
  }
  return sized("pnm", value[0], value[1]);
}

// WebP: RIFF, then a VP8 (lossy), VP8L (lossless) or VP8X (extended) chunk.
Result<ImageHeader> webp(std::string_view b) {
  if (b.size() < 32) return bad("truncated WebP header");
  const std::string_view chunk = b.substr(12, 4);
  if (chunk == "VP8 ") return sized("webp", le16(b, 26) & 0x3FFF, le16(b, 28) & 0x3FFF);
  if (chunk == "VP8L") {
    const uint32_t bits = le32(b, 21);
    return sized("webp", (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1);
  }
  if (chunk == "VP8X") {
    const uint32_t w = (le32(b, 24) & 0xFFFFFF) + 1, h = (le32(b, 27) & 0xFFFFFF) + 1;
    return sized("webp", w, h);
  }
  return bad("WebP without an image chunk");
}

// TIFF: ImageWidth (256) and ImageLength (257) of the first IFD, the page read.
Result<ImageHeader> tiff(std::string_view b) {
  if (b.size() < 8) return bad("truncated TIFF header");
  const bool le = b[0] == 'I';
  auto u16 = [&](std::size_t at) { return le ? le16(b, at) : be16(b, at); };
  auto u32 = [&](std::size_t at) { return le ? le32(b, at) : be32(b, at); };
  const std::size_t ifd = u32(4);
  if (ifd > b.size() || b.size() - ifd < 2) return bad("truncated TIFF directory");
  const std::size_t entries = u16(ifd);
  int64_t size[2] = {0, 0};
  for (std::size_t i = 0; i < entries; ++i) {
    const std::size_t at = ifd + 2 + 12 * i;
    if (at + 12 > b.size()) return bad("truncated TIFF directory");
    const uint32_t tag = u16(at), type = u16(at + 2), count = u32(at + 4);
    if (tag != 256 && tag != 257) continue;
    // One SHORT or LONG held in the entry, as the decoder reads it; a repeated tag
    // or another type could make the decoder see a size other than the one checked.
    if (size[tag - 256] != 0) return bad("TIFF directory repeats the image size");
    if (count != 1 || (type != 3 && type != 4)) return bad("TIFF image size of an unusual type");
    size[tag - 256] = type == 3 ? u16(at + 8) : u32(at + 8);
  }
  return sized("tiff", size[0], size[1]);
}

}  // namespace

Result<ImageHeader> readImageHeader(std::string_view b) {
  if (b.size() >= 8 && b.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8)) return png(b);
  if (b.size() >= 3 && uint8_t(b[0]) == 0xFF && uint8_t(b[1]) == 0xD8 && uint8_t(b[2]) == 0xFF)
    return jpeg(b);
  if (b.size() >= 2 && b.substr(0, 2) == "BM") return bmp(b);
  if (b.size() >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6') return pnm(b);
  if (b.size() >= 12 && b.substr(0, 4) == "RIFF" && b.substr(8, 4) == "WEBP") return webp(b);
  if (b.size() >= 4 && (b.substr(0, 4) == std::string_view("II*\0", 4) ||
                        b.substr(0, 4) == std::string_view("MM\0*", 4)))
    return tiff(b);
  return bad("not an image procamd reads (PNG, JPEG, BMP, PNM, WebP, TIFF)");
}

}  // namespace procam::content
