#include "dem/force_term.h"

namespace magbrush::dem {

void PerParticleForceTerm::add_forces(const ParticleState &state, ForceBuffers &forces, double t)
{
  // The same static split of the particles as inside the engine's team, so the same bits.
#pragma omp parallel if (state.size() > 512)
  add_forces_in_team(state, forces, t);
}

} // namespace magbrush::dem
