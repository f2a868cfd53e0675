// The bins of sleeve angle shared by the profiles along the sleeve (chain inclination, brush
// height): nip.chain_bin_angle wide, one centred on the line of centres, out to
// ±nip.chain_half_angle. Bin i (0 … size()−1) has its centre at (i − half) × width.
#pragma once

#include "case/case_model.h"

#include <cmath>
#include <cstddef>
#include <cstdlib>

namespace magbrush::dem {

struct SleeveAngleBins
{
  double width = 0.0; // [rad]
  int half = 0;       // bins on each side of the centre one

  explicit SleeveAngleBins(const NipSettings &s)
      : width(s.chain_bin_angle), half(static_cast<int>(std::lround(s.chain_half_angle / s.chain_bin_angle)))
  {
  }
  std::size_t size() const { return static_cast<std::size_t>(2 * half + 1); }
  // The bin of sleeve angle theta [rad]; −1 outside the profile.
  int of(double theta) const
  {
    const long k = std::lround(theta / width);
    return std::abs(k) > half ? -1 : static_cast<int>(k) + half;
  }
  double centre(std::size_t i) const { return (static_cast<double>(i) - half) * width; }
};

} // namespace magbrush::dem
