// The electric charges of the particles. Toner is charged triboelectrically against the
// carrier: each toner particle carries q = (q/m) m, with its own q/m drawn around the
// population's mean (a normal spread, truncated so that the spread alone never flips the
// sign) and a small fraction of "wrong-sign" toner whose charge is reversed (a few per cent
// in real developer). The carrier keeps the opposite charge (Kweon: "the carrier has the
// opposite charge"): a carrier population marked `counter_charge` carries together minus the
// total toner charge, so that the developer as a whole is neutral. The carriers share it in
// proportion to their surface area, where the toner touched them.
//
// The charges are drawn from a random stream of their own (seeded from dem.seed), so that a
// spread or a wrong-sign fraction changes no particle's size or position.
#pragma once

#include "dem/particle_state.h"

#include "case/case_model.h"

#include <random>
#include <vector>

namespace magbrush::dem {

// The random stream of the charges of a case (independent of the insertion's).
std::mt19937_64 charge_random_stream(const Case &c);

// One particle's q/m [C/kg] after population `p`: the mean, its truncated normal spread and
// the wrong-sign fraction. Holds its distributions, so that successive draws from one object
// are one stream (a normal distribution keeps the second of each pair it generates).
class ChargeToMassDraw
{
public:
  explicit ChargeToMassDraw(const Population &p);
  double operator()(std::mt19937_64 &rng);

private:
  double mean_ = 0.0, std_ = 0.0, wrong_ = 0.0;
  std::normal_distribution<double> spread_;
  std::bernoulli_distribution wrong_sign_;
};

// Charges [C] of particles of population `p` with the given diameters [m] and density
// [kg/m³], in the order of `diameters`. Counter-charged carriers get 0 here (see below).
std::vector<double> draw_charges(const Population &p, const std::vector<double> &diameters, double density,
                                 std::mt19937_64 &rng);

// Gives the particles of every counter-charged carrier population the opposite of the total
// charge of all other particles, shared in proportion to their surface area. Sums run in
// particle-index order (deterministic). No-op when no population is counter-charged.
void assign_counter_charges(const Case &c, ParticleState &particles);

} // namespace magbrush::dem
