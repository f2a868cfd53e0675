// The pair kernel (see pair_kernel.h).
#include "dem/pair_kernel.h"

#include "dem/contact_law.h"

#include <algorithm>
#include <cmath>

namespace magbrush::dem {

namespace {
// The kernel body for pairs [p_begin, p_end). Returns 1 when some pair overlaps by more than
// the guard fraction of the smaller radius.
template <bool Uniform, bool Adhesive, bool Masked = false>
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline int pair_loop(const PairKernelData &D, const RowTorques &T, std::int64_t p_begin, std::int64_t p_end)
{
  // Local restrict copies: the outputs alias neither the inputs nor each other, and the
  // compiler must not reload the pointers from D after every store.
  const double *__restrict x = D.x, *__restrict y = D.y, *__restrict z = D.z;
  const double *__restrict vx = D.vx, *__restrict vy = D.vy, *__restrict vz = D.vz;
  const double *__restrict wx = D.wx, *__restrict wy = D.wy, *__restrict wz = D.wz;
  const double *__restrict radius = D.radius, *__restrict mass = D.mass, *__restrict inv_inertia = D.inv_inertia;
  const std::int32_t *__restrict species = D.species, *__restrict owner = D.owner, *__restrict partner = D.partner;
  const std::int32_t *__restrict image = D.image;
  const double *__restrict shift_x = D.shift_x, *__restrict shift_y = D.shift_y, *__restrict shift_z = D.shift_z;
  const double *__restrict E_star = D.effective_modulus, *__restrict G_star = D.effective_shear;
  const double *__restrict mu = D.friction, *__restrict mu_r = D.rolling_friction;
  const double *__restrict alpha_n = D.damping_normal, *__restrict alpha_t = D.damping_tangential;
  const std::int64_t columns = D.table_columns;
  const double dt = D.dt, guard = D.overlap_guard;
  double *__restrict hx = D.hx, *__restrict hy = D.hy, *__restrict hz = D.hz;
  const std::int64_t base = D.slot_base;
  double *__restrict fx = D.fx - base, *__restrict fy = D.fy - base, *__restrict fz = D.fz - base;
  double *__restrict tjx = D.tjx - base, *__restrict tjy = D.tjy - base, *__restrict tjz = D.tjz - base;
  double *__restrict tix = T.x - p_begin, *__restrict tiy = T.y - p_begin, *__restrict tiz = T.z - p_begin;
  std::int32_t *__restrict touching = D.touching;
  const double *__restrict hamaker = D.hamaker, *__restrict asperity_i = D.asperity_i,
                           *__restrict asperity_j = D.asperity_j;
  const double z0 = D.adhesion_cutoff, range = D.adhesion_range;
  ContactCoefficients uniform_k;
  AdhesionCoefficients uniform_a;
  if (Uniform)
    uniform_k = {E_star[0], G_star[0], mu[0], mu_r[0], alpha_n[0], alpha_t[0]};
  if (Uniform && Adhesive)
    uniform_a = {hamaker[0], asperity_i[0], asperity_j[0]};
  const std::int32_t *__restrict skip = D.skip;
  int alarm = 0;
#pragma omp simd reduction(| : alarm)
  for (std::int64_t p = p_begin; p < p_end; ++p)
  {
    // A skipped pair is computed like any other (branch-free) and its outputs are discarded.
    const bool computed = Masked ? skip[p] == 0 : true;
    const std::int64_t i = owner[p], j = partner[p];
    const int im = image[p];
    const Vector3 d{x[j] - x[i] + shift_x[im], y[j] - y[i] + shift_y[im], z[j] - z[i] + shift_z[im]};
    const double ri = radius[i], rj = radius[j], reach = ri + rj;
    const double r2 = dot(d, d);
    const bool touch = r2 < reach * reach;
    // With adhesion, pairs within its range attract across the gap: they need the true
    // distance and normal (and the contact law sees zero overlap).
    const double reach_a = Adhesive ? reach + range : reach;
    const bool near = Adhesive ? r2 < reach_a * reach_a : touch;
    // A pair that does not touch computes at unit distance and zero overlap (no NaN, no
    // infinity); its outputs are zeroed below.
    const double dist = std::sqrt(near ? r2 : 1.0), inv_dist = 1.0 / dist;
    ContactKinematics c;
    c.n = inv_dist * d;
    c.overlap = touch ? reach - dist : 0.0;
    alarm |= (computed & touch & (c.overlap > guard * std::min(ri, rj))) ? 1 : 0;
    // Distances from the centres to the plane of the contact circle.
    c.lever_i = 0.5 * (dist + (ri * ri - rj * rj) * inv_dist);
    c.lever_j = dist - c.lever_i;
    const Vector3 wi{wx[i], wy[i], wz[i]}, wj{wx[j], wy[j], wz[j]};
    const Vector3 vij{vx[i] - vx[j], vy[i] - vy[j], vz[i] - vz[j]};
    c.v_rel = vij + cross(c.lever_i * wi + c.lever_j * wj, c.n);
    c.w_rel = wi - wj;
    c.R_star = ri * rj / reach;
    const double mi = mass[i], mj = mass[j];
    c.m_star = mi * mj / (mi + mj);
    c.radius_i = ri;
    c.radius_j = rj;
    c.inv_inertia_i = inv_inertia[i];
    c.inv_inertia_j = inv_inertia[j];
    ContactCoefficients k = uniform_k;
    if (!Uniform)
    {
      const std::int64_t type = species[i] * columns + species[j];
      k = {E_star[type], G_star[type], mu[type], mu_r[type], alpha_n[type], alpha_t[type]};
    }
    Vector3 xi_t{hx[p], hy[p], hz[p]};
    const ContactOutcome o = evaluate_contact(k, c, xi_t, dt);
    // A pair that stopped touching forgets its history.
    const double keep = (touch && computed) ? 1.0 : 0.0;
    if (Masked)
    {
      hx[p] = computed ? (touch ? xi_t.x : 0.0) : hx[p];
      hy[p] = computed ? (touch ? xi_t.y : 0.0) : hy[p];
      hz[p] = computed ? (touch ? xi_t.z : 0.0) : hz[p];
    }
    else
    {
      hx[p] = touch ? xi_t.x : 0.0;
      hy[p] = touch ? xi_t.y : 0.0;
      hz[p] = touch ? xi_t.z : 0.0;
    }
    if (Adhesive)
    {
      AdhesionCoefficients a = uniform_a;
      if (!Uniform)
      {
        const std::int64_t type = species[i] * columns + species[j];
        a = {hamaker[type], asperity_i[type], asperity_j[type]};
      }
      // Attraction towards the partner (+n on i), added to the contact force.
      const double R_a = HamakerAdhesion::radius(ri, a.asperity_i, rj, a.asperity_j);
      const double f_a = (near && computed) ? HamakerAdhesion::force(a.hamaker, R_a, dist - reach, z0) : 0.0;
      fx[p] = keep * o.force_i.x + f_a * c.n.x;
      fy[p] = keep * o.force_i.y + f_a * c.n.y;
      fz[p] = keep * o.force_i.z + f_a * c.n.z;
    }
    else
    {
      fx[p] = keep * o.force_i.x;
      fy[p] = keep * o.force_i.y;
      fz[p] = keep * o.force_i.z;
    }
    tix[p] = keep * o.torque_i.x;
    tiy[p] = keep * o.torque_i.y;
    tiz[p] = keep * o.torque_i.z;
    tjx[p] = keep * o.torque_j.x;
    tjy[p] = keep * o.torque_j.y;
    tjz[p] = keep * o.torque_j.z;
    if (Masked)
      touching[p] = computed ? (touch ? 1 : 0) : touching[p];
    else
      touching[p] = touch ? 1 : 0;
  }
  return alarm;
}

} // namespace

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define MAGBRUSH_PAIR_KERNEL_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define MAGBRUSH_PAIR_KERNEL_CLONES
#endif

namespace {
// The two kernels, each with its clones: contact only, and contact with adhesion. Kept as
// separate functions so that the contact-only one compiles to the same code as before
// adhesion existed (register allocation in this loop is tight: one more branch inside the
// function would move its spills and cost ~1.5 % of its instructions).
MAGBRUSH_PAIR_KERNEL_CLONES
int contact_pair_kernel(const PairKernelData &D, const RowTorques &T, std::int64_t p_begin, std::int64_t p_end)
{
  return D.uniform ? pair_loop<true, false>(D, T, p_begin, p_end) : pair_loop<false, false>(D, T, p_begin, p_end);
}

MAGBRUSH_PAIR_KERNEL_CLONES
int adhesive_pair_kernel(const PairKernelData &D, const RowTorques &T, std::int64_t p_begin, std::int64_t p_end)
{
  return D.uniform ? pair_loop<true, true>(D, T, p_begin, p_end) : pair_loop<false, true>(D, T, p_begin, p_end);
}

// With some pairs skipped (the toner in substeps): the same kernels, masked. Separate
// functions, so that the unmasked ones keep their code.
MAGBRUSH_PAIR_KERNEL_CLONES
int masked_pair_kernel(const PairKernelData &D, const RowTorques &T, std::int64_t p_begin, std::int64_t p_end)
{
  if (D.adhesive)
    return D.uniform ? pair_loop<true, true, true>(D, T, p_begin, p_end) : pair_loop<false, true, true>(D, T, p_begin, p_end);
  return D.uniform ? pair_loop<true, false, true>(D, T, p_begin, p_end) : pair_loop<false, false, true>(D, T, p_begin, p_end);
}
} // namespace

int particle_pair_kernel(const PairKernelData &D, const RowTorques &T, std::int64_t p_begin, std::int64_t p_end)
{
  if (D.skip)
    return masked_pair_kernel(D, T, p_begin, p_end);
  return D.adhesive ? adhesive_pair_kernel(D, T, p_begin, p_end) : contact_pair_kernel(D, T, p_begin, p_end);
}

} // namespace magbrush::dem
