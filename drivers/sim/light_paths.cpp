#include "sim/light_paths.hpp"

#include "sim/renderer.hpp"

namespace procam::sim {

std::size_t LightPaths::size() const {
  std::size_t n = 0;
  for (const Row& r : rows) n += r.paths.size();
  return n;
}

bool LightPaths::consistent() const {
  if (ambient.type() != CV_32FC3 || rows.size() != static_cast<std::size_t>(ambient.rows))
    return false;
  for (const Row& row : rows) {
    if (row.end.size() != static_cast<std::size_t>(ambient.cols)) return false;
    std::uint32_t last = 0;
    for (const std::uint32_t end : row.end) {
      if (end < last) return false;
      last = end;
    }
    if (last > row.paths.size()) return false;
  }
  return true;
}

cv::Mat LightPaths::light(const std::vector<const ProjectorImage*>& images, int threads) const {
  cv::Mat out = ambient.clone();
  forEachRow(out.rows, threads, [&](int y) {
    const Row& row = rows[static_cast<std::size_t>(y)];
    cv::Vec3f* px = out.ptr<cv::Vec3f>(y);
    std::uint32_t k = 0;
    for (int x = 0; x < out.cols; ++x) {
      for (const std::uint32_t end = row.end[static_cast<std::size_t>(x)]; k < end; ++k) {
        const Path& p = row.paths[k];
        const ProjectorImage* image = p.projector < images.size() ? images[p.projector] : nullptr;
        if (image) px[x] += image->sample(p.x, p.y).mul(p.weight);
      }
    }
  });
  return out;
}

}  // namespace procam::sim
