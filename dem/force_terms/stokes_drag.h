// Stokes drag of still air (Kawamoto A12): F = −6π η r v on every particle.
#pragma once

#include "dem/force_term.h"

namespace magbrush::dem {

class StokesDrag : public PerParticleForceTerm
{
public:
  explicit StokesDrag(double viscosity) : eta_(viscosity) {}
  const char *name() const override { return "Stokes drag"; }
  void add_forces_in_team(const ParticleState &s, ForceBuffers &f, double t) override;

private:
  double eta_;
};

} // namespace magbrush::dem
