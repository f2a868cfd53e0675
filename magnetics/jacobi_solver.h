// The mutual induction: Jacobi sweeps for the dipoles p_j = α_j B_j, where each bead's local
// field B_j = B_applied,j + Σ_k T_jk p_k (+ far field, + slab tail) depends on every other
// dipole (Kawamoto A9–A11).
//
// A sweep gathers every bead's local field from the OLD dipoles and updates its dipole
// through the induced-moment law (linear, or Fröhlich–Kennelly saturation): order-free
// within a sweep, hence parallel and bit-identical on any number of threads. Sweeps stop
// when max_j |Δp_j| ≤ tolerance · max_j |p_j|, or after max_sweeps.
//
// Plain Jacobi diverges when the coupling matrix αT has an eigenvalue below −1 (a touching
// square monolayer across the field for μr ≳ 24: λ = −β S/8). Under-relaxation
// p ← p + ω (p_Jacobi − p) maps every eigenvalue λ < 1 into the unit circle for small enough
// ω, so ω is halved whenever the largest dipole change grows twice in a row (deterministic:
// it depends on max-reductions only). Eigenvalues ≥ 1 are the point-dipole model's own
// polarisation catastrophe and cannot converge.
#pragma once

#include "magnetics/bead_arrays.h"
#include "magnetics/dipole_physics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

struct JacobiResult
{
  int sweeps = 0;          // sweeps done
  double relaxation = 1.0; // final under-relaxation factor ω (1 = plain Jacobi)
  double residual = 0.0;   // max|Δp| / max|p| of the last sweep
  bool converged = false;  // residual ≤ tolerance within max_sweeps
};

class JacobiSolver
{
public:
  JacobiSolver(double tolerance, int max_sweeps) : tolerance_(tolerance), max_sweeps_(max_sweeps) {}

  // Sweeps the dipoles (3 per bead) to the tolerance, over all beads or over `subset` only
  // (the other dipoles held). local_field(b, p, B) writes bead b's local field from the
  // dipoles p; before_sweep() runs before every sweep (the slab tail follows the dipoles).
  // B_local gets the last gathered local fields; next is work space (3 per bead).
  template <class LocalField, class BeforeSweep>
  JacobiResult solve(const BeadArrays &beads, const std::vector<double> &beta,
                     const std::vector<double> &Ms, std::vector<double> &dipoles,
                     std::vector<double> &next, std::vector<double> &B_local,
                     const LocalField &local_field, const BeforeSweep &before_sweep,
                     const std::vector<std::uint32_t> *subset = nullptr) const;

private:
  double tolerance_;
  int max_sweeps_;
};

template <class LocalField, class BeforeSweep>
JacobiResult JacobiSolver::solve(const BeadArrays &beads, const std::vector<double> &beta,
                                 const std::vector<double> &Ms, std::vector<double> &dipoles,
                                 std::vector<double> &next, std::vector<double> &B_local,
                                 const LocalField &local_field, const BeforeSweep &before_sweep,
                                 const std::vector<std::uint32_t> *subset) const
{
  const std::size_t n = subset ? subset->size() : beads.n;
  JacobiResult result;
  double omega = 1.0, previous_change = 0.0;
  int growth = 0;
  for (int sweep = 1; sweep <= max_sweeps_; ++sweep)
  {
    before_sweep();
    double max_change2 = 0.0, max_p2 = 0.0;
#pragma omp parallel for schedule(static) reduction(max : max_change2, max_p2) if (n >= bead_parallel_threshold)
    for (long m = 0; m < static_cast<long>(n); ++m)
    {
      const std::size_t b = subset ? (*subset)[m] : static_cast<std::size_t>(m);
      double *B = &B_local[3 * b];
      local_field(b, dipoles, B);
      double *p = &next[3 * b];
      induced_moment(beads.radius[b], beta[b], Ms[b], B, p);
      double change2 = 0.0, p2 = 0.0;
      for (int d = 0; d < 3; ++d)
      {
        const double dp = p[d] - dipoles[3 * b + d];
        change2 += dp * dp;
        if (omega != 1.0)
          p[d] = dipoles[3 * b + d] + omega * dp;
        p2 += p[d] * p[d];
      }
      max_change2 = std::max(max_change2, change2);
      max_p2 = std::max(max_p2, p2);
    }
    if (subset) // only the subset's dipoles were updated
      for (const std::uint32_t b : *subset)
        for (int d = 0; d < 3; ++d)
          dipoles[3 * b + d] = next[3 * b + d];
    else
      dipoles.swap(next);
    result.sweeps = sweep;
    result.residual = max_p2 > 0.0 ? std::sqrt(max_change2 / max_p2) : 0.0;
    if (result.residual <= tolerance_)
    {
      result.converged = true;
      break;
    }
    // Divergence shows in the absolute change (it grows like |λ|^k); the relative residual
    // can oscillate without growing twice in a row.
    const double change = std::sqrt(max_change2);
    growth = (sweep > 1 && change > previous_change) ? growth + 1 : 0;
    if (growth >= 2 && omega > 1.0 / 64.0)
    {
      omega *= 0.5;
      growth = 0;
    }
    previous_change = change;
  }
  result.relaxation = omega;
  return result;
}

} // namespace magbrush::magnetics
