// The particle–particle pair kernel of the DEM step: the contact law (contact_law.h) for a
// range of pairs of the neighbour list, written so that it vectorises.
//
// The half list stores each pair once, row by row (rows in particle order), so a range of
// rows is a contiguous range of pairs. Rows are cut into fixed blocks (independent of the
// thread count). For each block:
//   * the pair kernel computes every pair's contact: the force on i (kept in the pair's slot,
//     the partner needs it too), the torque on i (into a small per-thread buffer: only the
//     row needs it) and the torque on j (into the pair's slot);
//   * while that is still in cache, each row of the block sums its pairs: force and torque
//     of particle i from its own pairs, in pair order.
// After a barrier each particle sums the pairs in which it is the partner (its column, in
// ascending pair order, from zero) and adds that sum to its row's. The order of every sum is
// fixed by the list alone, so the forces have the same bits on any number of threads, with
// no atomics.
//
// On one thread the same sums are formed without the per-pair slots and the second pass:
// rows are finished in particle order, and a pair (i, j) always has i < j, so when row i
// is reached every pair in i's column has been seen. Each block's forces stay in a small
// scratch; each pair subtracts its force from its partner's column sum at once (ascending
// pair order, from zero, as the column pass does), and row i ends with column + row. Same
// bits as on two threads, one stream of the pairs instead of two.
//
// The kernel's loop body is branch-free (a pair that does not touch goes through the same
// arithmetic at a harmless stand-in geometry and its outputs are selected to zero), so it
// vectorises; an AVX-512 or AVX2 clone is picked at load time where the CPU has one. Vector
// and scalar code give the same bits: every operation is an IEEE add, multiply, divide or
// square root in the same order, and fused multiply-adds are off (dem/CMakeLists.txt).
#pragma once

#include <cstdint>

namespace magbrush::dem {

struct PairKernelData
{
  // Particles (read).
  const double *x, *y, *z, *vx, *vy, *vz, *wx, *wy, *wz, *radius, *mass, *inv_inertia;
  const std::int32_t *species;
  // Pairs (read).
  const std::int32_t *owner, *partner;
  const std::int32_t *image;
  const double *shift_x, *shift_y, *shift_z; // by image code
  // Coefficients by interaction type (species s, t at s * table_columns + t), one array per
  // field so that the vector code can gather them. `uniform`: one type only (one species),
  // then the coefficients are loop constants and nothing is gathered.
  const double *effective_modulus, *effective_shear, *friction, *rolling_friction, *damping_normal,
      *damping_tangential;
  std::int64_t table_columns;
  bool uniform;
  double dt, overlap_guard;
  // Pairs (read and write): history; (write) force on i, torque on j, touching flag.
  double *hx, *hy, *hz;
  double *fx, *fy, *fz, *tjx, *tjy, *tjz;
  std::int32_t *touching;
  // Van der Waals adhesion (contact_law.h, HamakerAdhesion) by interaction type, like the
  // coefficients. `adhesive`: some particle pair sticks; then pairs closer than contact +
  // adhesion_range attract, touching or not. Scenes without it run the kernel without these
  // lines at all (a template parameter, chosen once per call), so they cost nothing there.
  const double *hamaker, *asperity_i, *asperity_j;
  double adhesion_cutoff, adhesion_range;
  bool adhesive;
  // Pair p's force on i and torque on j go to fx[p − slot_base] … tjz[p − slot_base]: 0 when
  // they are the list's own per-pair slots (the column phase reads them later), the block's
  // first pair when they are a block's scratch (the one-thread path consumes them at once).
  std::int64_t slot_base = 0;
  // Pairs left to another pass (the toner's substeps, dem/toner_substeps.h): skip[p] = 1 gives
  // pair p zero force and torques here and leaves its history and touching flag as they are.
  // nullptr: every pair is computed (a kernel without these lines: a template parameter).
  const std::int32_t *skip = nullptr;
};

// Torque on i of the pairs p_begin + k, k = 0 .. block size (a per-thread buffer).
struct RowTorques
{
  double *x, *y, *z;
};

// The kernel for pairs [p_begin, p_end): each pair's contact force on i (into the pair's
// slot), torque on i (into T, indexed from p_begin) and on j (into the pair's slot), the
// updated history and the touching flag ("touching" means overlapping: a pair held only by
// adhesion across a gap has no contact and no history). Returns 1 when some pair overlaps by more than the
// guard fraction of the smaller radius.
int particle_pair_kernel(const PairKernelData &D, const RowTorques &T, std::int64_t p_begin, std::int64_t p_end);

} // namespace magbrush::dem
