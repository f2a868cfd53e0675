// Following particles across the periodic boundaries. The engine wraps every position back
// into the box; a term that keeps data by position between steps (a held far field, the
// references of a staleness test) needs continuous paths instead. A particle moves far less
// than half a period per step, so of the images of its engine position the one nearest to its
// previous unwrapped position is its new unwrapped position.
#pragma once

#include "dem/particle_state.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace magbrush::dem {

// The image of the engine coordinate `raw` nearest to the previous unwrapped coordinate
// `last`, along an axis of period L (0: not periodic, `raw` itself).
inline double nearest_image(double raw, double last, double L)
{
  const double jump = last - raw; // a multiple of L after a wrap, else a step's move
  return (L > 0.0 && std::abs(jump) > 0.5 * L) ? raw + L * std::round(jump / L) : raw;
}

// unwrapped[d][k] ← the image of the engine coordinate d of particle index[k] nearest to
// unwrapped[d][k] (d = x, y, z; a box length of 0 means not periodic: the engine coordinate).
inline void follow_unwrapped(const ParticleState &state, const std::vector<std::uint32_t> &index,
                             const std::array<double, 3> &box, std::vector<double> *const unwrapped[3])
{
  const std::vector<double> *engine[3] = {&state.x, &state.y, &state.z};
  for (int d = 0; d < 3; ++d)
  {
    const double L = box[static_cast<std::size_t>(d)];
    const double *from = engine[d]->data();
    double *to = unwrapped[d]->data();
    if (L > 0.0)
      for (std::size_t k = 0; k < index.size(); ++k)
        to[k] = nearest_image(from[index[k]], to[k], L);
    else
      for (std::size_t k = 0; k < index.size(); ++k)
        to[k] = from[index[k]];
  }
}

} // namespace magbrush::dem
