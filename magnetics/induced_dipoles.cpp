#include "magnetics/induced_dipoles.h"

#include "magnetics/dipole_physics.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace magbrush::magnetics {

namespace {
// Wall-clock laps of the phases of an evaluation (MagneticStats::time_*).
class PhaseClock
{
public:
  void restart() { clock_ = omp_get_wtime(); }
  void lap(double &phase)
  {
    const double now = omp_get_wtime();
    phase += now - clock_;
    clock_ = now;
  }

private:
  double clock_ = omp_get_wtime();
};
} // namespace

InducedDipoles::InducedDipoles(const MagneticSettings &settings, const std::array<double, 3> &box)
  : settings_(settings), box_(box), solver_(settings.tolerance, settings.max_sweeps),
    correction_(settings, box), staleness_(settings, box)
{
  live_.set_steps(settings_.live_pair_steps);
  if (!(settings_.cutoff_length > 0.0 || settings_.cutoff_diameters > 0.0))
    throw std::invalid_argument("magnetics: expected a positive cutoff (cutoff_diameters or "
                                "cutoff_length); found neither.");
  if (!(settings_.tolerance > 0.0) || settings_.max_sweeps < 1)
    throw std::invalid_argument("magnetics: expected tolerance > 0 and max_sweeps ≥ 1; found " +
                                std::to_string(settings_.tolerance) + " and " +
                                std::to_string(settings_.max_sweeps) + ".");
  if (settings_.model == DipoleModel::corrected &&
      !(settings_.switch_begin >= 2.0 && settings_.switch_end > settings_.switch_begin))
    throw std::invalid_argument("magnetics: the corrected model needs 2 ≤ switch_begin < "
                                "switch_end (in radii); found " +
                                std::to_string(settings_.switch_begin) + ", " +
                                std::to_string(settings_.switch_end) + ".");
  for (double L : box_)
    if (L < 0.0)
      throw std::invalid_argument("magnetics: periodic box lengths must be ≥ 0 (0 = open).");
  if (settings_.far_field == FarField::cell_multipole)
  {
    if (settings_.slab_tail_correction)
      throw std::invalid_argument(
        "magnetics: the slab tail correction is the mean field beyond a hard cutoff; the "
        "cell-multipole far field has no cutoff (it sums every periodic image). Switch "
        "slab_tail_correction off, or use far_field = none.");
    if (settings_.far_passes < 1 || !(settings_.far_cell_diameters > 0.0))
      throw std::invalid_argument("magnetics: the cell-multipole far field needs far_passes ≥ 1 "
                                  "and a positive cell size; found " +
                                  std::to_string(settings_.far_passes) + " and " +
                                  std::to_string(settings_.far_cell_diameters) + ".");
    far_ = std::make_unique<CellMultipoleField>(settings_.far_order, box_, settings_.far_near_reach);
    far_->set_single_precision(settings_.far_single_precision);
  }
  if (settings_.slab_tail_correction)
    tail_ = std::make_unique<SlabTail>(box_);
}

// ---------------------------------------------------------------------------------------
// One full evaluation.

MagneticStats InducedDipoles::compute(const BeadArrays &beads, const AppliedFieldFunction &field,
                                      double time, const ForceArrays &out)
{
  MagneticStats stats;
  if (beads.n == 0)
    return stats;
  if (!beads.x || !beads.y || !beads.z || !beads.radius || !beads.mu_r)
    throw std::invalid_argument("magnetics: bead arrays x, y, z, radius and mu_r are required.");

  set_materials(beads);
  PhaseClock clock;
  evaluate_applied_field(beads, field);
  zero_field_ = std::all_of(B0_.begin(), B0_.end(), [](double v) { return v == 0.0; });
  if (zero_field_)
  {
    hold_zero_forces(beads, time);
    stats.zero_field = true;
    clock.lap(stats.time_tensors);
    return stats;
  }
  clock.lap(stats.time_tensors);
  const double cutoff = find_near_pairs(beads, stats);
  clock.lap(stats.time_lists);
  evaluate_pair_tensors(beads, cutoff, stats);
  clock.lap(stats.time_tensors);
  solve_dipoles(beads, stats);
  clock.restart();
  hold_forces_of_dipoles(beads, time, stats, out);
  clock.lap(stats.time_forces);
  if (settings_.hold_dipoles)
  {
    live_.select(beads, near_, settings_.live_pair_radius);
    live_.rebase_all({beads, beta_, B_local_, p_}, live_correction());
  }
  return stats;
}

// The end of an evaluation, once the dipoles and local fields are known: the correction's
// tables, the pair forces, each bead's total (also added to `out`), the staleness references.
void InducedDipoles::hold_forces_of_dipoles(const BeadArrays &beads, double time, MagneticStats &stats,
                                            const ForceArrays &out)
{
  // Tables depend on the beads' β only: re-check when the list (hence the bead set) changed.
  if (settings_.model == DipoleModel::corrected && (stats.list_rebuilt || !correction_.has_tables()))
    correction_.prepare_tables(beta_);
  evaluate_forces(beads, stats);
  gather_forces(out);
  remember_evaluation(beads, time);
}

MagneticStats InducedDipoles::forces_of_dipoles(const BeadArrays &beads, const AppliedFieldFunction &field,
                                                double time, const std::vector<double> &p, const ForceArrays &out)
{
  if (p.size() != 3 * beads.n)
    throw std::invalid_argument("magnetics: forces_of_dipoles needs 3 dipole components per bead.");
  MagneticStats stats;
  if (beads.n == 0)
    return stats;
  set_materials(beads);
  evaluate_applied_field(beads, field);
  const double cutoff = find_near_pairs(beads, stats);
  evaluate_pair_tensors(beads, cutoff, stats);
  p_ = p;
  p_next_.resize(3 * beads.n);
  B_local_.resize(3 * beads.n);
  if (far_)
    evaluate_far_field(stats);
  if (tail_)
    tail_->evaluate(p_);
#pragma omp parallel for schedule(static) if (beads.n >= bead_parallel_threshold)
  for (long b = 0; b < static_cast<long>(beads.n); ++b)
    gather_local_field(static_cast<std::size_t>(b), p_, &B_local_[3 * b]);
  hold_forces_of_dipoles(beads, time, stats, out);
  return stats;
}

void InducedDipoles::set_materials(const BeadArrays &beads)
{
  beta_.resize(beads.n);
  Ms_.resize(beads.n);
  for (std::size_t b = 0; b < beads.n; ++b)
  {
    beta_[b] = clausius_mossotti(beads.mu_r[b]);
    Ms_[b] = beads.saturation_magnetisation ? beads.saturation_magnetisation[b] : 0.0;
  }
}

void InducedDipoles::evaluate_applied_field(const BeadArrays &beads,
                                            const AppliedFieldFunction &field)
{
  const std::size_t n = beads.n;
  B0_.resize(3 * n);
  gradB0_.resize(9 * n);
#pragma omp parallel for schedule(static) if (n >= bead_parallel_threshold)
  for (long b = 0; b < static_cast<long>(n); ++b)
    evaluate_applied_field_at(beads, field, static_cast<std::size_t>(b));
}

void InducedDipoles::evaluate_applied_field_at(const BeadArrays &beads, const AppliedFieldFunction &field,
                                               std::size_t b)
{
  const double x[3] = {beads.x[b], beads.y[b], beads.z[b]};
  double B[3], g[3][3];
  field(x, B, g);
  for (int a = 0; a < 3; ++a)
  {
    B0_[3 * b + a] = B[a];
    for (int c = 0; c < 3; ++c)
      gradB0_[9 * b + 3 * a + c] = g[a][c];
  }
}

void InducedDipoles::hold_zero_forces(const BeadArrays &beads, double time)
{
  live_.clear();
  // No applied field anywhere (before a field ramp starts, or a schedule at 0 mT): the
  // induced dipoles are all zero, and so are the forces: nothing to solve. The next compute
  // starts cold (from the applied-field dipoles).
  p_.clear();
  force_.assign(3 * beads.n, 0.0);
  torque_.assign(3 * beads.n, 0.0);
  staleness_.evaluated_all(beads, time);
  computed_ = true;
}

double InducedDipoles::find_near_pairs(const BeadArrays &beads, MagneticStats &stats)
{
  const double sum = radius_sum(beads);
  skin_ = settings_.skin_fraction * 2.0 * sum / beads.n;
  if (far_)
  {
    update_cells(beads, sum, stats);
    stats.cutoff = 0.0;
    return std::numeric_limits<double>::infinity();
  }
  const double cutoff = cutoff_length(beads);
  stats.cutoff = cutoff;
  update_cutoff_list(beads, cutoff, stats);
  return cutoff;
}

void InducedDipoles::update_cells(const BeadArrays &beads, double radius_sum, MagneticStats &stats)
{
  // No cutoff: the near pairs are those of neighbouring fine cells. Like a Verlet list, the
  // cells and the near pairs are kept until some bead moved more than half the skin (a bead
  // wrapped by the caller counts as a large move); in between, the beads keep the cells they
  // were sorted into and only their positions are updated.
  const std::size_t n = beads.n;
  const double mean_diameter = 2.0 * radius_sum / n;
  const double skin = settings_.skin_fraction * mean_diameter;
  MagneticNeighbourList &list = near_.list();
  if (!list.built() || list.particle_count() != n ||
      list.max_displacement(n, beads.x, beads.y, beads.z) > 0.5 * skin)
  {
    far_cell_size_ = settings_.far_cell_diameters * mean_diameter;
    far_->build(n, beads.x, beads.y, beads.z, far_cell_size_);
    // The pairs change hands by swaps (far field → spare → list → spare): no copy, and
    // every buffer keeps its capacity for the next rebuild.
    far_->take_near_pairs(spare_pairs_);
    list.set_pairs(n, beads.x, beads.y, beads.z, box_, 0.0, spare_pairs_);
    stats.list_rebuilt = true;
  }
  else
    far_->update_positions(beads.x, beads.y, beads.z);
  stats.listed_pairs = list.size();
  stats.far_cells = far_->fine_cells();
  stats.far_interactions = far_->interactions();
  if (settings_.model == DipoleModel::corrected)
    correction_.refresh_list(beads);
}

void InducedDipoles::update_cutoff_list(const BeadArrays &beads, double cutoff, MagneticStats &stats)
{
  MagneticNeighbourList &list = near_.list();
  const bool stale = !list.built() || list.particle_count() != beads.n || list.box() != box_ ||
                     std::abs(list.list_radius() - (cutoff + skin_)) > 1e-12 * cutoff ||
                     list.max_displacement(beads.n, beads.x, beads.y, beads.z) > 0.5 * skin_;
  if (stale)
  {
    list.build(beads.n, beads.x, beads.y, beads.z, box_, cutoff + skin_);
    stats.list_rebuilt = true;
  }
  stats.listed_pairs = list.size();
}

double InducedDipoles::cutoff_length(const BeadArrays &beads) const
{
  if (settings_.cutoff_length > 0.0)
    return settings_.cutoff_length;
  const double sum = radius_sum(beads);
  const double mean_diameter = beads.n ? 2.0 * sum / beads.n : 0.0;
  return settings_.cutoff_diameters * mean_diameter;
}

void InducedDipoles::evaluate_pair_tensors(const BeadArrays &beads, double cutoff, MagneticStats &stats)
{
  stats.pairs = near_.evaluate_tensors(beads, cutoff);
  if (far_)
    near_.build_rows();
  if (tail_)
    tail_->prepare(beads, cutoff);
}

void InducedDipoles::solve_dipoles(const BeadArrays &beads, MagneticStats &stats)
{
  const std::size_t n = beads.n;
  B_local_.resize(3 * n);
  p_next_.resize(3 * n);
  const bool warm_start = (p_.size() == 3 * n) && settings_.model != DipoleModel::point_dipole;
  if (!warm_start)
  {
    p_.resize(3 * n);
#pragma omp parallel for schedule(static) if (n >= bead_parallel_threshold)
    for (long b = 0; b < static_cast<long>(n); ++b)
      induced_moment(beads.radius[b], beta_[b], Ms_[b], &B0_[3 * b], &p_[3 * b]);
  }
  const bool fresh = warm_start && !fresh_.empty(); // beads that entered: applied-field dipoles
  if (fresh)
    for (std::uint32_t b : fresh_)
      induced_moment(beads.radius[b], beta_[b], Ms_[b], &B0_[3 * b], &p_[3 * b]);
  fresh_.clear();
  if (settings_.model == DipoleModel::point_dipole)
  {
    if (far_)
      evaluate_far_field(stats);
    if (tail_)
      tail_->evaluate(p_);
    hold_point_dipoles();
    stats.sweeps = 0;
    stats.residual = 0.0;
    stats.converged = true;
    return;
  }
  if (far_)
  {
    // The far field is held fixed through the sweeps (only the near field changes from
    // sweep to sweep) and re-evaluated from the latest dipoles far_passes times in all (one
    // more from a cold start, whose first far field comes from the applied-field dipoles).
    const int passes = settings_.far_passes + (warm_start && !fresh ? 0 : 1);
    for (int pass = 0; pass < passes; ++pass)
    {
      evaluate_far_field(stats);
      const double t0 = omp_get_wtime();
      sweep_to_tolerance(beads, stats);
      stats.time_sweeps += omp_get_wtime() - t0;
    }
    return;
  }
  const double t0 = omp_get_wtime();
  sweep_to_tolerance(beads, stats);
  stats.time_sweeps += omp_get_wtime() - t0;
}

void InducedDipoles::evaluate_far_field(MagneticStats &stats)
{
  const double t0 = omp_get_wtime();
  const std::size_t n = p_.size() / 3;
  B_far_.resize(3 * n);
  gradB_far_.resize(9 * n);
  far_->evaluate(p_.data(), B_far_.data(), gradB_far_.data());
  ++stats.far_passes;
  stats.time_far += omp_get_wtime() - t0;
}

void InducedDipoles::hold_point_dipoles()
{
  // Dipoles from the applied field only; the local field is needed only for the papers'
  // torque diagnostic (and the far field for the forces).
  const std::size_t n = p_.size() / 3;
  if (settings_.torque == TorqueModel::paper)
  {
#pragma omp parallel for schedule(static) if (n >= bead_parallel_threshold)
    for (long b = 0; b < static_cast<long>(n); ++b)
      gather_local_field(b, p_, &B_local_[3 * b]);
  }
  else
    B_local_ = B0_;
  if (far_ && settings_.torque != TorqueModel::paper)
    for (std::size_t k = 0; k < 3 * n; ++k)
      B_local_[k] += B_far_[k];
}

void InducedDipoles::sweep_to_tolerance(const BeadArrays &beads, MagneticStats &stats,
                                        const std::vector<std::uint32_t> *subset)
{
  const auto local_field = [this](std::size_t b, const std::vector<double> &p, double B[3]) {
    gather_local_field(b, p, B);
  };
  const auto follow_tail = [this] {
    if (tail_)
      tail_->evaluate(p_);
  };
  const JacobiResult result =
    solver_.solve(beads, beta_, Ms_, p_, p_next_, B_local_, local_field, follow_tail, subset);
  stats.sweeps += result.sweeps;
  stats.residual = result.residual;
  stats.converged = result.converged;
  stats.relaxation = result.relaxation;
  follow_tail(); // the tail force uses the final dipoles
}

void InducedDipoles::gather_local_field(std::size_t b, const std::vector<double> &p, double B[3]) const
{
  B[0] = B0_[3 * b];
  B[1] = B0_[3 * b + 1];
  B[2] = B0_[3 * b + 2];
  if (tail_)
  {
    const double *Bt = tail_->field(b);
    for (int d = 0; d < 3; ++d)
      B[d] += Bt[d];
  }
  if (far_)
  {
    double s[3] = {B_far_[3 * b], B_far_[3 * b + 1], B_far_[3 * b + 2]};
    if (near_.has_rows())
      near_.add_row_field(b, p, s);
    else // (beads admitted since the rows were built)
      near_.add_row_field_through_list(b, p, s);
    B[0] += s[0];
    B[1] += s[1];
    B[2] += s[2];
    return;
  }
  near_.add_list_field(b, p, B);
}

void InducedDipoles::evaluate_forces(const BeadArrays &beads, MagneticStats &stats)
{
  const InducedState state{beads, beta_, B_local_, p_};
  stats.corrected_pairs = pair_forces_.evaluate_all(state, near_, near_pair_correction());
  if (far_corrections())
    stats.corrected_pairs = correction_.evaluate_list_forces(state);
}

const TwoSphereCorrection *InducedDipoles::near_pair_correction() const
{
  return settings_.model == DipoleModel::corrected && !far_ ? &correction_ : nullptr;
}

bool InducedDipoles::far_corrections() const
{
  return far_ && settings_.model == DipoleModel::corrected;
}

void InducedDipoles::gather_forces(const ForceArrays &out)
{
  const std::size_t n = beta_.size();
  force_.resize(3 * n);
  torque_.resize(3 * n);
#pragma omp parallel for schedule(static) if (n >= bead_parallel_threshold)
  for (long b = 0; b < static_cast<long>(n); ++b)
    gather_bead(b);
  add_held_forces(out);
}

void InducedDipoles::gather_bead(std::size_t b)
{
  const double *p = &p_[3 * b];
  const double *g = &gradB0_[9 * b];
  // (p·∇)B_applied: F_a = Σ_c p_c ∂B_a/∂x_c.
  double F[3];
  for (int a = 0; a < 3; ++a)
    F[a] = p[0] * g[3 * a] + p[1] * g[3 * a + 1] + p[2] * g[3 * a + 2];
  // Slab tail: the sheets vary only along the open axis, F = n̂ (p·∂B_tail/∂u).
  if (tail_)
  {
    const double *dB = tail_->normal_derivative(b);
    F[tail_->normal_axis()] += p[0] * dB[0] + p[1] * dB[1] + p[2] * dB[2];
  }
  // Far field: (p·∇)B_far.
  if (far_)
  {
    const double *gf = &gradB_far_[9 * b];
    for (int a = 0; a < 3; ++a)
      F[a] += p[0] * gf[3 * a] + p[1] * gf[3 * a + 1] + p[2] * gf[3 * a + 2];
  }
  pair_forces_.add_incident(near_, b, F);
  if (far_corrections())
    correction_.add_incident_forces(b, F);
  double *T = &torque_[3 * b];
  if (settings_.torque == TorqueModel::paper)
  {
    const double *B = &B_local_[3 * b];
    T[0] = p[1] * B[2] - p[2] * B[1];
    T[1] = p[2] * B[0] - p[0] * B[2];
    T[2] = p[0] * B[1] - p[1] * B[0];
  }
  else
    T[0] = T[1] = T[2] = 0.0;
  for (int a = 0; a < 3; ++a)
    force_[3 * b + a] = F[a];
}

void InducedDipoles::remember_evaluation(const BeadArrays &beads, double time)
{
  staleness_.evaluated_all(beads, time);
  if (settings_.staleness_mode == StalenessMode::relative)
    staleness_.watch_close_pairs(beads, near_, skin_);
  computed_ = true;
}

// ---------------------------------------------------------------------------------------
// Held forces, staleness, re-sorting, ramps.

void InducedDipoles::add_held_forces(const ForceArrays &out) const
{
  const std::size_t n = force_.size() / 3;
  const bool torques = settings_.torque == TorqueModel::paper && out.tx && out.ty && out.tz;
#pragma omp parallel for schedule(static) if (n >= bead_parallel_threshold)
  for (long b = 0; b < static_cast<long>(n); ++b)
  {
    out.fx[b] += force_[3 * b];
    out.fy[b] += force_[3 * b + 1];
    out.fz[b] += force_[3 * b + 2];
    if (torques)
    {
      out.tx[b] += torque_[3 * b];
      out.ty[b] += torque_[3 * b + 1];
      out.tz[b] += torque_[3 * b + 2];
    }
  }
}

bool InducedDipoles::needs_refresh(const BeadArrays &beads, double time) const
{
  return check_staleness(beads, time).reason != RefreshReason::none;
}

StalenessCheck InducedDipoles::check_staleness(const BeadArrays &beads, double time) const
{
  if (!computed_)
  {
    StalenessCheck c;
    c.reason = RefreshReason::first;
    return c;
  }
  const MagneticNeighbourList &list = near_.list();
  return staleness_.check(beads, time, list.built() && list.particle_count() == beads.n);
}

bool InducedDipoles::live_pairs_held(const BeadArrays &beads) const
{
  return settings_.hold_dipoles && live_.size() > 0 && p_.size() == 3 * beads.n && B_local_.size() == 3 * beads.n;
}

const std::vector<double> *InducedDipoles::live_pair_changes(const BeadArrays &beads)
{
  if (!live_pairs_held(beads))
    return nullptr;
  return &live_.update({beads, beta_, B_local_, p_}, live_correction());
}

const std::vector<double> *InducedDipoles::live_pair_changes_in_team(const BeadArrays &beads)
{
  if (!live_pairs_held(beads))
    return nullptr;
  return &live_.update_in_team({beads, beta_, B_local_, p_}, live_correction());
}

void InducedDipoles::add_live_pair_changes(const BeadArrays &beads, const ForceArrays &out)
{
  const std::vector<double> *change = live_pair_changes(beads);
  if (!change)
    return;
  for (std::size_t b = 0; b < beads.n; ++b)
  {
    out.fx[b] += (*change)[3 * b];
    out.fy[b] += (*change)[3 * b + 1];
    out.fz[b] += (*change)[3 * b + 2];
  }
}

const TwoSphereCorrection *InducedDipoles::live_correction() const
{
  return settings_.model == DipoleModel::corrected && correction_.has_tables() ? &correction_ : nullptr;
}

void InducedDipoles::particles_reordered(const std::vector<std::int32_t> &order)
{
  auto permute = [&](std::vector<double> &v) {
    if (v.size() != 3 * order.size())
      return;
    std::vector<double> old(v);
    for (std::size_t k = 0; k < order.size(); ++k)
      for (int d = 0; d < 3; ++d)
        v[3 * k + d] = old[3 * static_cast<std::size_t>(order[k]) + d];
  };
  permute(p_);
  permute(force_);
  permute(torque_);
  staleness_.particles_reordered(order);
  near_.forget(); // pair indices refer to the old order
  correction_.forget_list();
  live_.clear();
}

void InducedDipoles::particles_changed(const std::vector<std::int32_t> &origin)
{
  const std::size_t old_n = p_.size() / 3;
  fresh_.clear();
  if (old_n == 0) // nothing kept: the next compute() starts cold anyway
    return;
  const std::vector<double> old(p_);
  p_.assign(3 * origin.size(), 0.0);
  for (std::size_t k = 0; k < origin.size(); ++k)
  {
    const std::int32_t o = origin[k];
    if (o >= 0 && static_cast<std::size_t>(o) < old_n)
      for (int d = 0; d < 3; ++d)
        p_[3 * k + d] = old[3 * static_cast<std::size_t>(o) + d];
    else
      fresh_.push_back(static_cast<std::uint32_t>(k));
  }
  force_.clear();
  torque_.clear();
  computed_ = false;
  near_.forget(); // pair indices refer to the old set
  correction_.forget_list();
  live_.clear();
}

bool InducedDipoles::linear() const
{
  return std::all_of(Ms_.begin(), Ms_.end(), [](double m) { return m == 0.0; });
}

void InducedDipoles::scale_applied_field(double ratio)
{
  if (!linear())
    throw std::logic_error("magnetics: scale_applied_field() needs linear beads (p ∝ B); these "
                           "saturate. Refresh instead.");
  // Every stored field and dipole is linear in the applied field, every force quadratic.
  for (auto *v : {&B0_, &gradB0_, &p_, &B_local_, &B_far_, &gradB_far_})
    for (double &x : *v)
      x *= ratio;
  if (tail_)
    tail_->scale(ratio);
  if (far_)
    far_->scale_fine_locals(ratio);
  const double ratio2 = ratio * ratio;
  for (auto *v : {&force_, &torque_})
    for (double &x : *v)
      x *= ratio2;
  pair_forces_.scale(ratio2);
  correction_.scale_forces(ratio2);
  live_.scale(ratio2);
}

// ---------------------------------------------------------------------------------------
// The local refresh.

bool InducedDipoles::refresh_locally(const BeadArrays &beads, const AppliedFieldFunction &field,
                                     double time, MagneticStats &stats)
{
  (void)time; // the refresh interval counts from the last full compute()
  stats = MagneticStats();
  local_fallback_ = LocalFallback::none;
  const double t_start = omp_get_wtime();
  if (!can_refresh_locally(beads))
  {
    local_fallback_ = LocalFallback::lists;
    return false;
  }
  if (!local_.select_moved(beads, staleness_, settings_))
    return true;
  local_.grow_region(beads, near_, settings_.local_region_radius);
  if (local_.region_too_large(beads.n, settings_.local_region_limit))
  {
    local_fallback_ = LocalFallback::region;
    return false;
  }
  reevaluate_moved_beads(beads, field);
  stats.time_tensors = omp_get_wtime() - t_start;
  solve_region_and_refresh_forces(beads, stats);
  return true;
}

bool InducedDipoles::can_refresh_locally(const BeadArrays &beads) const
{
  // The neighbour lists must still hold every pair the full evaluation would use (no bead
  // moved half the skin, none was wrapped); the slab tail sorts all beads: no local version.
  const std::size_t n = beads.n;
  const MagneticNeighbourList &list = near_.list();
  if (!computed_ || zero_field_ || staleness_.reference_count() != n || p_.size() != 3 * n ||
      force_.size() != 3 * n || tail_ || !list.built() || list.particle_count() != n)
    return false;
  if (list.max_displacement(n, beads.x, beads.y, beads.z) > 0.5 * skin_)
    return false;
  return !far_corrections() || correction_.list_current(beads, skin_);
}

void InducedDipoles::reevaluate_moved_beads(const BeadArrays &beads, const AppliedFieldFunction &field)
{
  for (const std::uint32_t b : local_.moved())
  {
    evaluate_applied_field_at(beads, field, b);
    staleness_.evaluated(beads, b);
  }
  for (const std::uint32_t k : local_.select_moved_pairs(near_))
  {
    near_.evaluate_tensor(beads, k);
    staleness_.pair_reevaluated(near_, k);
    near_.update_rows(k); // the per-bead copies the sweeps read
  }
}

void InducedDipoles::reevaluate_local_forces(const BeadArrays &beads, MagneticStats &stats)
{
  local_.select_force_pairs(near_, far_corrections() ? &correction_.list() : nullptr);
  const InducedState state{beads, beta_, B_local_, p_};
  for (const std::uint32_t k : local_.force_pairs())
    stats.corrected_pairs += pair_forces_.evaluate(state, near_, near_pair_correction(), k);
  stats.local_pairs = local_.force_pairs().size();
  for (const std::uint32_t k : local_.correction_pairs())
    stats.corrected_pairs += correction_.evaluate_list_force(state, k);
  for (const std::uint32_t b : local_.gathered())
    gather_bead(b);
}

// ---------------------------------------------------------------------------------------
// Admission of an exchange without a rebuild.

bool InducedDipoles::admit(const BeadArrays &beads, std::size_t first, const std::vector<std::uint32_t> &leavers,
                           const AppliedFieldFunction &field, MagneticStats &stats)
{
  stats = MagneticStats();
  const double t_start = omp_get_wtime();
  if (!can_admit(beads, first) || !far_->add_beads(beads.n, beads.x, beads.y, beads.z))
    return false;
  // From here on nothing can fail. The newcomers' near pairs join the list (the older beads
  // keep their pairs, tensors and stored forces), then the correction's list.
  MagneticNeighbourList &list = near_.list();
  const std::size_t old_pairs = list.size();
  if (beads.n > first) // (only leavers: the lists stay as they are)
  {
    admitted_pairs_.clear();
    far_->appended_near_pairs(first, admitted_pairs_);
    list.append(beads.n, beads.x, beads.y, beads.z, admitted_pairs_);
    near_.appended(beads, old_pairs);
    pair_forces_.resize(list.size());
    if (settings_.hold_dipoles)
      live_.append(beads, near_, old_pairs, settings_.live_pair_radius);
    if (far_corrections())
      correction_.admit(beads, first);
  }
  append_bead_state(beads, first, leavers, field);
  staleness_.admit(beads, first, near_, old_pairs, skin_, leavers);
  stats.time_lists = omp_get_wtime() - t_start;
  solve_around(beads, first, leavers, field, stats);
  stats.listed_pairs = list.size();
  return true;
}

bool InducedDipoles::can_admit(const BeadArrays &beads, std::size_t first) const
{
  if (!far_ || settings_.model == DipoleModel::point_dipole || beads.n < first)
    return false;
  // The held state must be that of the first `first` beads and current, as for a local refresh.
  const BeadArrays held{first, beads.x, beads.y, beads.z, beads.radius, beads.mu_r, beads.saturation_magnetisation};
  if (!can_refresh_locally(held))
    return false;
  if (!far_corrections() || beads.n == first)
    return true;
  if (!correction_.can_admit(beads, first))
    return false;
  // A newcomer's β must be one the correction has tables for (those of the held beads).
  for (std::size_t b = first; b < beads.n; ++b)
    if (std::find(beta_.begin(), beta_.end(), clausius_mossotti(beads.mu_r[b])) == beta_.end())
      return false;
  return true;
}

// The per-bead state of the newcomers: materials, applied field, the held far field (their
// fine cell's local expansion of the last full evaluation, as every bead of that cell holds
// it), the applied-field-plus-far-field dipole as the sweeps' start; the leavers' dipoles
// vanish (β = 0 from now on).
void InducedDipoles::append_bead_state(const BeadArrays &beads, std::size_t first,
                                       const std::vector<std::uint32_t> &leavers, const AppliedFieldFunction &field)
{
  const std::size_t n = beads.n;
  set_materials(beads);
  for (auto *v : {&B0_, &B_far_, &p_, &p_next_, &B_local_, &force_, &torque_})
    v->resize(3 * n, 0.0);
  for (auto *v : {&gradB0_, &gradB_far_})
    v->resize(9 * n, 0.0);
  for (std::size_t b = first; b < n; ++b)
  {
    evaluate_applied_field_at(beads, field, b);
    far_->far_field_at(b, &B_far_[3 * b], &gradB_far_[9 * b]);
    double B[3];
    for (int a = 0; a < 3; ++a)
      B[a] = B0_[3 * b + a] + B_far_[3 * b + a];
    induced_moment(beads.radius[b], beta_[b], Ms_[b], B, &p_[3 * b]);
    for (int a = 0; a < 3; ++a)
      B_local_[3 * b + a] = B[a];
  }
  for (const std::uint32_t b : leavers)
    for (int a = 0; a < 3; ++a)
      p_[3 * b + a] = 0.0;
}

// The local refresh of an admission: the leavers and the newcomers count as moved (their
// pairs' tensors, the region's dipoles, the forces of every pair touching a changed dipole).
void InducedDipoles::solve_around(const BeadArrays &beads, std::size_t first, const std::vector<std::uint32_t> &leavers,
                                  const AppliedFieldFunction &field, MagneticStats &stats)
{
  admitted_moved_.assign(leavers.begin(), leavers.end());
  for (std::size_t b = first; b < beads.n; ++b)
    admitted_moved_.push_back(static_cast<std::uint32_t>(b));
  local_.select_given(admitted_moved_, beads.n);
  local_.grow_region(beads, near_, settings_.local_region_radius);
  const double t_tensors = omp_get_wtime();
  reevaluate_moved_beads(beads, field);
  stats.time_tensors = omp_get_wtime() - t_tensors;
  solve_region_and_refresh_forces(beads, stats);
}

// What every local refresh ends with, once the moved beads' tensors are new: the region's
// dipoles by sweeps to the tolerance with everything else held, then the force of every pair
// touching a dipole that changed, and the counts.
void InducedDipoles::solve_region_and_refresh_forces(const BeadArrays &beads, MagneticStats &stats)
{
  const double t_sweeps = omp_get_wtime();
  local_.hold_region_dipoles(p_);
  sweep_to_tolerance(beads, stats, &local_.region());
  stats.time_sweeps = omp_get_wtime() - t_sweeps;
  local_.select_changed(p_, settings_.local_dipole_change);
  const double t_forces = omp_get_wtime();
  reevaluate_local_forces(beads, stats);
  if (settings_.hold_dipoles) // the renewed pairs' forces are the live pairs' new base
    live_.rebase({beads, beta_, B_local_, p_}, live_correction(), local_.force_pairs());
  stats.time_forces = omp_get_wtime() - t_forces;
  stats.local_moved = local_.moved().size();
  stats.local_region = local_.region().size();
  stats.local_gathered = local_.gathered().size();
  stats.pairs = local_.moved_pairs().size();
}

bool InducedDipoles::lists_current(const BeadArrays &beads) const
{
  const MagneticNeighbourList &list = near_.list();
  if (!list.built() || list.particle_count() != beads.n ||
      list.max_displacement(beads.n, beads.x, beads.y, beads.z) > 0.5 * skin_)
    return false;
  return !far_corrections() || correction_.list_current(beads, skin_);
}

// ---------------------------------------------------------------------------------------
// Restart.

namespace {
// Every setting, printed exactly: held state is restored only under the same settings.
std::string settings_fingerprint(const MagneticSettings &s)
{
  std::string f;
  auto add = [&f](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g ", v);
    f += buf;
  };
  for (double v : {static_cast<double>(s.model), static_cast<double>(s.torque), s.cutoff_diameters,
                   s.cutoff_length, s.skin_fraction, s.tolerance, static_cast<double>(s.max_sweeps),
                   s.refresh_interval, s.staleness_fraction, static_cast<double>(s.staleness_mode),
                   s.local_region_limit, s.local_region_radius, s.local_batch_fraction, s.local_dipole_change,
                   s.relative_check_radius, s.absolute_factor, s.switch_begin, s.switch_end,
                   static_cast<double>(s.slab_tail_correction), static_cast<double>(s.far_field),
                   s.far_cell_diameters, static_cast<double>(s.far_order), static_cast<double>(s.far_near_reach),
                   static_cast<double>(s.far_passes), static_cast<double>(s.far_single_precision),
                   static_cast<double>(s.defer_exchange), static_cast<double>(s.admit_exchange)})
    add(v);
  if (s.hold_dipoles) // (only when on: checkpoints written before the setting still restore)
    f += "hold_dipoles " + std::to_string(s.live_pair_radius) + " " + std::to_string(s.live_pair_steps) + " ";
  return f;
}
} // namespace

void InducedDipoles::write_state(StateOut &out) const
{
  out.put_string(settings_fingerprint(settings_));
  out.put(box_);
  out.put<std::uint8_t>(computed_);
  out.put<std::uint8_t>(zero_field_);
  out.put(skin_);
  out.put(far_cell_size_);
  for (const auto *v : {&beta_, &Ms_, &B0_, &gradB0_, &p_, &p_next_, &B_local_, &B_far_, &gradB_far_, &force_, &torque_})
    out.put_array(*v);
  near_.write_state(out);
  pair_forces_.write_state(out);
  correction_.write_state(out);
  out.put<std::uint8_t>(correction_.has_tables());
  staleness_.write_state(out);
  if (tail_)
    tail_->write_state(out);
  // The fine cells' local expansions (admit(): a newcomer's held far field).
  static const std::vector<double> none;
  out.put_array(far_ && far_->levels() > 0 ? far_->fine_locals() : none);
  if (settings_.hold_dipoles)
    live_.write_state(out);
}

bool InducedDipoles::read_state(StateIn &in)
{
  if (in.get_string() != settings_fingerprint(settings_) || in.get<std::array<double, 3>>() != box_)
    return false;
  computed_ = in.get<std::uint8_t>() != 0;
  zero_field_ = in.get<std::uint8_t>() != 0;
  skin_ = in.get<double>();
  far_cell_size_ = in.get<double>();
  for (auto *v : {&beta_, &Ms_, &B0_, &gradB0_, &p_, &p_next_, &B_local_, &B_far_, &gradB_far_, &force_, &torque_})
    in.get_array(*v);
  near_.read_state(in);
  pair_forces_.read_state(in);
  correction_.read_state(in);
  if (in.get<std::uint8_t>() != 0)
    correction_.prepare_tables(beta_);
  staleness_.read_state(in);
  if (tail_)
    tail_->read_state(in);
  // The far field's cells: built from the positions the near list was built from, they are
  // the cells of the run that wrote the state (a build depends on those positions and the
  // cell size only; the next evaluation moves the beads within them or rebuilds).
  const MagneticNeighbourList &list = near_.list();
  if (far_ && list.built() && list.particle_count() > 0 && far_cell_size_ > 0.0)
  {
    const std::vector<double> &xr = list.reference_positions();
    const std::size_t n = list.particle_count();
    std::vector<double> x(n), y(n), z(n);
    for (std::size_t b = 0; b < n; ++b)
    {
      x[b] = xr[3 * b];
      y[b] = xr[3 * b + 1];
      z[b] = xr[3 * b + 2];
    }
    far_->build(n, x.data(), y.data(), z.data(), far_cell_size_);
  }
  std::vector<double> locals;
  in.get_array(locals);
  if (far_ && !locals.empty())
    far_->set_fine_locals(locals);
  if (settings_.hold_dipoles)
    live_.read_state(in, p_.size() / 3, near_);
  return true;
}

} // namespace magbrush::magnetics
