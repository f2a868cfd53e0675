// The slab tail correction: the mean field of every dipole beyond a hard cutoff, in a slab
// periodic along two axes and open along the third (normal n̂).
//
// Dipole sums in such a slab converge only like 1/R_c (the truncated rim of a polarised
// layer), so a hard cutoff misses tens of per cent of the force in a brush. Beyond the
// cutoff every bead's periodic images are smeared into a uniform sheet of areal moment
// p_k/A; an infinite uniform dipole sheet has no field off the sheet, so what the cutoff
// misses is minus the disc of that sheet inside the cutoff sphere. The disc field on its
// axis gives, with h_ik = u_k − u_i along n̂,
//
//     B_tail,i = −μ0/(4 R_c A) Σ_k (1 − h_ik²/R_c²)₊ (2 p_k,n n̂ − p_k,t),
//     F_tail,i = n̂ p_i·∂B_tail,i/∂u_i.
//
// Linear in p (so it joins the mutual induction, re-evaluated every sweep), even in h
// (Newton's third law to round-off), and O(N log N): the beads are sorted along n̂ once per
// evaluation and every sweep takes prefix sums of the sheet moments q, q u and q u².
#pragma once

#include "common/state_stream.h"

#include "magnetics/bead_arrays.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

class SlabTail
{
public:
  // box[d] = periodic length (0 = open). Throws unless exactly one axis is open.
  explicit SlabTail(const std::array<double, 3> &box);

  int normal_axis() const { return normal_axis_; }

  // Sorts the beads along the open axis and finds every bead's window |h| < cutoff.
  void prepare(const BeadArrays &beads, double cutoff);
  // The tail field and its derivative along n̂ of the dipoles p (3 per bead).
  void evaluate(const std::vector<double> &p);

  // Bead b's tail field [T] and its derivative along n̂ [T/m] (3 each).
  const double *field(std::size_t b) const { return &B_[3 * b]; }
  const double *normal_derivative(std::size_t b) const { return &dB_[3 * b]; }

  // The dipoles were scaled by `ratio` (a linear ramp of the applied field).
  void scale(double ratio);

  // Restart (common/state_stream.h): everything above, exactly.
  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  std::array<double, 3> box_;
  int normal_axis_ = -1;
  double area_ = 0.0, cutoff_ = 0.0;
  std::vector<std::uint32_t> order_;    // beads sorted along n̂
  std::vector<std::size_t> lo_, hi_;    // their cutoff windows, in sorted positions
  std::vector<double> u_, S0_, S1_, S2_; // sorted coordinates, prefix sums of q, q u, q u²
  std::vector<double> B_, dB_;          // per bead
};

} // namespace magbrush::magnetics
