// Gravity and Stokes drag (Kawamoto A12). Both are per-particle loops that run inside the
// engine's team (add_forces_in_team); add_forces() opens a region of its own for callers
// outside one (initialize(), tests).
#include "force_term.h"

#include <cmath>

namespace magbrush::dem {

void Gravity::add_forces(const ParticleState &s, ForceBuffers &f, double t)
{
#pragma omp parallel if (s.size() > 512)
  add_forces_in_team(s, f, t);
}

void Gravity::add_forces_in_team(const ParticleState &s, ForceBuffers &f, double)
{
  const long n = static_cast<long>(s.size());
#pragma omp for schedule(static) nowait
  for (long i = 0; i < n; ++i)
  {
    const std::size_t k = static_cast<std::size_t>(i);
    f.fx[k] += s.mass[k] * g_[0];
    f.fy[k] += s.mass[k] * g_[1];
    f.fz[k] += s.mass[k] * g_[2];
  }
}

void StokesDrag::add_forces(const ParticleState &s, ForceBuffers &f, double t)
{
#pragma omp parallel if (s.size() > 512)
  add_forces_in_team(s, f, t);
}

void StokesDrag::add_forces_in_team(const ParticleState &s, ForceBuffers &f, double)
{
  const long n = static_cast<long>(s.size());
  const double c = 6.0 * M_PI * eta_;
#pragma omp for schedule(static) nowait
  for (long i = 0; i < n; ++i)
  {
    const std::size_t k = static_cast<std::size_t>(i);
    const double b = c * s.radius[k];
    f.fx[k] -= b * s.vx[k];
    f.fy[k] -= b * s.vy[k];
    f.fz[k] -= b * s.vz[k];
  }
}

} // namespace magbrush::dem
