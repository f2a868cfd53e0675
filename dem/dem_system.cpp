// The DEM engine's step and state (see dem_system.h).
#include "dem/dem_system.h"

#include "dem/carried_toner.h"
#include "dem/checkpoint_file.h"
#include "dem/contact_law.h"
#include "dem/insertion.h"
#include "dem/pair_kernel.h"
#include "dem/phase_clock.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace magbrush::dem {

namespace {
std::size_t U(std::int32_t v) { return static_cast<std::size_t>(v); }
} // namespace

DemSystem::DemSystem(const Case &c) : DemSystem(c, build_wall_primitives(c)) {}

DemSystem::DemSystem(const Case &c, const WallSet &walls)
  : case_(c), walls_(walls), guards_(c.dem.max_overlap_fraction, c.dem.max_kinetic_energy_growth)
{
  box_.length = {c.dem.periodic_length_x, c.dem.periodic_length_y, c.dem.periodic_length};
}

void DemSystem::insert_particles()
{
  insert_populations(case_, walls_, box_, particles_);
  if (exchange_)
  {
    ParticleState add;
    exchange_->initial_particles(particles_, add);
    for (std::size_t k = 0; k < add.size(); ++k)
      particles_.append_from(add, k);
  }
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
  // Particles the exchange may bring in later (none without one): they count for the stable
  // time step, and for the skin when the scene starts empty.
  ParticleState later;
  if (exchange_)
    exchange_->smallest_particles(later);
  if (n == 0 && later.size() == 0)
    throw std::invalid_argument("dem: the scene has no particles (check the populations' count/mass)");
  if (particles_.next_id < particles_.id_bound())
    particles_.next_id = particles_.id_bound(); // ids set by hand (tests): never reuse one
  std::vector<std::string> species_materials, species_names;
  std::vector<Material> materials;
  for (const auto &p : case_.populations)
  {
    species_materials.push_back(p.material);
    species_names.push_back(p.name);
    materials.push_back(contact_material(case_, materials.size())); // toner stiffness factor
  }
  for (std::size_t i = 0; i < n; ++i)
    if (particles_.species[i] < 0 || U(particles_.species[i]) >= species_materials.size())
      throw std::invalid_argument("dem: particle " + std::to_string(particles_.id[i]) + " has species " +
                                  std::to_string(particles_.species[i]) + " but the case has " +
                                  std::to_string(species_materials.size()) + " populations");
  table_.build(case_, species_materials, walls_.materials());
  // The table again, one array per field (the pair kernel gathers from these).
  const std::size_t types = table_.species() * table_.columns();
  coefficient_fields_.assign(9 * types, 0.0);
  for (std::size_t t = 0; t < types; ++t)
  {
    const ContactCoefficients &k = table_.data()[t];
    const AdhesionCoefficients &a = table_.adhesion_data()[t];
    const double fields[9] = {k.effective_modulus, k.effective_shear, k.friction,
                              k.rolling_friction, k.damping_normal, k.damping_tangential,
                              a.hamaker, a.asperity_i, a.asperity_j};
    for (std::size_t f = 0; f < 9; ++f)
      coefficient_fields_[f * types + t] = fields[f];
  }
  ParticleState all = particles_;
  for (std::size_t k = 0; k < later.size(); ++k)
    all.append_from(later, k);
  stable_ = stable_time_step(all, materials, species_names, table_, walls_.size(),
                             std::max(1.0, 2.0 * walls_.max_surface_speed()));
  dt_ = choose_time_step(case_.dem, stable_);
  configure_substeps(materials, species_names, all); // may lengthen dt_ to k substeps

  const ParticleState &sized = n > 0 ? particles_ : later;
  double mean_d = 0.0, mass = 0.0, sized_count = 0.0;
  const int carried = carried_toner_population(case_);
  for (std::size_t i = 0; i < sized.size(); ++i)
  {
    mean_d += 2.0 * sized.radius[i];
    mass += sized.mass[i];
    sized_count += 1.0;
    if (carried >= 0 && sized.carried_count[i] > 0)
    {
      // Carried toner counts as the particles it becomes (the scene the skin is for).
      const double c = static_cast<double>(sized.carried_count[i]);
      mean_d += c * case_.populations[static_cast<std::size_t>(carried)].diameter_mean;
      sized_count += c;
    }
  }
  mean_d /= sized_count;
  skin_ = case_.dem.verlet_skin * mean_d;
  energy_floor_ = 0.5 * mass * 1.0; // (1 m/s)²: the runaway guard ignores growth below this
  forces_.resize(n);
  contact_count_.assign(n, 0);
  wall_slots_.reset(n, walls_.size());
  times_.terms.resize(terms_.size(), 0.0);
}

void DemSystem::initialize()
{
  setup_derived();
  list_ = NeighbourList{}; // a fresh start: no history from an earlier particle set
  rebuild_neighbour_list();
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
  if (substeps_.on())
    initial_fast_forces(thread_flags_[0]);
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
  wall_slots_.permute(order, scratch_, iscratch_);
  for (auto &t : terms_)
    t->particles_reordered(order);
}

void DemSystem::rebuild_neighbour_list(const std::vector<std::int32_t> *origin)
{
  PhaseTimer timer(times_.neighbour);
  // Pairs are listed out to contact + adhesion range (0 without adhesion) + skin.
  const double reach = table_.particles_adhesive() ? table_.adhesion_range() : 0.0;
  list_.rebuild(particles_, box_, skin_ + reach,
                [this](const std::vector<std::int32_t> &order) { permute_particles(order); }, origin);
  x0_ = particles_.x;
  y0_ = particles_.y;
  z0_ = particles_.z;
  force_rebuild_ = false;
  ++rebuilds_;
  find_fast_pairs();
}

void DemSystem::set_particle_exchange(std::unique_ptr<ParticleExchange> exchange)
{
  if (exchange && exchange->interval_steps() < 1)
    throw std::invalid_argument(std::string("dem: particle exchange '") + exchange->name() +
                                "' must exchange at most once per step");
  exchange_ = std::move(exchange);
}

// Leavers out and newcomers in, as one map from the new index to the old (origin_), applied
// to every per-particle array of the engine and its parts; the list rebuild that follows
// carries the contact history through the same map.
void DemSystem::exchange_particles(const std::vector<std::int32_t> &leave, const ParticleState &enter)
{
  const std::size_t n = particles_.size();
  leaving_.assign(n, 0);
  for (std::int32_t i : leave)
  {
    if (i < 0 || U(i) >= n || leaving_[U(i)])
      throw std::invalid_argument("dem: particle exchange: index " + std::to_string(i) +
                                  " is not a particle, or named twice");
    leaving_[U(i)] = 1;
  }
  keep_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (!leaving_[i])
      keep_.push_back(static_cast<std::int32_t>(i));
  particles_.permute(keep_, scratch_, iscratch_);
  forces_.permute(keep_, scratch_);
  permute_array(contact_count_, keep_, iscratch_);
  wall_slots_.permute(keep_, scratch_, iscratch_);
  for (std::size_t k = 0; k < enter.size(); ++k)
  {
    if (enter.species[k] < 0 || U(enter.species[k]) >= case_.populations.size())
      throw std::invalid_argument("dem: particle exchange: an entering particle has species " +
                                  std::to_string(enter.species[k]));
    particles_.append_from(enter, k);
  }
  const std::size_t m = particles_.size();
  forces_.extend(m);
  contact_count_.resize(m, 0);
  wall_slots_.extend(m);
  origin_ = keep_;
  origin_.resize(m, -1);
  entered_ += static_cast<long>(enter.size());
  left_ += static_cast<long>(leave.size());
  for (auto &t : terms_)
    t->particles_changed(origin_);
  double mass = 0.0;
  for (double v : particles_.mass)
    mass += v;
  energy_floor_ = 0.5 * mass * 1.0;
  rebuild_neighbour_list(&origin_);
}

// The exchange of the step in progress (after its drift, before its forces). False when
// nobody left or entered: then the particles, their order and the lists are as they were, and
// nothing (neither the engine's list nor a force term's) has to be rebuilt for it — a fed
// scene exchanges every few µs, mostly with nobody at its doors.
bool DemSystem::run_scheduled_exchange()
{
  leave_plan_.clear();
  enter_plan_.resize(0);
  exchange_->plan(particles_, time_, leave_plan_, enter_plan_);
  if (leave_plan_.empty() && enter_plan_.size() == 0)
    return false;
  exchange_particles(leave_plan_, enter_plan_);
  return true;
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

// Velocity Verlet's drift x += dt v(t + dt/2); returns the squared displacement since the
// last list build, and raises `step2` to the squared displacement of this drift.
inline double DemSystem::drift(std::size_t i, double dt, double &step2)
{
  ParticleState &s = particles_;
  const double ux = dt * s.vx[i], uy = dt * s.vy[i], uz = dt * s.vz[i];
  step2 = std::max(step2, ux * ux + uy * uy + uz * uz);
  s.x[i] += ux;
  s.y[i] += uy;
  s.z[i] += uz;
  const double dx = s.x[i] - x0_[i], dy = s.y[i] - y0_[i], dz = s.z[i] - z0_[i];
  return dx * dx + dy * dy + dz * dz;
}

// A particle in substeps is not moved by the step's kick and drift: its substeps move it
// later in the step (toner_substeps.cpp). For the list's expiry it counts with its drift so far
// plus a bound on its motion over the step, dt (2|v| + 1 m/s): the list must stay valid
// through the substeps, which come after the check.
inline double DemSystem::substep_drift_bound(std::size_t i, double dt) const
{
  const ParticleState &s = particles_;
  const double v = std::sqrt(s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i] + s.vz[i] * s.vz[i]);
  const double dx = s.x[i] - x0_[i], dy = s.y[i] - y0_[i], dz = s.z[i] - z0_[i];
  const double d = std::sqrt(dx * dx + dy * dy + dz * dz) + dt * (2.0 * v + 1.0);
  return d * d;
}

// Whether particle i's state is finite (checked after the final kick).
static inline bool state_is_finite(const ParticleState &s, std::size_t i)
{
  return std::isfinite(s.vx[i] + s.vy[i] + s.vz[i] + s.wx[i] + s.wy[i] + s.wz[i] + s.x[i] + s.y[i] + s.z[i]);
}

// First half of velocity Verlet: v(t + dt/2) = v(t) + (dt/2) F(t)/m, x(t + dt) = x + dt v(t + dt/2).
// Also this thread's largest squared displacement since the last list build; after the
// barrier every thread reads every thread's (max_drift2_of_team).
void DemSystem::kick_and_drift_phase(StepFlags &mine)
{
  double max_drift2 = 0.0, max_step2 = 0.0;
  const long n = static_cast<long>(particles_.size());
  const double h = 0.5 * dt_, dt = dt_;
  ParticleState &s = particles_;
  const ForceBuffers &f = forces_;
  const bool substeps = substeps_.on();
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    if (substeps && substeps_.fast(s.species[i]))
    {
      max_drift2 = std::max(max_drift2, substep_drift_bound(i, dt));
      continue;
    }
    half_kick(s, f, i, h);
    max_drift2 = std::max(max_drift2, drift(i, dt, max_step2));
  }
  mine.max_drift2 = max_drift2;
  mine.max_step2 = max_step2;
#pragma omp barrier
}

// Second half: v(t + dt) = v(t + dt/2) + (dt/2) F(t + dt)/m; flags a non-finite state.
// Static schedule, no barrier: a thread kicks exactly the particles whose forces it summed
// (and, in the next step, drifts them: the same static split).
void DemSystem::final_kick_phase(StepFlags &mine)
{
  ParticleAlarm not_finite; // the first in this thread's share
  const long n = static_cast<long>(particles_.size());
  const double h = 0.5 * dt_;
  ParticleState &s = particles_;
  const ForceBuffers &f = forces_;
  const bool substeps = substeps_.on();
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    if (substeps && substeps_.fast(s.species[i]))
      continue; // kicked in its substeps
    half_kick(s, f, i, h);
    if (!state_is_finite(s, i) && not_finite.particle < 0)
      not_finite.set(k, s.position(i));
  }
  if (mine.not_finite.particle < 0)
    mine.not_finite = not_finite;
}

// The final kick of this step and the kick and drift of the next, particle by particle: the
// same operations in the same order as final_kick_phase followed by kick_and_drift_phase
// (the same bits), but the velocities, forces and inverse masses are read once instead of
// twice. At 55k particles the arrays no longer stay in cache from one loop to the next, and
// these streaming loops cost twice as much per particle as at 14k (docs/dem_vs_lammps.md).
// Both halves use the forces of this step; the static split is that of both phases, and
// the barrier at the end is kick_and_drift_phase's.
void DemSystem::final_kick_and_next_drift_phase(StepFlags &mine)
{
  ParticleAlarm not_finite;
  double max_drift2 = 0.0, max_step2 = 0.0;
  const long n = static_cast<long>(particles_.size());
  const double h = 0.5 * dt_, dt = dt_;
  ParticleState &s = particles_;
  const ForceBuffers &f = forces_;
  const bool substeps = substeps_.on();
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    if (substeps && substeps_.fast(s.species[i]))
    {
      max_drift2 = std::max(max_drift2, substep_drift_bound(i, dt));
      continue;
    }
    half_kick(s, f, i, h);
    if (!state_is_finite(s, i) && not_finite.particle < 0)
      not_finite.set(k, s.position(i));
    half_kick(s, f, i, h);
    max_drift2 = std::max(max_drift2, drift(i, dt, max_step2));
  }
  if (mine.not_finite.particle < 0)
    mine.not_finite = not_finite;
  mine.max_drift2 = max_drift2;
  mine.max_step2 = max_step2;
#pragma omp barrier
}

std::string DemSystem::describe_particle(std::size_t i) const { return describe_particle(i, particles_.position(i)); }

std::string DemSystem::describe_particle(std::size_t i, const Vector3 &at) const
{
  return StabilityGuards::describe_particle(particles_, i, at);
}

// ---------------------------------------------------------------------------------------
// Particle–particle contacts (the kernel and the order of the sums: pair_kernel.h).

// Phase 1 (all threads, work-shared; ends with a barrier): pairs and rows, block by block.
// Sets this thread's overlap alarm when one of its pairs overlaps beyond the guard. On one
// thread the columns are summed here too (one_thread_pairs_rows_and_columns).
void DemSystem::pair_and_row_phase(StepFlags &mine)
{
  const PairKernelData D = pair_kernel_data();
  if (omp_get_num_threads() == 1)
  {
    mine.overlap_alarm |= one_thread_pairs_rows_and_columns(D, mine.row_torques);
    return;
  }
  int overlap_alarm = 0;
  const long n = static_cast<long>(particles_.size());
  const std::int32_t *row_start = list_.row_start.data();
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

// The kernel's view of the particles, the pairs and their slots.
PairKernelData DemSystem::pair_kernel_data()
{
  const ParticleState &s = particles_;
  NeighbourList &L = list_;
  // Image shifts and coefficients as plain arrays, one per component / field.
  const std::size_t types = table_.species() * table_.columns();
  const double *coef = coefficient_fields_.data();
  return PairKernelData{s.x.data(), s.y.data(), s.z.data(), s.vx.data(), s.vy.data(), s.vz.data(),
                        s.wx.data(), s.wy.data(), s.wz.data(), s.radius.data(), s.mass.data(),
                        s.inv_inertia.data(), s.species.data(), L.owner.data(), L.partner.data(),
                        L.image.data(), L.shift_component(0), L.shift_component(1), L.shift_component(2), coef, coef + types,
                        coef + 2 * types, coef + 3 * types, coef + 4 * types, coef + 5 * types,
                        static_cast<std::int64_t>(table_.columns()), table_.species() == 1, dt_,
                        case_.dem.max_overlap_fraction, L.hist_x.data(), L.hist_y.data(), L.hist_z.data(),
                        L.force_x.data(), L.force_y.data(), L.force_z.data(), L.torque_j_x.data(),
                        L.torque_j_y.data(), L.torque_j_z.data(), L.touching.data(),
                        coef + 6 * types, coef + 7 * types, coef + 8 * types, table_.adhesion_cutoff(),
                        table_.adhesion_range(), table_.particles_adhesive(), 0,
                        substeps_.on() ? substeps_.skip.data() : nullptr};
}

namespace {
// m pairs into their partners' column sums, in pair order: column[partner] += sign × v (sign
// ±1: −F on the partner, +its torque; the sign only flips, so the sum is the column pass's
// `−=`), and the touching flags into the contact counts (when given).
void scatter_to_columns(const std::int32_t *__restrict partner, const std::int32_t *__restrict touching,
                        const double *__restrict vx, const double *__restrict vy, const double *__restrict vz,
                        double sign, double *__restrict cx, double *__restrict cy, double *__restrict cz,
                        std::int32_t *__restrict count, std::size_t m)
{
  for (std::size_t k = 0; k < m; ++k)
  {
    const std::size_t j = static_cast<std::size_t>(partner[k]);
    cx[j] += sign * vx[k];
    cy[j] += sign * vy[k];
    cz[j] += sign * vz[k];
  }
  if (count)
    for (std::size_t k = 0; k < m; ++k)
      count[static_cast<std::size_t>(partner[k])] += touching[k];
}
} // namespace

// Phases 1 and 2 on one thread (pair_kernel.h): the same sums in the same order, so the same
// bits, but each block's pair forces stay in `scratch` and go straight into the partners'
// column sums, which wait in the force arrays until their own row is reached. At 55k
// particles the per-pair slots (48 bytes a pair, written, then read back through the
// transposed index) no longer stay in cache between the two passes.
int DemSystem::one_thread_pairs_rows_and_columns(PairKernelData D, std::vector<double> &scratch)
{
  int overlap_alarm = 0;
  const long n = static_cast<long>(particles_.size());
  const std::int32_t *row_start = list_.row_start.data(), *partner = list_.partner.data();
  ForceBuffers &f = forces_;
  for (std::vector<double> *a : {&f.fx, &f.fy, &f.fz, &f.tx, &f.ty, &f.tz})
    std::fill(a->begin(), a->end(), 0.0); // the column sums start from zero
  std::fill(contact_count_.begin(), contact_count_.end(), 0);
  const long blocks = (n + contact_block_rows - 1) / contact_block_rows;
  for (long b = 0; b < blocks; ++b)
  {
    const long i0 = b * contact_block_rows, i1 = std::min(n, i0 + contact_block_rows);
    const std::int64_t p0 = row_start[i0], p1 = row_start[i1];
    const std::size_t m = static_cast<std::size_t>(p1 - p0);
    scratch.resize(9 * m);
    double *out = scratch.data();
    D.fx = out, D.fy = out + m, D.fz = out + 2 * m;
    D.tjx = out + 3 * m, D.tjy = out + 4 * m, D.tjz = out + 5 * m;
    D.slot_base = p0;
    const RowTorques T{out + 6 * m, out + 7 * m, out + 8 * m};
    overlap_alarm |= particle_pair_kernel(D, T, p0, p1);
    // The block's pairs into their partners' column sums, in ascending pair order (each
    // partner j > its pair's i). Every pair of a column of this block's rows is then in:
    // its pairs belong to earlier rows, of this block or of earlier ones. (Forces and
    // torques in separate passes: fewer live pointers, no spills in the scalar loops.)
    scatter_to_columns(partner + p0, D.touching + p0, D.fx, D.fy, D.fz, -1.0, f.fx.data(), f.fy.data(), f.fz.data(),
                       contact_count_.data(), m);
    scatter_to_columns(partner + p0, nullptr, D.tjx, D.tjy, D.tjz, 1.0, f.tx.data(), f.ty.data(), f.tz.data(), nullptr,
                       m);
    // Each row's own pairs, then column + row, as column_phase forms it.
    for (long i = i0; i < i1; ++i)
    {
      double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
      std::int32_t count = 0;
      for (std::int64_t p = row_start[i]; p < row_start[i + 1]; ++p)
      {
        const std::size_t k = static_cast<std::size_t>(p - p0);
        count += D.touching[p];
        fx += D.fx[k];
        fy += D.fy[k];
        fz += D.fz[k];
        tx += T.x[k];
        ty += T.y[k];
        tz += T.z[k];
      }
      const std::size_t iu = static_cast<std::size_t>(i);
      f.fx[iu] = fx + f.fx[iu];
      f.fy[iu] = fy + f.fy[iu];
      f.fz[iu] = fz + f.fz[iu];
      f.tx[iu] = tx + f.tx[iu];
      f.ty[iu] = ty + f.ty[iu];
      f.tz[iu] = tz + f.tz[iu];
      contact_count_[iu] += count;
    }
  }
  return overlap_alarm;
}

// Phase 2 (after phase 1's barrier; static schedule, no barrier): each particle sums the
// pairs in which it is the partner, in ascending pair order from zero (−F on it, the pair's
// torque on j), and adds that to its row's sum. (On one thread phase 1 has done this.)
void DemSystem::column_phase()
{
  if (omp_get_num_threads() == 1)
    return;
  const NeighbourList &L = list_;
  const long n = static_cast<long>(particles_.size());
  ForceBuffers &f = forces_;
  const std::int32_t *col_start = L.col_start.data(), *col_pair = L.col_pair.data();
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
    std::int32_t count = 0;
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
    f.fx[i] += fx;
    f.fy[i] += fy;
    f.fz[i] += fz;
    f.tx[i] += tx;
    f.ty[i] += ty;
    f.tz[i] += tz;
    contact_count_[i] += count;
  }
}

// Overlap first (the worst pair is searched in the state where it happened), then the walls,
// then the state.
void DemSystem::raise_alarms(const StepAlarms &alarms) const
{
  if (alarms.overlap_alarm)
    raise_worst_pair_overlap();
  if (alarms.wall_crowded.particle >= 0)
    guards_.wall_crowded(clock(), describe_particle(U(alarms.wall_crowded.particle), alarms.wall_crowded.at),
                         max_wall_contacts);
  if (alarms.wall_overlap.particle >= 0)
    guards_.wall_overlap(clock(), describe_particle(U(alarms.wall_overlap.particle), alarms.wall_overlap.at));
  if (alarms.not_finite.particle >= 0)
    guards_.not_finite(clock(), describe_particle(U(alarms.not_finite.particle), alarms.not_finite.at));
}

void DemSystem::raise_worst_pair_overlap() const
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
  guards_.pair_overlap(clock(), describe_particle(wi), s.id[wj], worst);
}

// Wall contacts of every particle (static schedule, no barrier; walls_.prepare() has run).
// Records the largest index of a particle that overlaps a wall beyond the guard (alarm) or
// touches too many walls (crowded); raise_alarms() turns them into errors. The toner in
// substeps is left to its substeps (toner_substeps.cpp).
void DemSystem::wall_phase(StepFlags &mine)
{
  long alarm = -1, too_many = -1;
  ParticleState &s = particles_;
  const ForceArrays out = forces_.main();
  const long n = static_cast<long>(s.size());
  const double dt = dt_;
  const bool substeps = substeps_.on();
#pragma omp for schedule(static) nowait
  for (long k = 0; k < n; ++k)
  {
    const std::size_t i = static_cast<std::size_t>(k);
    if (substeps && substeps_.fast(s.species[i]))
      continue;
    particle_wall_contacts(i, dt, out, alarm, too_many);
  }
  record_wall_alarms(mine, alarm, too_many);
}

void DemSystem::record_wall_alarms(StepFlags &mine, long alarm, long too_many) const
{
  const ParticleState &s = particles_;
  if (alarm > mine.wall_overlap.particle)
    mine.wall_overlap.set(alarm, s.position(static_cast<std::size_t>(std::max(0L, alarm))));
  if (too_many > mine.wall_crowded.particle)
    mine.wall_crowded.set(too_many, s.position(static_cast<std::size_t>(std::max(0L, too_many))));
}

void DemSystem::particle_wall_contacts(std::size_t i, double dt, const ForceArrays &out, long &alarm,
                                       long &too_many)
{
  ParticleState &s = particles_;
  const std::size_t W = walls_.size();
  const double guard = case_.dem.max_overlap_fraction;
  // Van der Waals adhesion reaches across a gap (0 without adhesion: only touching walls).
  const bool adhesive = table_.adhesive();
  const double range = adhesive ? table_.adhesion_range() : 0.0, z0 = table_.adhesion_cutoff();
  WallContactGeometry g[max_wall_contacts + 1];
  int which[max_wall_contacts + 1] = {};
  const long k = static_cast<long>(i);
  const Vector3 p = s.position(i);
  const double r = s.radius[i];
  // Pass 1: which walls touch this particle now.
  int m = 0;
  for (std::size_t w = 0; w < W; ++w)
  {
    if (!walls_.may_touch(w, p, r + range) || !walls_.contact(w, p, r, g[m], range))
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
  wall_slots_.release_untouched(i, which, m);
  // Pass 3: evaluate each contact with its slot's history.
  for (int c = 0; c < m; ++c)
  {
    const std::size_t sl = wall_slots_.slot_for(i, which[c]);
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
    Vector3 xi_t = wall_slots_.history(sl);
    ContactOutcome o;
    if (ck.overlap > 0.0) // always, without adhesion
      o = evaluate_contact(table_.particle_wall(s.species[i], which[c]), ck, xi_t, dt);
    else
      xi_t = {}; // held across a gap by adhesion only: no contact, no history
    if (adhesive)
    {
      const AdhesionCoefficients &a = table_.adhesion_wall(s.species[i], which[c]);
      const double R_a = HamakerAdhesion::wall_radius(r, a.asperity_i, a.asperity_j);
      o.force_i += HamakerAdhesion::force(a.hamaker, R_a, -ck.overlap, z0) * ck.n;
    }
    wall_slots_.set_history(sl, xi_t);
    const double force[3] = {o.force_i.x, o.force_i.y, o.force_i.z}, torque[3] = {o.torque_i.x, o.torque_i.y, o.torque_i.z};
    out.add(i, force, torque);
    // Load on the wall: −F at the contact point, torque about the wall's reference point.
    const Vector3 arm = p + ck.lever_i * ck.n - g[c].torque_origin;
    wall_slots_.set_load(sl, -o.force_i, cross(arm, -o.force_i));
  }
}

void DemSystem::check_energy()
{
  PhaseTimer timer(times_.guards);
  guards_.check_energy(clock(), particles_, kinetic_energy() + rotational_energy(), energy_floor_);
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

std::vector<WallLoad> DemSystem::wall_loads() const { return wall_slots_.loads(walls_.size()); }

void DemSystem::wall_contacts(std::size_t w, std::vector<WallContactRecord> &out) const
{
  wall_slots_.contacts_of_wall(w, out);
}

std::size_t DemSystem::memory_bytes() const
{
  const auto &s = particles_;
  std::size_t b = 0;
  for (const auto *a : {&s.x, &s.y, &s.z, &s.vx, &s.vy, &s.vz, &s.wx, &s.wy, &s.wz, &s.radius, &s.mass,
                        &s.inv_mass, &s.inv_inertia, &s.charge, &forces_.fx, &forces_.fy, &forces_.fz,
                        &forces_.tx, &forces_.ty, &forces_.tz, &x0_, &y0_, &z0_, &scratch_})
    b += a->capacity() * sizeof(double);
  for (const auto *a : {&s.species, &s.id, &contact_count_, &iscratch_})
    b += a->capacity() * sizeof(std::int32_t);
  return b + wall_slots_.memory_bytes() + list_.memory_bytes();
}

// ---------------------------------------------------------------------------------------
// Checkpoints (format: checkpoint_file.h): the clock, then every dynamic array.

// The particle and force arrays, in the order of the file.
namespace {
template <typename State, typename Forces>
auto checkpoint_arrays(State &s, Forces &f)
{
  return std::array{&s.x, &s.y, &s.z, &s.vx, &s.vy, &s.vz, &s.wx, &s.wy, &s.wz, &s.radius, &s.mass,
                    &s.inv_mass, &s.inv_inertia, &s.charge, &s.carried_mass, &s.carried_charge, &f.fx, &f.fy, &f.fz, &f.tx, &f.ty, &f.tz,
                    &f.fast_fx, &f.fast_fy, &f.fast_fz, &f.fast_tx, &f.fast_ty, &f.fast_tz};
}
} // namespace

void DemSystem::write_checkpoint(const std::string &path) { write_checkpoint(path, CheckpointIdentity{}); }

void DemSystem::write_checkpoint(const std::string &path, const CheckpointIdentity &identity,
                                 const std::function<void(StateOut &)> &appendix)
{
  CheckpointWriter out(path, identity);
  out.put(step_);
  out.put(time_);
  out.put(dt_);
  out.put(guards_.last_energy());
  out.put<std::uint64_t>(walls_.size());
  for (const auto *a : checkpoint_arrays(particles_, forces_))
    out.put_array(*a);
  out.put_array(particles_.species);
  out.put_array(particles_.id);
  out.put_array(particles_.carried_count);
  out.put_array(contact_count_);
  // The positions the neighbour list was built from: a restart builds the same list from
  // them (the same pairs in the same order), so that writing a checkpoint changes nothing in
  // the run that writes it — a checkpoint taken at a wall-clock moment leaves the bits alone.
  out.put_array(x0_);
  out.put_array(y0_);
  out.put_array(z0_);
  out.put(rebuilds_);
  out.put<std::uint8_t>(force_rebuild_); // a rebuild requested for the next step
  // Particles entering and leaving: the id counter and the engine's counts; the skin and the
  // energy-guard floor were set at initialize() for a set of particles that may have changed
  // since, so the restart takes them from here (before it rebuilds the list with the skin).
  out.put(particles_.next_id);
  out.put(entered_);
  out.put(left_);
  out.put(skin_);
  out.put(energy_floor_);
  list_.write_history(out);
  wall_slots_.write(out);
  // Each force term's own state, framed by its name so that a restart under a different set
  // of terms is refused rather than misread.
  out.put<std::uint64_t>(terms_.size());
  for (const auto &term : terms_)
  {
    const std::string name = term->name();
    out.put_array(std::vector<char>(name.begin(), name.end()));
    term->write_state(out);
  }
  // The particle exchange's own state, framed by its name ("" = none).
  const std::string exchange = exchange_ ? exchange_->name() : "";
  out.put_array(std::vector<char>(exchange.begin(), exchange.end()));
  if (exchange_)
    exchange_->write_state(out);
  if (appendix)
    appendix(out);
  out.commit();
}

void DemSystem::read_checkpoint(const std::string &path, const std::function<void(StateIn &)> &appendix)
{
  CheckpointReader in(path);
  const long step = in.get<long>();
  const double time = in.get<double>();
  const double dt = in.get<double>();
  const double last_energy = in.get<double>();
  const auto n_walls = in.get<std::uint64_t>();
  if (n_walls != walls_.size())
    in.fail("has " + std::to_string(n_walls) + " walls, the case has " + std::to_string(walls_.size()) +
            ": restart with the case that wrote it");
  for (auto *a : checkpoint_arrays(particles_, forces_))
    in.get_array(*a);
  in.get_array(particles_.species);
  in.get_array(particles_.id);
  in.get_array(particles_.carried_count);
  in.get_array(contact_count_);
  std::vector<double> x0, y0, z0;
  in.get_array(x0);
  in.get_array(y0);
  in.get_array(z0);
  const long rebuilds = in.get<long>();
  const bool rebuild_requested = in.get<std::uint8_t>() != 0;
  const auto next_id = in.get<std::int32_t>();
  const long entered = in.get<long>(), left = in.get<long>();
  const double skin = in.get<double>(), energy_floor = in.get<double>();
  const std::size_t n = particles_.size();
  for (const auto *a : checkpoint_arrays(particles_, forces_))
    if (a->size() != n)
      in.fail("is corrupt (particle arrays of different lengths)");
  if (particles_.species.size() != n || particles_.id.size() != n || particles_.carried_count.size() != n ||
      contact_count_.size() != n ||
      x0.size() != n || y0.size() != n || z0.size() != n)
    in.fail("is corrupt (particle arrays of different lengths)");
  // Derived set-up (contact table, time-step check, skin) as for a fresh run, then the state.
  const ForceBuffers saved_forces = forces_;
  const std::vector<std::int32_t> saved_counts = contact_count_;
  setup_derived();
  particles_.next_id = next_id;
  entered_ = entered;
  left_ = left;
  skin_ = skin;
  energy_floor_ = energy_floor;
  // The neighbour list of the run that wrote the file, built again from the positions it was
  // built from. The particles are already in that build's cell order, so the build's stable
  // re-sort leaves them in place (checked: a changed order would continue differently).
  std::swap(particles_.x, x0);
  std::swap(particles_.y, y0);
  std::swap(particles_.z, z0);
  const std::vector<std::int32_t> ids = particles_.id;
  rebuild_neighbour_list();
  std::swap(particles_.x, x0);
  std::swap(particles_.y, y0);
  std::swap(particles_.z, z0);
  if (particles_.id != ids) // (x0_ … now hold the build positions again, as in the writer)
    in.fail("does not reproduce its neighbour list (the particles were re-sorted): restart with the "
            "magbrush that wrote it");
  rebuilds_ = rebuilds;
  force_rebuild_ = rebuild_requested;
  list_.read_history(in);
  wall_slots_.read(in);
  const auto n_terms = in.get<std::uint64_t>();
  if (n_terms != terms_.size())
    in.fail("holds the state of " + std::to_string(n_terms) + " force terms, this run has " +
            std::to_string(terms_.size()) + ": restart with the case that wrote it");
  for (const auto &term : terms_)
  {
    std::vector<char> name;
    in.get_array(name);
    if (std::string(name.begin(), name.end()) != term->name())
      in.fail("holds the state of force term '" + std::string(name.begin(), name.end()) +
              "' where this run has '" + term->name() + "': restart with the case that wrote it");
    term->read_state(in);
  }
  std::vector<char> exchange_name;
  in.get_array(exchange_name);
  const std::string exchange = exchange_ ? exchange_->name() : "";
  if (std::string(exchange_name.begin(), exchange_name.end()) != exchange)
    in.fail("was written with particle exchange '" + std::string(exchange_name.begin(), exchange_name.end()) +
            "' where this run has '" + exchange + "': restart with the case that wrote it");
  if (exchange_)
    exchange_->read_state(in);
  if (appendix)
    appendix(in);
  forces_ = saved_forces;
  contact_count_ = saved_counts;
  step_ = step;
  time_ = time;
  guards_.set_last_energy(last_energy);
  dt_ = dt;
  initialized_ = true;
}

} // namespace magbrush::dem
