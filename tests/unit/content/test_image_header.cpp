// Image sizes read from headers alone: every format procamd decodes gives the
// size OpenCV encoded, truncated and unknown headers are refused, and a decode
// over the pixel limit is refused before the decoder runs.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "content/image_header.hpp"
#include "content/still_sources.hpp"

namespace procam::content {
namespace {

std::string encoded(const std::string& ext, cv::Size size, int type = CV_8UC3) {
  std::vector<uchar> bytes;
  cv::Mat m(size, type, cv::Scalar::all(90));
  EXPECT_TRUE(cv::imencode(ext, m, bytes)) << ext;
  return std::string(bytes.begin(), bytes.end());
}

TEST(ImageHeader, EveryReadFormatGivesItsSize) {
  const cv::Size size(37, 23);
  const std::pair<const char*, const char*> formats[] = {{".png", "png"},   {".jpg", "jpeg"},
                                                         {".bmp", "bmp"},   {".ppm", "pnm"},
                                                         {".webp", "webp"}, {".tiff", "tiff"}};
  for (const auto& [ext, name] : formats) {
    const std::string bytes = encoded(ext, size);
    auto h = readImageHeader(bytes);
    ASSERT_TRUE(h) << ext << ": " << h.error().message;
    EXPECT_STREQ(h->format, name);
    EXPECT_EQ(h->size, size) << ext;
  }
  // Grey PGM and lossless WebP (its other header).
  auto pgm = readImageHeader(encoded(".pgm", {5, 9}, CV_8UC1));
  ASSERT_TRUE(pgm);
  EXPECT_EQ(pgm->size, cv::Size(5, 9));
  std::vector<uchar> lossless;
  ASSERT_TRUE(cv::imencode(".webp", cv::Mat(cv::Size(41, 17), CV_8UC3, cv::Scalar::all(1)),
                           lossless, {cv::IMWRITE_WEBP_QUALITY, 101}));
  auto webp = readImageHeader(std::string(lossless.begin(), lossless.end()));
  ASSERT_TRUE(webp) << webp.error().message;
  EXPECT_EQ(webp->size, cv::Size(41, 17));
}

TEST(ImageHeader, TruncatedUnknownAndImpossibleHeadersAreRefused) {
  const std::string png = encoded(".png", {8, 8});
  for (const std::string& bytes :
       {png.substr(0, 20), encoded(".jpg", {8, 8}).substr(0, 6), std::string("GIF89a....."),
        std::string("P6 12"), std::string(), std::string("BM")}) {
    auto h = readImageHeader(bytes);
    EXPECT_FALSE(h) << bytes.size() << " bytes";
    if (!h) {
      EXPECT_EQ(h.error().code, ErrorCode::kInvalidInput);
    }
  }
  std::string zero = png;
  for (int i = 16; i < 20; ++i) zero[i] = 0;  // width 0
  EXPECT_FALSE(readImageHeader(zero));
}

// A TIFF directory read as the decoder reads it: a repeated size tag or a size of
// another type than one SHORT or LONG is refused (the decoder might see another size).
TEST(ImageHeader, TiffSizeMustBeUnambiguous) {
  auto tiff = [](std::initializer_list<std::array<uint32_t, 4>> entries) {
    std::string b("II*\0\x08\0\0\0", 8);
    auto le = [&](uint32_t v, int bytes) {
      for (int i = 0; i < bytes; ++i) b += char((v >> (8 * i)) & 0xFF);
    };
    le(uint32_t(entries.size()), 2);
    for (const auto& [tag, type, count, value] : entries) {
      le(tag, 2), le(type, 2), le(count, 4), le(value, 4);
    }
    le(0, 4);
    return b;
  };
  auto ok = readImageHeader(tiff({{256, 3, 1, 640}, {257, 4, 1, 480}}));
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->size, cv::Size(640, 480));
  EXPECT_FALSE(readImageHeader(tiff({{256, 4, 1, 60000}, {256, 3, 1, 2}, {257, 3, 1, 2}})));
  EXPECT_FALSE(readImageHeader(tiff({{256, 16, 1, 8}, {257, 3, 1, 2}})));  // LONG8: an offset
  EXPECT_FALSE(readImageHeader(tiff({{256, 3, 2, 8}, {257, 3, 1, 2}})));
}

TEST(ImageHeader, DecodeOverThePixelLimitIsRefusedFromTheHeader) {
  const std::string png = encoded(".png", {100, 50});
  auto ok = decodeStillImage(png, "a.png", 5000);
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ((*ok)->size(), cv::Size(100, 50));
  auto refused = decodeStillImage(png, "a.png", 4999);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::kTooLarge);
  EXPECT_NE(refused.error().message.find("100x50"), std::string::npos) << refused.error().message;
  // A header that lies about a huge size costs nothing: refused before decoding.
  std::string lie = png;
  lie[16] = 0x00, lie[17] = 0x00, lie[18] = 0x75, lie[19] = 0x30;  // width 30000
  lie[20] = 0x00, lie[21] = 0x00, lie[22] = 0x75, lie[23] = 0x30;  // height 30000
  auto big = decodeStillImage(lie, "lie.png");
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().code, ErrorCode::kTooLarge);
}

}  // namespace
}  // namespace procam::content
