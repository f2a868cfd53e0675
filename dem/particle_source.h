// The inflow: developer fed onto the sleeve during the run, the way the sleeve carries it out
// of the sump past the doctor blade (case keys inflow.*, case/case_keys_flow.cpp).
//
// A layer of developer mass per sleeve area Γ (DMA) rides on the sleeve surface, which moves
// at v = ω R. Over a time τ the surface carries the arc R Δφ past the entry angle θ_in, with
// Δφ = ∫ω dt (the sleeve's spin-up ramp included), so the source owes the mass
//
//     Δm = Γ R Δφ L_z        (mass flux Γ v L_z, L_z the periodic slab length)
//
// and places it in that arc, θ_in … θ_in + Δφ (in the sense of rotation; at least two bead
// diameters long, since an exchange every few steps sweeps far less than a bead), within
// inflow.layer_height of the surface: carriers of the fed population, drawn from its size
// distribution, at random (uniform in area), without overlap with the particles present, the
// walls or each other. The previous exchange's particles have moved on by Δφ with the sleeve,
// so the arc is free. Each new particle moves rigidly with the sleeve (v = ω ẑ × x, ω ẑ).
// Toner populations that give a concentration TC come attached: each carrier brings toner of
// mass TC × its own mass, touching its surface at random points (a toner that does not fit
// is owed to the next carrier), or, for toner that rides its carrier (carried_until_gap),
// as part of the carrier's mass and charge (dem/carried_toner.h). The carriers' share of Γ is
// Γ / (1 + ΣTC). Charges as at insertion (dem/particle_charges.h): each toner its population's
// q/m (spread and wrong-sign fraction included) times its mass; a counter-charged carrier
// minus the charge of the toner it brings, so that the developer fed is neutral, carrier by
// carrier.
//
// What is owed and not placed (a drawn diameter that did not fit, mass below one particle)
// stays owed: over a run the mass created follows Γ R φ(t) L_z to within one particle.
// With inflow.supply: sump the inflow stands for a sump that OFFERS Γ: when the entry arc has
// no room (the pile in front of a doctor blade has backed up to it), what is owed beyond the
// fraction of a particle is declined and counted (declined_mass), and the mass picked up is
// what the flow report measures. The random stream, the mass owed and the counts are written
// into checkpoints.
//
// With inflow.sump_mass the sump is finite and closed: it holds that developer per slab length
// at the start (carriers and each toner in the feed's proportions, each a stock of its own),
// the inflow draws on it — a carrier or toner particle is only created while its stock holds
// its mass — and everything the outflow removes goes back into it (return_to_sump). Mass in
// the scene plus mass in the sump is then constant over any number of revolutions.
//
// With inflow.prefill_arc the sleeve already carries the layer at the start: the same areal
// mass, placed the same way over the arc θ_in … θ_in ± prefill_arc (downstream), so that the
// run does not spend a transit time bringing the first developer to where it is measured.
// Where a drum leaves the layer no room, the prefill is refused, or thinned to what fits there
// and downstream of it (inflow.prefill_where_no_room), so that it can fill a nip.
// Those particles are part of the initial state (not counted as created), at rest when the
// scene settles first (dem.settle_time) and moving with the sleeve otherwise.
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

class ParticleSource
{
public:
  // Throws std::invalid_argument naming the key when the case cannot feed (no sleeve, no
  // slab, no carrier population, a layer too thin for the particles).
  ParticleSource(const Case &c, const DemWalls &walls, const PeriodicBox &box);

  // Appends to `enter` the particles owed for the arc the sleeve swept since the last call
  // (the first call counts from t = 0); `state` is the scene now (for the overlap test).
  void create(const ParticleState &state, double t, ParticleState &enter);

  // Appends to `add` the layer over the prefill arc (nothing without one); `present` is the
  // scene as inserted. Throws std::invalid_argument naming inflow.prefill_arc and the angle
  // where the layer does not fit (a wall nearer the sleeve than the layer allows).
  void prefill(const ParticleState &present, ParticleState &add);

  // Prefilled at the start: number and mass of carriers and toner together.
  long prefilled_count() const { return prefilled_count_; }
  double prefilled_mass() const { return prefilled_mass_; }
  // A thinned prefill (inflow.prefill_where_no_room: thin): the carrier mass of the layer that
  // found no room [kg], and the fraction of the layer that passed its narrowest place (1: it
  // fitted everywhere).
  double prefill_thinned_mass() const { return prefill_thinned_mass_; }
  double prefill_passed_fraction() const { return prefill_passed_; }
  double prefill_narrowest_angle() const { return prefill_narrowest_; } // [rad] (roller angle)
  // ... and the carrier mass the pieces past the narrowest place were not given [kg] (the
  // layer that did not pass): prefilled carriers + thinned + withheld = the layer's carriers.
  double prefill_withheld_mass() const { return prefill_withheld_mass_; }

  // One particle per fed population at its smallest diameter (for the stable time step).
  void smallest_particles(ParticleState &out) const;

  // Offered by a sump (inflow.supply: sump) and left there for want of room so far [kg].
  double declined_mass() const { return declined_mass_; }

  // A finite sump (inflow.sump_mass): whether there is one, the mass it holds now [kg], and
  // the return of a removed particle of population `species` and mass m to it.
  bool finite_sump() const { return finite_sump_; }
  double sump_stock() const;
  void return_to_sump(int species, double m);

  // Created so far, per population index: number and mass [kg].
  const std::vector<long> &created_count() const { return count_; }
  const std::vector<double> &created_mass() const { return mass_; }
  // The sleeve's rotation angle since t = 0 [rad] (signed), and the mass owed for it:
  // Γ R |φ(t)| L_z [kg].
  double sleeve_rotation(double t) const;
  double mass_due(double t) const { return areal_mass_ * R_ * std::abs(sleeve_rotation(t)) * Lz_; }

  void write_state(CheckpointWriter &out) const;
  void read_state(CheckpointReader &in);

private:
  struct Feed
  {
    int species = 0;
    Population population; // a copy (the case need not outlive the source): q/m, counter-charge
    double density = 0.0;
    SizeDistribution size; // diameters [m]
    double concentration = 0.0; // toner: mass per carrier mass
    bool carried = false;       // toner: rides the carrier as its mass and charge (carried_toner.h)
  };
  Feed carrier_;
  std::vector<Feed> toner_;
  const DemWalls &walls_;
  PeriodicBox box_;
  double R_ = 0.0, Lz_ = 0.0, height_ = 0.0, theta_in_ = 0.0, omega_ = 0.0, spin_up_ = 0.0;
  double areal_mass_ = 0.0, carrier_share_ = 1.0;
  bool sump_ = false; // inflow.supply: sump
  double prefill_arc_ = 0.0;
  bool prefill_thins_ = false; // inflow.prefill_where_no_room: thin
  double prefill_thinned_mass_ = 0.0, prefill_passed_ = 1.0, prefill_narrowest_ = 0.0;
  double prefill_withheld_mass_ = 0.0;
  bool finite_sump_ = false;
  bool drawing_ = false; // creating the run's inflow (not the prefill): draws on a finite sump
  bool prefill_at_rest_ = false;
  long prefilled_count_ = 0;
  double prefilled_mass_ = 0.0;

  // State (checkpointed).
  std::mt19937_64 rng_;
  double t_last_ = 0.0;
  double owed_carrier_ = 0.0;
  std::vector<double> owed_toner_;
  double pending_d_ = 0.0; // a carrier diameter drawn and not yet placed (0: none)
  double declined_mass_ = 0.0;
  std::vector<double> stock_; // a finite sump's stock per population index [kg]
  std::vector<long> count_;
  std::vector<double> mass_;

  // Scratch: the particles near the arc (positions, radii), this exchange's included.
  std::vector<Vector3> near_x_;
  std::vector<double> near_r_;

  double draw_diameter(const Feed &f);
  bool clear_of_everything(const Vector3 &p, double r) const;
  void gather_near(const ParticleState &state, double theta0, double dphi);
  bool place_carrier(double d, double theta0, double dphi, double t, ParticleState &enter);
  void add_near(const ParticleState &state, double theta0, double dphi);
  bool fill_owed(double t, double theta0, double span, bool may_decline, ParticleState &enter);
  void check_owed() const;
  void attach_toner(const Vector3 &centre, double rc, double t, ParticleState &enter);
  void append(const Feed &f, const Vector3 &p, double d, double t, double charge, ParticleState &enter);
  void count_created(const Feed &f, double m);
  bool in_stock(const Feed &f, double m) const;
};

} // namespace magbrush::dem
