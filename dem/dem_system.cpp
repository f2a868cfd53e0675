// The DEM engine's step and state (see dem_system.h).
#include "dem_system.h"

#include "contact_law.h"
#include "insertion.h"
#include "phase_clock.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

namespace magbrush::dem {

namespace {
std::size_t U(std::int32_t v) { return static_cast<std::size_t>(v); }
} // namespace

DemSystem::DemSystem(const Case &c) : DemSystem(c, build_wall_primitives(c)) {}

DemSystem::DemSystem(const Case &c, const WallSet &walls) : case_(c), walls_(walls)
{
  box_.length = {c.dem.periodic_length_x, c.dem.periodic_length_y, c.dem.periodic_length};
}

void DemSystem::insert_particles()
{
  insert_populations(case_, walls_, box_, particles_);
}

void DemSystem::add_force_term(std::unique_ptr<ForceTerm> term)
{
  times_.terms.push_back(0.0);
  terms_.push_back(std::move(term));
}

void DemSystem::replace_force_term(const std::string &name, std::unique_ptr<ForceTerm> term)
{
  for (auto &t : terms_)
    if (name == t->name())
    {
      if (term->runs_in_team() != t->runs_in_team())
        throw std::invalid_argument("dem: the replacement of force term '" + name +
                                    "' must run in the same place of the step (in the team or not)");
      t = std::move(term);
      return;
    }
  throw std::invalid_argument("dem: no force term '" + name + "' to replace");
}

void DemSystem::setup_derived()
{
  const std::size_t n = particles_.size();
  if (n == 0)
    throw std::invalid_argument("dem: the scene has no particles (check the populations' count/mass)");
  std::vector<std::string> species_materials, species_names;
  std::vector<Material> materials;
  for (const auto &p : case_.populations)
  {
    species_materials.push_back(p.material);
    species_names.push_back(p.name);
    materials.push_back(case_.material(p.material));
  }
  for (std::size_t i = 0; i < n; ++i)
    if (particles_.species[i] < 0 || U(particles_.species[i]) >= species_materials.size())
      throw std::invalid_argument("dem: particle " + std::to_string(particles_.id[i]) + " has species " +
                                  std::to_string(particles_.species[i]) + " but the case has " +
                                  std::to_string(species_materials.size()) + " populations");
  table_.build(case_, species_materials, walls_.materials());
  // The table again, one array per field (the pair kernel gathers from these).
  const std::size_t types = table_.species() * table_.columns();
  coefficient_fields_.assign(6 * types, 0.0);
  for (std::size_t t = 0; t < types; ++t)
  {
    const ContactCoefficients &k = table_.data()[t];
    const double fields[6] = {k.effective_modulus, k.effective_shear, k.friction,
                              k.rolling_friction, k.damping_normal, k.damping_tangential};
    for (std::size_t f = 0; f < 6; ++f)
      coefficient_fields_[f * types + t] = fields[f];
  }
  stable_ = stable_time_step(particles_, materials, species_names, table_, walls_.size(),
                             std::max(1.0, 2.0 * walls_.max_surface_speed()));
  dt_ = choose_time_step(case_.dem, stable_);

  double mean_d = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < n; ++i)
  {
    mean_d += 2.0 * particles_.radius[i];
    mass += particles_.mass[i];
  }
  mean_d /= static_cast<double>(n);
  skin_ = case_.dem.verlet_skin * mean_d;
  energy_floor_ = 0.5 * mass * 1.0; // (1 m/s)²: the runaway guard ignores growth below this
  forces_.resize(n);
  contact_count_.assign(n, 0);
  if (walls_.size() > 0)
  {
    const std::size_t k = n * max_wall_contacts;
    wall_id_.assign(k, -1);
    for (auto *a : {&wall_hx_, &wall_hy_, &wall_hz_, &wall_fx_, &wall_fy_, &wall_fz_, &wall_tx_, &wall_ty_, &wall_tz_})
      a->assign(k, 0.0);
  }
  times_.terms.resize(terms_.size(), 0.0);
}

void DemSystem::initialize()
{
  setup_derived();
  rebuild_neighbor_list();
  // Forces at t = 0, so that the first half kick uses them.
  walls_.prepare(time_, walls_frozen_);
  thread_flags_.assign(static_cast<std::size_t>(std::max(1, omp_get_max_threads())), StepFlags{});
#pragma omp parallel if (parallel())
  {
    StepFlags &mine = my_flags();
    pair_and_row_phase(mine);
    column_phase();
    if (walls_.size() > 0)
      wall_phase(mine);
  }
  raise_alarms(team_alarms());
  for (std::size_t t = 0; t < terms_.size(); ++t)
    terms_[t]->add_forces(particles_, forces_, time_);
  initialized_ = true;
}

void DemSystem::permute_particles(const std::vector<std::int32_t> &order)
{
  particles_.permute(order, scratch_, iscratch_);
  forces_.permute(order, scratch_);
  permute_array(contact_count_, order, iscratch_);
  if (!wall_id_.empty())
  {
    // Slots move in blocks of max_wall_contacts.
    std::vector<std::int32_t> slot_order(order.size() * max_wall_contacts);
    for (std::size_t k = 0; k < order.size(); ++k)
      for (int s = 0; s < max_wall_contacts; ++s)
        slot_order[k * max_wall_contacts + U(s)] = order[k] * max_wall_contacts + s;
    permute_array(wall_id_, slot_order, iscratch_);
    for (auto *a : {&wall_hx_, &wall_hy_, &wall_hz_, &wall_fx_, &wall_fy_, &wall_fz_, &wall_tx_, &wall_ty_, &wall_tz_})
      permute_array(*a, slot_order, scratch_);
  }
  for (auto &t : terms_)
    t->particles_reordered(order);
}

void DemSystem::rebuild_neighbor_list()
{
  PhaseTimer timer(times_.neighbor);
  list_.rebuild(particles_, box_, skin_, [this](const std::vector<std::int32_t> &order) { permute_particles(order); });
  x0_ = particles_.x;
  y0_ = particles_.y;
  z0_ = particles_.z;
  force_rebuild_ = false;
  ++rebuilds_;
}

// Velocity Verlet's half step of the velocities: v += (h/m) F, ω += (h/I) T.
static inline void half_kick(ParticleState &s, const ForceBuffers &f, std::size_t i, double h)
{
  const double im = s.inv_mass[i], iI = s.inv_inertia[i];
  s.vx[i] += h * f.fx[i] * im;
  s.vy[i] += h * f.fy[i] * im;
  s.vz[i] += h * f.fz[i] * im;
  s.wx[i] += h * f.tx[i] * iI;
  s.wy[i] += h * f.ty[i] * iI;
  s.wz[i] += h * f.tz[i] * iI;
}

// First half of velocity Verlet: v(t + dt/2) = v(t) + (dt/2) F(t)/m, x(t + dt) = x + dt v(t + dt/2).
// Also this thread's largest squared displacement since the last list build; after the
// barrier every thread reads every thread's (max_drift2_of_team).
void DemSystem::kick_and_drift_phase(StepFlags &mine)
{
  double max_drift2 = 0.0;
  const long n = static_cast<long>(particles_.size());
  const double h = 0.5 * dt_, dt = dt_;
  ParticleState &s = particles_;
  const ForceBuffers &f = forces_;
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    half_kick(s, f, i, h);
    s.x[i] += dt * s.vx[i];
    s.y[i] += dt * s.vy[i];
    s.z[i] += dt * s.vz[i];
    const double dx = s.x[i] - x0_[i], dy = s.y[i] - y0_[i], dz = s.z[i] - z0_[i];
    max_drift2 = std::max(max_drift2, dx * dx + dy * dy + dz * dz);
  }
  mine.max_drift2 = max_drift2;
#pragma omp barrier
}

// Second half: v(t + dt) = v(t + dt/2) + (dt/2) F(t + dt)/m; flags a non-finite state.
// Static schedule, no barrier: a thread kicks exactly the particles whose forces it summed
// (and, in the next step, drifts them: the same static split).
void DemSystem::final_kick_phase(StepFlags &mine)
{
  StepFlags::ParticleAlarm not_finite; // the first in this thread's share
  const long n = static_cast<long>(particles_.size());
  const double h = 0.5 * dt_;
  ParticleState &s = particles_;
  const ForceBuffers &f = forces_;
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    half_kick(s, f, i, h);
    if (!std::isfinite(s.vx[i] + s.vy[i] + s.vz[i] + s.wx[i] + s.wy[i] + s.wz[i] + s.x[i] + s.y[i] + s.z[i]))
      if (not_finite.particle < 0)
        not_finite.set(k, s.position(i));
  }
  if (mine.not_finite.particle < 0)
    mine.not_finite = not_finite;
}

void DemSystem::raise_state_alarm(const StepFlags &flags) const
{
  if (flags.not_finite.particle < 0)
    return;
  char msg[512];
  std::snprintf(msg, sizeof msg,
                "stability guard: NaN/Inf at step %ld (t = %.6g s) in the state of %s. The time step "
                "(%.3g s) is probably too large for the stiffest contact or force term: reduce "
                "dem.time_step (or time_step_safety), or check the material stiffness and the force terms",
                step_, time_,
                describe_particle(static_cast<std::size_t>(flags.not_finite.particle), flags.not_finite.at).c_str(),
                dt_);
  throw StabilityError(msg);
}

std::string DemSystem::describe_particle(std::size_t i) const { return describe_particle(i, particles_.position(i)); }

std::string DemSystem::describe_particle(std::size_t i, const Vector3 &at) const
{
  char buf[256];
  std::snprintf(buf, sizeof buf, "particle id %d (species %d, r = %.3g m, at (%.4g, %.4g, %.4g) m)",
                particles_.id[i], particles_.species[i], particles_.radius[i], at.x, at.y, at.z);
  return buf;
}

// ---------------------------------------------------------------------------------------
// Particle–particle contacts.
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
namespace {
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
};

// Torque on i of the pairs p_begin + k, k = 0 .. block size (a per-thread buffer).
struct RowTorques
{
  double *x, *y, *z;
};

// The kernel body for pairs [p_begin, p_end). Returns 1 when some pair overlaps by more than
// the guard fraction of the smaller radius.
template <bool Uniform>
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
  double *__restrict fx = D.fx, *__restrict fy = D.fy, *__restrict fz = D.fz;
  double *__restrict tjx = D.tjx, *__restrict tjy = D.tjy, *__restrict tjz = D.tjz;
  double *__restrict tix = T.x - p_begin, *__restrict tiy = T.y - p_begin, *__restrict tiz = T.z - p_begin;
  std::int32_t *__restrict touching = D.touching;
  ContactCoefficients uniform_k;
  if (Uniform)
    uniform_k = {E_star[0], G_star[0], mu[0], mu_r[0], alpha_n[0], alpha_t[0]};
  int alarm = 0;
#pragma omp simd reduction(| : alarm)
  for (std::int64_t p = p_begin; p < p_end; ++p)
  {
    const std::int64_t i = owner[p], j = partner[p];
    const int im = image[p];
    const Vector3 d{x[j] - x[i] + shift_x[im], y[j] - y[i] + shift_y[im], z[j] - z[i] + shift_z[im]};
    const double ri = radius[i], rj = radius[j], reach = ri + rj;
    const double r2 = dot(d, d);
    const bool touch = r2 < reach * reach;
    // A pair that does not touch computes at unit distance and zero overlap (no NaN, no
    // infinity); its outputs are zeroed below.
    const double dist = std::sqrt(touch ? r2 : 1.0), inv_dist = 1.0 / dist;
    ContactKinematics c;
    c.n = inv_dist * d;
    c.overlap = touch ? reach - dist : 0.0;
    alarm |= (touch & (c.overlap > guard * std::min(ri, rj))) ? 1 : 0;
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
    const double keep = touch ? 1.0 : 0.0;
    hx[p] = touch ? xi_t.x : 0.0;
    hy[p] = touch ? xi_t.y : 0.0;
    hz[p] = touch ? xi_t.z : 0.0;
    fx[p] = keep * o.force_i.x;
    fy[p] = keep * o.force_i.y;
    fz[p] = keep * o.force_i.z;
    tix[p] = keep * o.torque_i.x;
    tiy[p] = keep * o.torque_i.y;
    tiz[p] = keep * o.torque_i.z;
    tjx[p] = keep * o.torque_j.x;
    tjy[p] = keep * o.torque_j.y;
    tjz[p] = keep * o.torque_j.z;
    touching[p] = touch ? 1 : 0;
  }
  return alarm;
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define MAGBRUSH_PAIR_KERNEL_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define MAGBRUSH_PAIR_KERNEL_CLONES
#endif

MAGBRUSH_PAIR_KERNEL_CLONES
int particle_pair_kernel(const PairKernelData &D, const RowTorques &T, std::int64_t p_begin, std::int64_t p_end)
{
  return D.uniform ? pair_loop<true>(D, T, p_begin, p_end) : pair_loop<false>(D, T, p_begin, p_end);
}
} // namespace

// Phase 1 (all threads, work-shared; ends with a barrier): pairs and rows, block by block.
// Sets this thread's overlap alarm when one of its pairs overlaps beyond the guard.
void DemSystem::pair_and_row_phase(StepFlags &mine)
{
  int overlap_alarm = 0;
  const ParticleState &s = particles_;
  const NeighborList &L = list_;
  const long n = static_cast<long>(s.size());
  // Image shifts and coefficients as plain arrays, one per component / field.
  double shift[3][27];
  for (int code = 0; code < 27; ++code)
  {
    const Vector3 v = L.shifts()[code];
    shift[0][code] = v.x;
    shift[1][code] = v.y;
    shift[2][code] = v.z;
  }
  const std::size_t types = table_.species() * table_.columns();
  const double *coef = coefficient_fields_.data();
  NeighborList &W = list_; // the pair slots written here
  const PairKernelData D{s.x.data(), s.y.data(), s.z.data(), s.vx.data(), s.vy.data(), s.vz.data(),
                         s.wx.data(), s.wy.data(), s.wz.data(), s.radius.data(), s.mass.data(),
                         s.inv_inertia.data(), s.species.data(), L.owner.data(), L.partner.data(),
                         L.image.data(), shift[0], shift[1], shift[2], coef, coef + types, coef + 2 * types,
                         coef + 3 * types, coef + 4 * types, coef + 5 * types,
                         static_cast<std::int64_t>(table_.columns()), table_.species() == 1, dt_,
                         case_.dem.max_overlap_fraction, W.hist_x.data(), W.hist_y.data(), W.hist_z.data(),
                         W.force_x.data(), W.force_y.data(), W.force_z.data(), W.torque_j_x.data(),
                         W.torque_j_y.data(), W.torque_j_z.data(), W.touching.data()};
  const std::int32_t *row_start = L.row_start.data();
  ForceBuffers &f = forces_;
  const long blocks = (n + contact_block_rows - 1) / contact_block_rows;
  std::vector<double> &row_torques = mine.row_torques; // the torques on i of one block's pairs
#pragma omp for schedule(dynamic, 2) nowait
  for (long b = 0; b < blocks; ++b)
  {
    const long i0 = b * contact_block_rows, i1 = std::min(n, i0 + contact_block_rows);
    const std::int64_t p0 = row_start[i0], p1 = row_start[i1];
    row_torques.resize(3 * static_cast<std::size_t>(p1 - p0));
    const RowTorques T{row_torques.data(), row_torques.data() + (p1 - p0), row_torques.data() + 2 * (p1 - p0)};
    overlap_alarm |= particle_pair_kernel(D, T, p0, p1);
    for (long i = i0; i < i1; ++i)
    {
      double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
      std::int32_t count = 0;
      for (std::int64_t p = row_start[i]; p < row_start[i + 1]; ++p)
      {
        count += D.touching[p];
        fx += D.fx[p];
        fy += D.fy[p];
        fz += D.fz[p];
        tx += T.x[p - p0];
        ty += T.y[p - p0];
        tz += T.z[p - p0];
      }
      const std::size_t iu = static_cast<std::size_t>(i);
      f.fx[iu] = fx;
      f.fy[iu] = fy;
      f.fz[iu] = fz;
      f.tx[iu] = tx;
      f.ty[iu] = ty;
      f.tz[iu] = tz;
      contact_count_[iu] = count;
    }
  }
  mine.overlap_alarm |= overlap_alarm;
#pragma omp barrier
}

// Phase 2 (after phase 1's barrier; static schedule, no barrier): each particle adds the
// pairs in which it is the partner, in ascending pair order: −F on it, the pair's torque on j.
void DemSystem::column_phase()
{
  const NeighborList &L = list_;
  const long n = static_cast<long>(particles_.size());
  ForceBuffers &f = forces_;
  const std::int32_t *col_start = L.col_start.data(), *col_pair = L.col_pair.data();
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    double fx = f.fx[i], fy = f.fy[i], fz = f.fz[i], tx = f.tx[i], ty = f.ty[i], tz = f.tz[i];
    std::int32_t count = contact_count_[i];
    for (std::int32_t q = col_start[i]; q < col_start[i + 1]; ++q)
    {
      const std::size_t p = U(col_pair[q]);
      count += L.touching[p];
      fx -= L.force_x[p];
      fy -= L.force_y[p];
      fz -= L.force_z[p];
      tx += L.torque_j_x[p];
      ty += L.torque_j_y[p];
      tz += L.torque_j_z[p];
    }
    f.fx[i] = fx;
    f.fy[i] = fy;
    f.fz[i] = fz;
    f.tx[i] = tx;
    f.ty[i] = ty;
    f.tz[i] = tz;
    contact_count_[i] = count;
  }
}

// Overlap first (the worst pair is searched in the state where it happened), then the walls,
// then the state.
void DemSystem::raise_alarms(const StepFlags &flags) const
{
  if (flags.overlap_alarm)
    check_overlaps();
  raise_wall_alarms(flags);
  raise_state_alarm(flags);
}

void DemSystem::check_overlaps() const
{
  // Serial scan for the worst pair, only when the parallel kernel raised the alarm.
  const ParticleState &s = particles_;
  double worst = 0.0;
  std::size_t wi = 0, wj = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::int32_t pp = list_.row_start[i]; pp < list_.row_start[i + 1]; ++pp)
    {
      const std::size_t p = U(pp), j = U(list_.partner[p]);
      const Vector3 sh = list_.shift(p);
      const Vector3 d{s.x[j] - s.x[i] + sh.x, s.y[j] - s.y[i] + sh.y, s.z[j] - s.z[i] + sh.z};
      const double frac = (s.radius[i] + s.radius[j] - norm(d)) / std::min(s.radius[i], s.radius[j]);
      if (frac > worst)
      {
        worst = frac;
        wi = i;
        wj = j;
      }
    }
  char msg[768];
  std::snprintf(msg, sizeof msg,
                "stability guard: at step %ld (t = %.6g s) %s overlaps particle id %d by %.1f %% of the smaller "
                "radius (limit dem.max_overlap_fraction = %.1f %%). Contacts are too soft for the loads or "
                "the time step (%.3g s) is too large: increase Young's modulus, reduce dem.time_step, or check "
                "the insertion and the force terms",
                step_, time_, describe_particle(wi).c_str(), s.id[wj], 100.0 * worst,
                100.0 * case_.dem.max_overlap_fraction, dt_);
  throw StabilityError(msg);
}

// Wall contacts of every particle (static schedule, no barrier; walls_.prepare() has run).
// Records the largest index of a particle that overlaps a wall beyond the guard (alarm) or
// touches too many walls (crowded); raise_wall_alarms() turns them into errors.
void DemSystem::wall_phase(StepFlags &mine)
{
  long alarm = -1, too_many = -1;
  ParticleState &s = particles_;
  ForceBuffers &f = forces_;
  const long n = static_cast<long>(s.size());
  const std::size_t W = walls_.size();
  const double dt = dt_, guard = case_.dem.max_overlap_fraction;
  // This thread's scratch (constructed once, not per particle).
  WallContactGeometry g[max_wall_contacts + 1];
  int which[max_wall_contacts + 1];
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    const Vector3 p = s.position(i);
    const double r = s.radius[i];
  // Pass 1: which walls touch this particle now.
    int m = 0;
    for (std::size_t w = 0; w < W; ++w)
    {
      if (!walls_.contact(w, p, r, g[m]))
        continue;
      which[m] = static_cast<int>(w);
      if (m == max_wall_contacts)
      {
        too_many = k;
        break;
      }
      ++m;
    }
    // Pass 2: free the slots of walls no longer touched.
    const std::size_t base = i * max_wall_contacts;
    for (int q = 0; q < max_wall_contacts; ++q)
    {
      const std::size_t sl = base + U(q);
      if (wall_id_[sl] < 0)
        continue;
      bool still = false;
      for (int c = 0; c < m; ++c)
        still = still || which[c] == wall_id_[sl];
      if (!still)
      {
        wall_id_[sl] = -1;
        wall_hx_[sl] = wall_hy_[sl] = wall_hz_[sl] = 0.0;
        wall_fx_[sl] = wall_fy_[sl] = wall_fz_[sl] = wall_tx_[sl] = wall_ty_[sl] = wall_tz_[sl] = 0.0;
      }
    }
    // Pass 3: evaluate each contact with its slot's history.
    for (int c = 0; c < m; ++c)
    {
      std::size_t sl = base + max_wall_contacts;
      for (int q = 0; q < max_wall_contacts && sl == base + max_wall_contacts; ++q)
        if (wall_id_[base + U(q)] == which[c])
          sl = base + U(q);
      for (int q = 0; q < max_wall_contacts && sl == base + max_wall_contacts; ++q)
        if (wall_id_[base + U(q)] < 0)
          sl = base + U(q);
      wall_id_[sl] = which[c];
      if (g[c].overlap > guard * r)
        alarm = k;
      ContactKinematics ck;
      ck.n = g[c].n;
      ck.overlap = g[c].overlap;
      ck.lever_i = r - g[c].overlap; // rigid wall: the contact plane is the wall surface
      ck.lever_j = 0.0;
      const Vector3 w = s.angular_velocity(i);
      ck.v_rel = s.velocity(i) + cross(ck.lever_i * w, ck.n) - g[c].surface_velocity;
      ck.w_rel = w - g[c].angular_velocity;
      ck.R_star = r;
      ck.m_star = s.mass[i];
      ck.radius_i = r;
      ck.inv_inertia_i = s.inv_inertia[i];
      Vector3 xi_t{wall_hx_[sl], wall_hy_[sl], wall_hz_[sl]};
      const ContactOutcome o = evaluate_contact(table_.particle_wall(s.species[i], which[c]), ck, xi_t, dt);
      wall_hx_[sl] = xi_t.x;
      wall_hy_[sl] = xi_t.y;
      wall_hz_[sl] = xi_t.z;
      f.fx[i] += o.force_i.x;
      f.fy[i] += o.force_i.y;
      f.fz[i] += o.force_i.z;
      f.tx[i] += o.torque_i.x;
      f.ty[i] += o.torque_i.y;
      f.tz[i] += o.torque_i.z;
      // Load on the wall: −F at the contact point, torque about the wall's reference point.
      wall_fx_[sl] = -o.force_i.x;
      wall_fy_[sl] = -o.force_i.y;
      wall_fz_[sl] = -o.force_i.z;
      const Vector3 arm = p + ck.lever_i * ck.n - g[c].torque_origin;
      const Vector3 tq = cross(arm, -o.force_i);
      wall_tx_[sl] = tq.x;
      wall_ty_[sl] = tq.y;
      wall_tz_[sl] = tq.z;
    }
  }
  if (alarm > mine.wall_overlap.particle)
    mine.wall_overlap.set(alarm, s.position(static_cast<std::size_t>(std::max(0L, alarm))));
  if (too_many > mine.wall_crowded.particle)
    mine.wall_crowded.set(too_many, s.position(static_cast<std::size_t>(std::max(0L, too_many))));
}

void DemSystem::raise_wall_alarms(const StepFlags &flags) const
{
  const double guard = case_.dem.max_overlap_fraction;
  const auto &crowded = flags.wall_crowded, &overlap = flags.wall_overlap;
  if (crowded.particle >= 0)
    throw StabilityError("wall contacts: " + describe_particle(static_cast<std::size_t>(crowded.particle), crowded.at) +
                         " touches more than " + std::to_string(max_wall_contacts) +
                         " walls at once at step " + std::to_string(step_) +
                         "; the walls overlap or leave a gap smaller than a particle: check the geometry");
  if (overlap.particle >= 0)
  {
    char msg[768];
    std::snprintf(msg, sizeof msg,
                  "stability guard: at step %ld (t = %.6g s) %s overlaps a wall by more than %.1f %% of its "
                  "radius (dem.max_overlap_fraction). The wall pushes too hard for the contact stiffness or "
                  "the time step (%.3g s) is too large: reduce dem.time_step, slow the wall, or increase the "
                  "stiffness",
                  step_, time_, describe_particle(static_cast<std::size_t>(overlap.particle), overlap.at).c_str(),
                  100.0 * guard, dt_);
    throw StabilityError(msg);
  }
}

void DemSystem::check_energy()
{
  PhaseTimer timer(times_.guards);
  const double ke = kinetic_energy() + rotational_energy();
  if (!std::isfinite(ke))
    throw StabilityError("stability guard: kinetic energy is not finite at step " + std::to_string(step_) +
                         ": reduce dem.time_step");
  if (guard_energy_ >= 0.0 && ke > case_.dem.max_kinetic_energy_growth * std::max(guard_energy_, energy_floor_))
  {
    // Name the fastest particle: the likely origin of the runaway.
    std::size_t worst = 0;
    double v2max = -1;
    for (std::size_t i = 0; i < particles_.size(); ++i)
    {
      const double v2 = particles_.vx[i] * particles_.vx[i] + particles_.vy[i] * particles_.vy[i] +
                        particles_.vz[i] * particles_.vz[i];
      if (v2 > v2max)
      {
        v2max = v2;
        worst = i;
      }
    }
    char msg[768];
    std::snprintf(msg, sizeof msg,
                  "stability guard: kinetic energy grew from %.4g J to %.4g J (more than x%.3g, "
                  "dem.max_kinetic_energy_growth) within 100 steps at step %ld (t = %.6g s); fastest: %s at "
                  "%.4g m/s. Energy is being created numerically: reduce dem.time_step (now %.3g s) or the "
                  "contact stiffness, or check the force terms",
                  guard_energy_, ke, case_.dem.max_kinetic_energy_growth, step_, time_,
                  describe_particle(worst).c_str(), std::sqrt(v2max), dt_);
    throw StabilityError(msg);
  }
  guard_energy_ = ke;
}

double DemSystem::kinetic_energy() const
{
  double e = 0.0;
  const auto &s = particles_;
  for (std::size_t i = 0; i < s.size(); ++i)
    e += 0.5 * s.mass[i] * (s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i] + s.vz[i] * s.vz[i]);
  return e;
}

double DemSystem::rotational_energy() const
{
  double e = 0.0;
  const auto &s = particles_;
  for (std::size_t i = 0; i < s.size(); ++i)
    e += 0.5 / s.inv_inertia[i] * (s.wx[i] * s.wx[i] + s.wy[i] * s.wy[i] + s.wz[i] * s.wz[i]);
  return e;
}

double DemSystem::elastic_energy() const
{
  double e = 0.0;
  const auto &s = particles_;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::int32_t pp = list_.row_start[i]; pp < list_.row_start[i + 1]; ++pp)
    {
      const std::size_t p = U(pp), j = U(list_.partner[p]);
      const Vector3 sh = list_.shift(p);
      const Vector3 d{s.x[j] - s.x[i] + sh.x, s.y[j] - s.y[i] + sh.y, s.z[j] - s.z[i] + sh.z};
      const double delta = s.radius[i] + s.radius[j] - norm(d);
      if (delta <= 0.0)
        continue;
      const auto &c = table_.particle_pair(s.species[i], s.species[j]);
      const double R = s.radius[i] * s.radius[j] / (s.radius[i] + s.radius[j]);
      e += HertzNormal::energy(HertzNormal::stiffness(c.effective_modulus, R), delta);
    }
  return e;
}

long DemSystem::particle_contacts() const
{
  long c = 0;
  for (auto t : list_.touching)
    c += t;
  return c;
}

std::vector<WallLoad> DemSystem::wall_loads() const
{
  std::vector<WallLoad> loads(walls_.size());
  for (std::size_t sl = 0; sl < wall_id_.size(); ++sl)
  {
    if (wall_id_[sl] < 0)
      continue;
    WallLoad &l = loads[U(wall_id_[sl])];
    l.force[0] += wall_fx_[sl];
    l.force[1] += wall_fy_[sl];
    l.force[2] += wall_fz_[sl];
    l.torque[0] += wall_tx_[sl];
    l.torque[1] += wall_ty_[sl];
    l.torque[2] += wall_tz_[sl];
    ++l.contacts;
  }
  return loads;
}

void DemSystem::wall_contacts(std::size_t w, std::vector<WallContactRecord> &out) const
{
  out.clear();
  const int wall = static_cast<int>(w);
  for (std::size_t sl = 0; sl < wall_id_.size(); ++sl)
  {
    if (wall_id_[sl] != wall)
      continue;
    WallContactRecord r;
    r.particle = static_cast<std::uint32_t>(sl / max_wall_contacts);
    r.force_on_wall = {wall_fx_[sl], wall_fy_[sl], wall_fz_[sl]};
    r.torque_on_wall = {wall_tx_[sl], wall_ty_[sl], wall_tz_[sl]};
    out.push_back(r);
  }
}

std::size_t DemSystem::memory_bytes() const
{
  const auto &s = particles_;
  std::size_t b = 0;
  for (const auto *a : {&s.x, &s.y, &s.z, &s.vx, &s.vy, &s.vz, &s.wx, &s.wy, &s.wz, &s.radius, &s.mass,
                        &s.inv_mass, &s.inv_inertia, &s.charge, &forces_.fx, &forces_.fy, &forces_.fz,
                        &forces_.tx, &forces_.ty, &forces_.tz, &x0_, &y0_, &z0_, &wall_hx_, &wall_hy_,
                        &wall_hz_, &wall_fx_, &wall_fy_, &wall_fz_, &wall_tx_, &wall_ty_, &wall_tz_, &scratch_})
    b += a->capacity() * sizeof(double);
  for (const auto *a : {&s.species, &s.id, &contact_count_, &wall_id_, &iscratch_})
    b += a->capacity() * sizeof(std::int32_t);
  return b + list_.memory_bytes();
}

// ---------------------------------------------------------------------------------------
// Checkpoints: a flat binary file, "MBDEMCK2" (2: 32-bit pair flags), then the clock and every dynamic array with
// its length. Written to <path>.tmp and renamed, so a crash never leaves half a checkpoint.
namespace {
constexpr char checkpoint_magic[9] = "MBDEMCK2";

template <typename T>
void put(std::ofstream &o, const T &v) { o.write(reinterpret_cast<const char *>(&v), sizeof(T)); }
template <typename T>
void put_vec(std::ofstream &o, const std::vector<T> &v)
{
  put<std::uint64_t>(o, v.size());
  o.write(reinterpret_cast<const char *>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
}
template <typename T>
T get(std::ifstream &in)
{
  T v{};
  in.read(reinterpret_cast<char *>(&v), sizeof(T));
  return v;
}
template <typename T>
void get_vec(std::ifstream &in, std::vector<T> &v, const std::string &path)
{
  const auto n = get<std::uint64_t>(in);
  if (!in || n > (1ull << 34))
    throw std::runtime_error("checkpoint '" + path + "' is truncated or corrupt");
  v.resize(n);
  in.read(reinterpret_cast<char *>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
  if (!in)
    throw std::runtime_error("checkpoint '" + path + "' is truncated");
}
} // namespace

void DemSystem::write_checkpoint(const std::string &path)
{
  const std::string tmp = path + ".tmp";
  {
    std::ofstream o(tmp, std::ios::binary | std::ios::trunc);
    if (!o)
      throw std::runtime_error("cannot write checkpoint '" + tmp + "': check that the directory exists and is writable");
    o.write(checkpoint_magic, 8);
    put(o, step_);
    put(o, time_);
    put(o, dt_);
    put(o, guard_energy_);
    put<std::uint64_t>(o, walls_.size());
    const auto &s = particles_;
    const ForceBuffers &fb = forces_;
    for (const auto *a : {&s.x, &s.y, &s.z, &s.vx, &s.vy, &s.vz, &s.wx, &s.wy, &s.wz, &s.radius, &s.mass,
                          &s.inv_mass, &s.inv_inertia, &s.charge, &fb.fx, &fb.fy, &fb.fz,
                          &fb.tx, &fb.ty, &fb.tz})
      put_vec(o, *a);
    put_vec(o, s.species);
    put_vec(o, s.id);
    put_vec(o, contact_count_);
    put_vec(o, list_.row_start);
    put_vec(o, list_.partner);
    put_vec(o, list_.touching);
    put_vec(o, list_.hist_x);
    put_vec(o, list_.hist_y);
    put_vec(o, list_.hist_z);
    put_vec(o, wall_id_);
    for (const auto *a : {&wall_hx_, &wall_hy_, &wall_hz_, &wall_fx_, &wall_fy_, &wall_fz_, &wall_tx_, &wall_ty_, &wall_tz_})
      put_vec(o, *a);
    if (!o)
      throw std::runtime_error("writing checkpoint '" + tmp + "' failed (disk full?)");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error("cannot rename '" + tmp + "' to '" + path + "'");
  // Both this run and a run restarted from the file rebuild the list at the next step, so
  // that they continue through identical lists.
  force_rebuild_ = true;
}

void DemSystem::read_checkpoint(const std::string &path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw std::runtime_error("cannot open checkpoint '" + path + "'");
  char magic[8];
  in.read(magic, 8);
  if (!in || std::memcmp(magic, checkpoint_magic, 8) != 0)
    throw std::runtime_error("'" + path + "' is not a magbrush DEM checkpoint (expected header MBDEMCK2)");
  step_ = get<long>(in);
  time_ = get<double>(in);
  const double dt = get<double>(in);
  guard_energy_ = get<double>(in);
  const auto n_walls = get<std::uint64_t>(in);
  if (n_walls != walls_.size())
    throw std::runtime_error("checkpoint '" + path + "' has " + std::to_string(n_walls) + " walls, the case has " +
                             std::to_string(walls_.size()) + ": restart with the case that wrote it");
  auto &s = particles_;
  for (auto *a : {&s.x, &s.y, &s.z, &s.vx, &s.vy, &s.vz, &s.wx, &s.wy, &s.wz, &s.radius, &s.mass, &s.inv_mass,
                  &s.inv_inertia, &s.charge, &forces_.fx, &forces_.fy, &forces_.fz, &forces_.tx, &forces_.ty,
                  &forces_.tz})
    get_vec(in, *a, path);
  get_vec(in, s.species, path);
  get_vec(in, s.id, path);
  get_vec(in, contact_count_, path);
  // Derived set-up (contact table, time-step check, skin) as for a fresh run, then the state.
  const long step = step_;
  const double time = time_, guard = guard_energy_;
  ForceBuffers saved_forces = forces_;
  std::vector<std::int32_t> saved_counts = contact_count_;
  setup_derived();
  get_vec(in, list_.row_start, path);
  get_vec(in, list_.partner, path);
  get_vec(in, list_.touching, path);
  get_vec(in, list_.hist_x, path);
  get_vec(in, list_.hist_y, path);
  get_vec(in, list_.hist_z, path);
  get_vec(in, wall_id_, path);
  for (auto *a : {&wall_hx_, &wall_hy_, &wall_hz_, &wall_fx_, &wall_fy_, &wall_fz_, &wall_tx_, &wall_ty_, &wall_tz_})
    get_vec(in, *a, path);
  forces_ = saved_forces;
  contact_count_ = saved_counts;
  step_ = step;
  time_ = time;
  guard_energy_ = guard;
  dt_ = dt;
  x0_ = particles_.x; // drift reference; the list is rebuilt at the next step anyway
  y0_ = particles_.y;
  z0_ = particles_.z;
  force_rebuild_ = true;
  initialized_ = true;
}

} // namespace magbrush::dem
