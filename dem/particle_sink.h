// The outflow: particles removed from a roller scene during the run (case keys outflow.*,
// case/case_keys_flow.cpp): those in a sector of the sleeve downstream — from
// outflow.angle over outflow.width in the sense the sleeve turns, at any distance from the
// axis — and those farther than outflow.outer_radius from the roller axis (they left the
// window the scene describes). Counts what it removed per population; the counts go into
// checkpoints.
#pragma once

#include "dem/particle_state.h"

#include "case/case_model.h"

#include <cstdint>
#include <vector>

namespace magbrush::dem {

class CheckpointWriter;
class CheckpointReader;

class ParticleSink
{
public:
  explicit ParticleSink(const Case &c);

  // True when a particle at p is in the removal region.
  bool removes(const Vector3 &p) const;
  // Appends the indices of the particles in the removal region to `leave` and counts them.
  void select(const ParticleState &state, std::vector<std::int32_t> &leave);

  // Removed so far, per population index: number and mass [kg].
  const std::vector<long> &removed_count() const { return count_; }
  const std::vector<double> &removed_mass() const { return mass_; }

  void write_state(CheckpointWriter &out) const;
  void read_state(CheckpointReader &in);

private:
  double angle_ = 0.0, width_ = 0.0, sense_ = 1.0, outer_radius_ = 0.0;
  std::size_t carried_ = 0; // the population of the toner carriers carry (carried_toner.h), if any
  std::vector<long> count_;
  std::vector<double> mass_;
};

} // namespace magbrush::dem
