// Conversion of device formats into the pipeline's, against values computed by hand.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "camera/convert.hpp"

namespace procam::camera {
namespace {

TEST(Convert, GreyIsWrappedWithoutACopy) {
  std::vector<uint8_t> px = {1, 2, 3, 0, 4, 5, 6, 0};  // 3x2 with stride 4
  cv::Mat storage;
  Frame f;
  ASSERT_TRUE(convertFrame({SourceFormat::kGrey, px.data(), px.size(), 3, 2, 4}, PROCAM_PIXEL_GRAY8,
                           true, storage, f));
  EXPECT_EQ(f.copies, 0);
  EXPECT_EQ(f.image.data, px.data());
  EXPECT_EQ(f.image.at<uint8_t>(1, 2), 6);
  ASSERT_TRUE(convertFrame({SourceFormat::kGrey, px.data(), px.size(), 3, 2, 4}, PROCAM_PIXEL_GRAY8,
                           false, storage, f));
  EXPECT_EQ(f.copies, 1);
  EXPECT_NE(f.image.data, px.data());
  EXPECT_EQ(f.image.at<uint8_t>(1, 0), 4);
}

TEST(Convert, Y16KeepsSixteenBitsAndScalesToEight) {
  std::vector<uint16_t> px = {0, 65535, 257 * 100, 1000};
  const auto* bytes = reinterpret_cast<const uint8_t*>(px.data());
  cv::Mat storage;
  Frame f;
  ASSERT_TRUE(
      convertFrame({SourceFormat::kY16, bytes, 8, 2, 2, 4}, PROCAM_PIXEL_GRAY16, true, storage, f));
  EXPECT_EQ(f.image.type(), CV_16UC1);
  EXPECT_EQ(f.image.at<uint16_t>(1, 1), 1000);
  ASSERT_TRUE(
      convertFrame({SourceFormat::kY16, bytes, 8, 2, 2, 4}, PROCAM_PIXEL_GRAY8, true, storage, f));
  EXPECT_EQ(f.image.type(), CV_8UC1);
  EXPECT_EQ(f.image.at<uint8_t>(0, 1), 255);
  EXPECT_EQ(f.image.at<uint8_t>(1, 0), 100);
}

TEST(Convert, YuyvBecomesRgbAndGray) {
  // Neutral chroma (128): R = G = B = 255/219 (Y - 16), BT.601 limited range, the
  // quantisation V4L2 gives YUYV by default.
  std::vector<uint8_t> px = {50, 128, 200, 128};  // two pixels: Y0=50, Y1=200
  cv::Mat storage;
  Frame f;
  ASSERT_TRUE(convertFrame({SourceFormat::kYuyv, px.data(), 4, 2, 1, 4}, PROCAM_PIXEL_RGB8, true,
                           storage, f));
  ASSERT_EQ(f.image.type(), CV_8UC3);
  EXPECT_EQ(f.copies, 1);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(f.image.at<cv::Vec3b>(0, 0)[c], (50 - 16) * 255.0 / 219.0, 1);
    EXPECT_NEAR(f.image.at<cv::Vec3b>(0, 1)[c], (200 - 16) * 255.0 / 219.0, 1);
  }
  // Red chroma (V high) puts more in R than in B: the channel order is RGB.
  px = {100, 128, 100, 200};
  ASSERT_TRUE(convertFrame({SourceFormat::kYuyv, px.data(), 4, 2, 1, 4}, PROCAM_PIXEL_RGB8, true,
                           storage, f));
  EXPECT_GT(f.image.at<cv::Vec3b>(0, 0)[0], f.image.at<cv::Vec3b>(0, 0)[2] + 50);
  ASSERT_TRUE(convertFrame({SourceFormat::kYuyv, px.data(), 4, 2, 1, 4}, PROCAM_PIXEL_GRAY8, true,
                           storage, f));
  EXPECT_NEAR(f.image.at<uint8_t>(0, 1), (100 - 16) * 255.0 / 219.0, 0.6);
}

TEST(Convert, MjpegDecodesToRgb) {
  cv::Mat bgr(16, 24, CV_8UC3, cv::Scalar(30, 60, 200));  // B G R
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
  cv::Mat storage;
  Frame f;
  ASSERT_TRUE(convertFrame({SourceFormat::kMjpeg, jpeg.data(), jpeg.size(), 24, 16, 0},
                           PROCAM_PIXEL_RGB8, true, storage, f));
  const cv::Vec3b p = f.image.at<cv::Vec3b>(8, 12);
  EXPECT_NEAR(p[0], 200, 4);  // R first
  EXPECT_NEAR(p[2], 30, 4);
  // A size that is not the negotiated one, and bytes that are not a JPEG.
  EXPECT_FALSE(convertFrame({SourceFormat::kMjpeg, jpeg.data(), jpeg.size(), 32, 16, 0},
                            PROCAM_PIXEL_RGB8, true, storage, f));
  jpeg.assign(100, 7);
  auto bad = convertFrame({SourceFormat::kMjpeg, jpeg.data(), jpeg.size(), 24, 16, 0},
                          PROCAM_PIXEL_RGB8, true, storage, f);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);
}

TEST(Convert, TruncatedBufferIsRefused) {
  std::vector<uint8_t> px(10);
  cv::Mat storage;
  Frame f;
  auto r = convertFrame({SourceFormat::kGrey, px.data(), px.size(), 4, 4, 4}, PROCAM_PIXEL_GRAY8,
                        true, storage, f);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::camera
