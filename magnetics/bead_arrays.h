// The inputs and outputs of the magnetics, as plain structure-of-arrays views on the
// caller's memory (SI units): the carrier beads, where their forces are added, and the
// applied field. Every collaborator of InducedDipoles reads beads through these.
#pragma once

#include <cstddef>
#include <functional>

namespace magbrush::magnetics {

// The applied field: B [T] and its gradient gradB[a][b] = ∂B_a/∂x_b [T/m] at a point [m].
// Called concurrently from several threads: it must be thread-safe (read-only).
using AppliedFieldFunction =
  std::function<void(const double x[3], double B[3], double gradB[3][3])>;

// A uniform applied field (no gradient): the compression test and the verification tests.
AppliedFieldFunction uniform_field(double Bx, double By, double Bz);

// The carrier beads (structure of arrays, n entries each; SI units).
struct BeadArrays
{
  std::size_t n = 0;
  const double *x = nullptr, *y = nullptr, *z = nullptr;
  const double *radius = nullptr;
  const double *mu_r = nullptr;                     // relative permeability per bead
  const double *saturation_magnetisation = nullptr; // M_s [A/m] per bead; null or 0 = linear
};

// Where the forces (and optionally torques) are ADDED. Torque pointers may be null.
struct ForceArrays
{
  double *fx = nullptr, *fy = nullptr, *fz = nullptr;
  double *tx = nullptr, *ty = nullptr, *tz = nullptr;
};

// Below this many beads (or pairs) a loop runs on one thread: forking a team costs more than
// it saves, and far more on an oversubscribed machine. The results do not depend on it.
constexpr std::size_t bead_parallel_threshold = 512;

// Σ radius over the beads [m], summed in bead order (the mean diameter 2Σ/n is the unit of
// the skin, the cutoff and the cell size).
inline double radius_sum(const BeadArrays &beads)
{
  double sum = 0.0;
  for (std::size_t b = 0; b < beads.n; ++b)
    sum += beads.radius[b];
  return sum;
}

} // namespace magbrush::magnetics
