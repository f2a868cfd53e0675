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
// After a barrier each particle adds the pairs in which it is the partner (its column, in
// ascending pair order). The order of every sum is fixed by the list alone, so the forces
// have the same bits on any number of threads, with no atomics.
//
// The kernel's loop body is branch-free (a pair that does not touch goes through the same
// arithmetic at a harmless stand-in geometry and its outputs are selected to zero), so it
// vectorises; an AVX-512 or AVX2 clone is picked at load time where the CPU has one. Vector
// and scalar code give the same bits: every operation is an IEEE add, multiply, divide or
// square root in the same order, and fused multiply-adds are off (dem/CMakeLists.txt).
//
// The particles' data reach the kernel as one record per particle (PairParticleRecords), not
// as the engine's twelve separate arrays: a partner j then costs two cache lines, not twelve,
// and the kernel's accesses form two streams (rows i and partners j) instead of some fifty
// (twelve arrays, each read at i and at the partners one cell, one row and one plane of cells
// ahead). On 55k particles, whose arrays no longer fit the cache, that made the kernel
// ~10 % faster (docs/dem_vs_lammps.md); the arrays stay the engine's state, the records are a
// copy the step refreshes (DemSystem::kick_and_drift_phase).
#pragma once

#include "dem/particle_state.h"

#include <cstdint>
#include <vector>

namespace magbrush::dem {

// Per-particle records for the pair kernel: the twelve values it reads, 16 doubles (128 bytes,
// two whole cache lines) a particle, the first record 64-byte aligned.
class PairParticleRecords
{
public:
  static constexpr std::size_t stride = 16;
  enum Field : std::size_t { x, y, z, vx, vy, vz, wx, wy, wz, radius, mass, inv_inertia };

  // Room for n particles; allocates only when n exceeds every earlier size. The contents are
  // undefined afterwards: write every record before the kernel reads it.
  void resize(std::size_t n)
  {
    storage_.resize(stride * n + 8); // + 8: room to align the first record
    base_ = storage_.data();
    while (reinterpret_cast<std::uintptr_t>(base_) % 64 != 0)
      ++base_;
  }
  const double *data() const { return base_; }
  // Copies particle i's current values into its record.
  void write(std::size_t i, const ParticleState &s)
  {
    double *r = base_ + stride * i;
    r[x] = s.x[i];
    r[y] = s.y[i];
    r[z] = s.z[i];
    r[vx] = s.vx[i];
    r[vy] = s.vy[i];
    r[vz] = s.vz[i];
    r[wx] = s.wx[i];
    r[wy] = s.wy[i];
    r[wz] = s.wz[i];
    r[radius] = s.radius[i];
    r[mass] = s.mass[i];
    r[inv_inertia] = s.inv_inertia[i];
  }
  std::size_t memory_bytes() const { return storage_.capacity() * sizeof(double); }

private:
  std::vector<double> storage_;
  double *base_ = nullptr;
};

struct PairKernelData
{
  // Particles (read): their records, and the species.
  const double *particles;
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
