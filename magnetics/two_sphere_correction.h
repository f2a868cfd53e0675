// The short range of the `corrected` model: the exact two-sphere force minus the isolated-pair
// mutual-dipole force, added to every pair closer than switch_end mean radii.
//
// Point dipoles miss the multipoles that two nearly touching spheres induce in each other:
// at contact (μr 3.9) the exact attraction along the field is 2.6× the point-dipole force,
// mutual dipoles give 1.3×. For a pair at centre distance D = d/ā (ā the mean radius) in the
// local field H it sits in,
//
//     ΔF = w(D) μ0 ā² (a_i a_j/ā²)³ [ (Δf∥ H_r² + Δf⊥ |H_t|²) r̂ − Δf_t H_r H_t ],
//     H = ½[(B_i − T p_j) + (B_j − T p_i)]/μ0   (each bead's local field without its partner),
//
// with Δf = f_exact − f_mutual from the identical-sphere table at the pair's mean β
// (two_sphere_table.h), w = 1 below switch_begin and a C¹ smoothstep to 0 at switch_end.
// Exact for an isolated pair in a uniform field; unequal beads are rescaled by the dipole
// scaling (a_i a_j)³/ā⁶ (0.35 % at a radius ratio of 0.8).
//
// With a hard cutoff the corrected pairs are among the near pairs. With the cell-multipole
// far field a pair within switch_end may sit in fine cells two apart, so the correction then
// keeps a short Verlet list of its own (every pair within switch_end × its mean radius +
// skin, searched on cells of switch_end × the largest radius + skin) and stores
// its pair forces like the near pairs: once per pair, applied ± (Newton's third law exact).
#pragma once

#include "common/state_stream.h"

#include "magnetics/bead_arrays.h"
#include "magnetics/dipole_physics.h"
#include "magnetics/magnetic_neighbour_list.h"
#include "magnetics/magnetic_settings.h"
#include "magnetics/two_sphere_table.h"

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

namespace magbrush::magnetics {

// What the correction reads of the solved beads: β, the local fields B_j and the dipoles
// p_j (3 per bead, interleaved).
struct InducedState
{
  const BeadArrays &beads;
  const std::vector<double> &beta;
  const std::vector<double> &local_field;
  const std::vector<double> &p;
};

class TwoSphereCorrection
{
public:
  TwoSphereCorrection(const MagneticSettings &settings, const std::array<double, 3> &box);

  // One table per distinct pair β (mean of the two beads' β); almost always one material.
  void prepare_tables(const std::vector<double> &beta);
  bool has_tables() const { return !tables_.empty(); }

  // Adds the correction of pair (i, j), r = x_j − x_i, T = T(r), to F (the force on j);
  // false when the pair is beyond switch_end.
  bool add(const InducedState &s, std::uint32_t i, std::uint32_t j, const double r[3],
           const DipoleTensor &T, double F[3]) const;

  // The own pair list (cell-multipole far field): rebuilt when stale, like a Verlet list.
  void refresh_list(const BeadArrays &beads);
  // Beads appended (indices first … n−1): their pairs within reach join the list (a
  // brute-force search over all beads and their periodic images: a handful of
  // newcomers, every image within reach, however many periods the reach spans), their forces
  // start at zero. False, and nothing changed, when the list is not current or its radius
  // does not cover the newcomers (larger beads).
  bool can_admit(const BeadArrays &beads, std::size_t first) const;
  bool admit(const BeadArrays &beads, std::size_t first);
  // The list still holds every pair within switch_end (no bead moved half the skin).
  bool list_current(const BeadArrays &beads, double skin) const;
  const MagneticNeighbourList &list() const { return list_; }
  // The forces of every listed pair (returns how many were within switch_end), or of pair k.
  std::size_t evaluate_list_forces(const InducedState &s);
  bool evaluate_list_force(const InducedState &s, std::size_t k);
  // Adds bead b's share of the stored list forces to F.
  void add_incident_forces(std::size_t b, double F[3]) const;
  // The applied field was scaled by `ratio`: forces by ratio².
  void scale_forces(double ratio2);
  // Forget the list (the caller re-sorted its beads).
  void forget_list() { list_.clear(); } // (keeps the buffers for the next build)

  // Restart (common/state_stream.h): the own list and its stored forces; the tables are
  // prepared again from β (they depend on nothing else).
  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  MagneticSettings settings_;
  std::array<double, 3> box_;
  std::map<double, std::shared_ptr<const TwoSphereTable>> tables_;
  MagneticNeighbourList list_;
  std::vector<double> force_; // per listed pair: the force on its j bead
  double skin_ = 0.0;         // the skin the list was built with [m]
  std::vector<MagneticNeighbourList::Pair> admitted_; // admit(): scratch

  const TwoSphereTable *table(double beta_i, double beta_j) const;
};

// Adds to F the stored forces of the pairs of `list` incident to bead b. A pair's force is
// stored as the force on its j bead; its i bead gets the negative (Newton's third law,
// exact). The list's fixed incidence order makes the sum the same on any number of threads.
void add_incident_pair_forces(const MagneticNeighbourList &list, const std::vector<double> &pair_force,
                              std::size_t b, double F[3]);

} // namespace magbrush::magnetics
