// Gravity (Kawamoto A12): F = m g on every particle.
#pragma once

#include "dem/force_term.h"

#include <array>

namespace magbrush::dem {

class Gravity : public PerParticleForceTerm
{
public:
  explicit Gravity(const std::array<double, 3> &g) : g_(g) {}
  const char *name() const override { return "gravity"; }
  void add_forces_in_team(const ParticleState &s, ForceBuffers &f, double t) override;

private:
  std::array<double, 3> g_;
};

} // namespace magbrush::dem
