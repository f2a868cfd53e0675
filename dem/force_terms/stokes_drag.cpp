// Stokes drag: a per-particle loop, run inside the engine's team (dem/force_term.h, PerParticleForceTerm).
#include "dem/force_terms/stokes_drag.h"

#include "dem/force_terms/force_term_registry.h"

#include <cmath>

namespace magbrush::dem {

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

namespace {
// On when the air has a viscosity (dem.air_viscosity > 0).
const bool registered = register_force_term(
    {"Stokes drag", force_term_order::stokes_drag,
     [](const Case &c) -> std::string {
       return c.dem.air_viscosity > 0.0 ? "" : "dem.air_viscosity is zero";
     },
     [](const Case &c, const DemSystem &) -> std::unique_ptr<ForceTerm> {
       return std::make_unique<StokesDrag>(c.dem.air_viscosity);
     }});
} // namespace

} // namespace magbrush::dem
