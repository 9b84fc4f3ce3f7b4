#include "sim/camera_response.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace procam::sim {

int CameraResponse::outputType() const {
  return CV_MAKETYPE(spec_.bit_depth <= 8 ? CV_8U : CV_16U, spec_.channels);
}

void CameraResponse::convertRow(const cv::Vec3f* radiance, int row, std::uint64_t seed,
                                cv::Mat& out) const {
  const double max_dn = spec_.maxDn();
  const double full_well = spec_.full_well_e;
  const bool shot = noise_ && full_well > 0;
  const bool read = noise_ && spec_.read_noise_dn > 0;
  const double inv_gamma = 1.0 / spec_.response_gamma;
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(row), 0x70726f63u};
  std::mt19937_64 rng(seq);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int channels = spec_.channels;
  const bool eight_bit = spec_.bit_depth <= 8;

  for (int x = 0; x < out.cols; ++x) {
    for (int c = 0; c < channels; ++c) {
      const double value = channels == 1 ? luminance(radiance[x]) : radiance[x][c];
      // Fraction of the full well; the well saturates at 1.
      double well = std::clamp(spec_.exposure * value, 0.0, 1.0);
      if (shot) {
        // Shot noise: Gaussian with the Poisson variance (= electron count).
        const double electrons = well * full_well;
        well = (electrons + std::sqrt(electrons) * normal(rng)) / full_well;
      }
      double dn = spec_.gain * well * max_dn;
      if (read) dn += spec_.read_noise_dn * normal(rng);
      const double linear = std::clamp(dn / max_dn, 0.0, 1.0);
      const double code =
          std::round(max_dn * (inv_gamma == 1.0 ? linear : std::pow(linear, inv_gamma)));
      if (eight_bit) {
        out.ptr<std::uint8_t>(row)[x * channels + c] = static_cast<std::uint8_t>(code);
      } else {
        out.ptr<std::uint16_t>(row)[x * channels + c] = static_cast<std::uint16_t>(code);
      }
    }
  }
}

}  // namespace procam::sim
