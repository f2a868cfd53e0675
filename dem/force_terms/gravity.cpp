// Gravity: a per-particle loop, run inside the engine's team (dem/force_term.h, PerParticleForceTerm).
#include "dem/force_terms/gravity.h"

#include "dem/force_terms/force_term_registry.h"

namespace magbrush::dem {

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

namespace {
// On when the case gives a non-zero dem.gravity (Kawamoto's horizontal slab has none).
const bool registered = register_force_term(
    {"gravity", force_term_order::gravity,
     [](const Case &c) -> std::string {
       const auto &g = c.dem.gravity;
       return g[0] == 0.0 && g[1] == 0.0 && g[2] == 0.0 ? "dem.gravity is zero" : "";
     },
     [](const Case &c, const DemSystem &) -> std::unique_ptr<ForceTerm> {
       return std::make_unique<Gravity>(c.dem.gravity);
     }});
} // namespace

} // namespace magbrush::dem
