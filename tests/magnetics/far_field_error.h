// How the far-field tests measure an error: RMS over the beads of |X_far − (X_ref − X_near)|
// divided by RMS |X_ref − X_near|, i.e. relative to the far part itself (the near part is
// exact by construction). X is any per-bead field component array (potential, field,
// gradient), laid out alike in the three vectors.
#pragma once

#include <cmath>
#include <vector>

namespace magbrush::magnetics::testing {

inline double far_field_rms_error(const std::vector<double> &far, const std::vector<double> &near,
                                  const std::vector<double> &ref)
{
  double e = 0.0, r = 0.0;
  for (std::size_t k = 0; k < far.size(); ++k)
  {
    const double want = ref[k] - near[k];
    e += (far[k] - want) * (far[k] - want);
    r += want * want;
  }
  return std::sqrt(e / r);
}

} // namespace magbrush::magnetics::testing
