// A hand-made layer for the sleeve measurements' tests: N beads evenly spaced round the
// sleeve at a height above it, the whole ring turned by an angle (a layer riding on the sleeve
// is this ring turned by ω t).
#pragma once

#include "dem/particle_state.h"

#include <cmath>

namespace magbrush::dem::test_scenes {

// N beads of mass m_each and radius 25 µm on a circle of radius R + h, turned by φ, at z = 0.1 mm.
inline ParticleState sleeve_ring(double R, int n, double h, double phi, double m_each)
{
  ParticleState s;
  const double r = 25e-6, density = m_each / (4.0 / 3.0 * M_PI * r * r * r);
  for (int k = 0; k < n; ++k)
  {
    const double a = phi + 2.0 * M_PI * (k + 0.5) / n;
    s.add({(R + h) * std::cos(a), (R + h) * std::sin(a), 0.1e-3}, r, density, 0, 0.0);
  }
  return s;
}

} // namespace magbrush::dem::test_scenes
