// The flux through a radial line of the roller: the mass (and number) of particles that
// crossed the half-plane θ = θ_L (roller angle) between two successive samples, counted
// from positions alone — each particle's angle relative to the line at the previous sample
// and now, matched by stable id — so it is independent of any counter of the inflow or the
// outflow. A crossing in the sense the sleeve turns counts +, against it −; a particle seen
// at only one of the two samples (it entered or left in between) counts nothing. Between
// samples a particle must move less than a quarter turn (it does, by far).
//
// Also the areal mass around the line: the mass of the particles whose angle lies within
// ±window/2 of it, divided by the sleeve area of the window, R × window × L_z. At a steady
// state the flux equals that areal mass × the sleeve speed × L_z for a layer riding on the
// sleeve (the check of tests/dem/test_particle_flow.cpp).
#pragma once

#include "dem/particle_state.h"

#include "common/state_stream.h"

#include <cstdint>
#include <limits>
#include <vector>

namespace magbrush::dem {

struct LineFluxSample
{
  double time = 0.0;
  double crossed_mass = 0.0; // net mass across the line since the previous sample [kg]
  long crossed = 0;          // net number
  double areal_mass = 0.0;   // in the window [kg/m²]
};

class LineFlux
{
public:
  // `sense` = +1 when the sleeve turns counter-clockwise, −1 otherwise.
  LineFlux(double angle, double sense, double window, double sleeve_radius, double slab_length);

  // Only particles within `r` of the roller axis are seen (the layer on the sleeve, not what
  // falls off it); a particle beyond it at either sample does not cross. Default: all.
  void set_max_radius(double r) { max_radius_ = r; }

  // Counts the crossings since the previous call and the areal mass now.
  LineFluxSample sample(double time, const ParticleState &state);

  // The previous sample the next crossings are counted against (checkpoints).
  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  double angle_, sense_, window_, R_, Lz_;
  double max_radius_ = std::numeric_limits<double>::infinity();
  bool first_ = true;
  // Previous and current sample: id, signed angle from the line, mass; sorted by id.
  struct Seen
  {
    std::int32_t id;
    double angle, mass;
    bool operator<(const Seen &o) const { return id < o.id; }
  };
  std::vector<Seen> before_, now_;
};

} // namespace magbrush::dem
