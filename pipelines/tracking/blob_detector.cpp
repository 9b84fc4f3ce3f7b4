#include "tracking/blob_detector.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace procam::tracking {
namespace {

struct Moments {
  double w = 0, wx = 0, wy = 0, wxx = 0, wyy = 0, wxy = 0;
};

}  // namespace

Result<std::vector<Blob>> detectBlobs(const cv::Mat& image, const cv::Mat& background,
                                      const BlobOptions& o) {
  if (image.empty() || image.channels() != 1 || (image.depth() != CV_8U && image.depth() != CV_16U))
    return fail(ErrorCode::kInvalidInput, "blob detection needs an 8- or 16-bit mono image");
  if (!background.empty() &&
      (background.size() != image.size() || background.type() != image.type()))
    return fail(ErrorCode::kInvalidInput, "background differs from the image in size or type");
  if (!(o.threshold > 0) || !std::isfinite(o.threshold) || o.min_area < 1 ||
      o.max_area < o.min_area || !(o.max_elongation >= 1) || o.max_blobs < 1)
    return fail(ErrorCode::kInvalidInput, "bad blob options");

  cv::Mat signal;
  image.convertTo(signal, CV_32F);
  if (!background.empty()) {
    cv::Mat bg;
    background.convertTo(bg, CV_32F);
    signal -= bg;
  }
  cv::Mat mask = signal > o.threshold;
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);

  // Area filter first (cheap, from the stats), then one pass for the weighted moments.
  std::vector<char> keep(static_cast<size_t>(n), 0);
  for (int i = 1; i < n; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    keep[static_cast<size_t>(i)] = area >= o.min_area && area <= o.max_area;
  }
  std::vector<Moments> m(static_cast<size_t>(n));
  const double threshold = o.threshold;
  for (int y = 0; y < labels.rows; ++y) {
    const int* lab = labels.ptr<int>(y);
    const float* s = signal.ptr<float>(y);
    for (int x = 0; x < labels.cols; ++x) {
      const int l = lab[x];
      if (l == 0 || !keep[static_cast<size_t>(l)]) continue;
      Moments& a = m[static_cast<size_t>(l)];
      // Weight above the threshold: pixels enter the mask with zero weight, so the
      // mask's jagged, off-centre edge adds no bias to the centroid.
      const double w = s[x] - threshold;
      a.w += w;
      a.wx += w * x;
      a.wy += w * y;
      a.wxx += w * x * x;
      a.wyy += w * y * y;
      a.wxy += w * x * y;
    }
  }

  std::vector<Blob> blobs;
  for (int i = 1; i < n; ++i) {
    const Moments& a = m[static_cast<size_t>(i)];
    if (!keep[static_cast<size_t>(i)] || !(a.w > 0)) continue;
    const double cx = a.wx / a.w, cy = a.wy / a.w;
    // Central second moments; a single pixel has none, so add the pixel's own 1/12.
    const double sxx = std::max(a.wxx / a.w - cx * cx, 0.0) + 1.0 / 12;
    const double syy = std::max(a.wyy / a.w - cy * cy, 0.0) + 1.0 / 12;
    const double sxy = a.wxy / a.w - cx * cy;
    const double mean = 0.5 * (sxx + syy);
    const double half = std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
    const double elongation = std::sqrt((mean + half) / std::max(mean - half, 1e-12));
    if (elongation > o.max_elongation) continue;
    blobs.push_back(Blob{Vec2(cx, cy), stats.at<int>(i, cv::CC_STAT_AREA), a.w, elongation});
  }
  std::sort(blobs.begin(), blobs.end(),
            [](const Blob& a, const Blob& b) { return a.intensity > b.intensity; });
  if (blobs.size() > static_cast<size_t>(o.max_blobs))
    blobs.resize(static_cast<size_t>(o.max_blobs));
  return blobs;
}

}  // namespace procam::tracking
