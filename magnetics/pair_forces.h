// The dipole–dipole forces of the near pairs,
//
//     F_dd(k→j) = (3μ0 / 4π r⁴) [ (p_j·r̂)p_k + (p_k·r̂)p_j + (p_j·p_k) r̂ − 5(p_j·r̂)(p_k·r̂) r̂ ],
//
// evaluated once per pair in a parallel loop and stored as the force on the pair's j bead;
// every bead then gathers +F (as j) or −F (as i) over its incident pairs in the list's fixed
// order. Newton's third law holds exactly per pair, and every bead's sum is the same on any
// number of threads. With a hard cutoff the `corrected` model's two-sphere correction of a
// pair is added to the same stored force.
#pragma once

#include "common/state_stream.h"

#include "magnetics/near_pairs.h"
#include "magnetics/two_sphere_correction.h"

#include <cstddef>
#include <vector>

namespace magbrush::magnetics {

class PairForces
{
public:
  // The force of every near pair; `correction` (null for none) adds the two-sphere
  // correction. Returns the number of corrected pairs.
  std::size_t evaluate_all(const InducedState &s, const NearPairs &near,
                           const TwoSphereCorrection *correction);
  // Near pair k's force again; true when it was corrected.
  bool evaluate(const InducedState &s, const NearPairs &near, const TwoSphereCorrection *correction,
                std::size_t k);
  // Adds bead b's share of the stored pair forces to F.
  void add_incident(const NearPairs &near, std::size_t b, double F[3]) const
  {
    add_incident_pair_forces(near.list(), force_, b, F);
  }
  // Pairs were appended to the list: their stored forces start at zero (evaluate() fills them).
  void resize(std::size_t pairs) { force_.resize(3 * pairs, 0.0); }
  // The applied field was scaled by `ratio`: forces by ratio².
  void scale(double ratio2);

  // Restart (common/state_stream.h): everything above, exactly.
  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  std::vector<double> force_; // per pair: the force on its j bead
};

} // namespace magbrush::magnetics
