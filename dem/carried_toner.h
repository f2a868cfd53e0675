// Toner carried by its carrier: the reduced toner model of a development nip
// (populations[].carried_until_gap).
//
// Most toner in a nip never leaves its carrier: it rides the brush from the inflow to the
// outflow, and only the toner of the carriers that come near the drum can develop. Resolving
// all of it as particles costs most of a development run (each toner is a particle with
// contacts, adhesion and Coulomb pairs, and the smallest of them sets the time step). With
// this model a carrier carries its toner as a count, a mass and a charge: its mass, moment of
// inertia and charge include them (so gravity, inertia, the applied field and Coulomb see the
// developer as it is, to the monopole), and no toner particle exists. When the carrier's
// surface comes within the release gap of the drum surface, its toner is released: placed as
// particles touching its surface at random points (uniform over the sphere, as
// populations[].attached places toner), clear of every particle and wall, each moving with
// the carrier's surface (v + ω × r); from then on they are resolved like any toner, and may
// develop. A toner that finds no room stays carried and is tried again at the next exchange.
//
// Conservation: each release draws the toner's diameters from the population's distribution
// (truncated normal, ±3σ) and scales them so that their mass is exactly the carried mass; the
// charges are drawn from the population's q/m distribution (spread and wrong-sign fraction
// included) and subtracted from the carrier's charge, so the total charge is conserved
// exactly (what the carried charge and the drawn charges differ by stays with the carrier).
//
// Deterministic: the release and the recapture run at the engine's particle exchange
// (serial), in index order, from one random stream that goes into the checkpoint.
//
// Toner that rides out of reach again goes back: a released toner touching a carrier whose
// surface is farther than twice the release gap from the drum (the factor 2 keeps a carrier
// at the edge from releasing and taking back at every exchange) becomes carried toner again.
//
// What the model assumes: toner on a carrier stays there until the drum is within the gap
// (no toner leaves a carrier in the bulk of the brush), and free toner (touching no carrier)
// stays resolved.
#pragma once

#include "dem/neighbour_list.h"
#include "dem/particle_state.h"
#include "dem/size_distribution.h"
#include "dem/wall_contacts.h"

#include "case/case_model.h"

#include <random>
#include <vector>

namespace magbrush::dem {

class CheckpointWriter;
class CheckpointReader;

// The toner population of the case that rides its carriers (carried_until_gap > 0), or −1.
int carried_toner_population(const Case &c);

// Adds toner of mass m and charge q to particle k as carried toner: its mass (and inverse),
// its moment of inertia (the toner as a thin shell on its surface, 2/3 m r²), its charge and
// its carried count, mass and charge. `count` toner at once (m and q their totals).
void load_carried_toner(ParticleState &s, std::size_t k, int count, double m, double q);

class CarriedTonerRelease
{
public:
  // Throws std::invalid_argument naming the key when the case has no carried toner or no drum.
  CarriedTonerRelease(const Case &c, const DemWalls &walls, const PeriodicBox &box);

  // Releases the toner of every carrier whose surface is within the release gap of the drum
  // (except those `leaving` marks, 1 per index): appends the toner to `enter` (which may hold
  // other newcomers already: the toner is placed clear of them) and takes their mass and
  // charge off the carriers in `state` (their number and order unchanged). `t`: the time (for
  // the walls' positions).
  void release(ParticleState &state, double t, const std::vector<char> &leaving, ParticleState &enter);

  // Takes back what rides out of reach again: every toner of the population (not marked in
  // `leaving`) that touches a carrier (surface gap below 2 % of its radius) whose surface is
  // farther than twice the release gap from the drum, the toner itself not within the
  // release gap of the drum, leaves (appended to `leave`, marked in `leaving`) and becomes
  // the carrier's carried toner: its mass, charge and momentum added to the carrier.
  void recapture(ParticleState &state, std::vector<char> &leaving, std::vector<std::int32_t> &leave);

  // One toner at the population's smallest diameter (for the stable time step).
  void smallest_particles(ParticleState &out) const;

  int species() const { return species_; }
  double release_gap() const { return gap_; }
  // Released so far: toner particles placed; taken back so far.
  long released() const { return released_; }
  long recaptured() const { return recaptured_; }

  void write_state(CheckpointWriter &out) const;
  void read_state(CheckpointReader &in);

private:
  Population population_; // a copy: the case need not outlive the release
  const DemWalls &walls_;
  PeriodicBox box_;
  int species_ = -1;
  double density_ = 0.0;
  SizeDistribution size_; // the released toner's diameters [m]
  double gap_ = 0.0;
  double drum_x_ = 0.0, drum_y_ = 0.0, drum_radius_ = 0.0;

  // State (checkpointed).
  std::mt19937_64 rng_;
  long released_ = 0, recaptured_ = 0;

  // Scratch: the particles near the carrier being released (positions, radii).
  std::vector<Vector3> near_x_;
  std::vector<double> near_r_;
  std::vector<double> d_, q_;
  std::vector<char> is_carrier_; // per population

  double drum_gap(const ParticleState &s, std::size_t k) const;
  void gather_near(const ParticleState &state, const ParticleState &enter, std::size_t k);
  bool clear(const Vector3 &p, double r, double t) const;
  void release_carrier(ParticleState &state, std::size_t k, double t, ParticleState &enter);
};

} // namespace magbrush::dem
