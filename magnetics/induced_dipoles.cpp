#include "induced_dipoles.h"

#include "dipole_physics.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace magbrush::magnetics {

namespace {

// Adds to F the stored forces of the pairs incident to bead b. A pair's force is stored as the
// force on its j bead; its i bead gets the negative (Newton's third law, exact). The list's
// fixed incidence order makes the sum the same on any number of threads.
void add_incident_pair_forces(const MagneticNeighbourList &list, const std::vector<double> &pair_force,
                              std::size_t b, double F[3])
{
  const auto &begin = list.incident_begin();
  const auto &pair_of = list.incident_pair();
  const auto &first = list.incident_first();
  for (std::size_t q = begin[b]; q < begin[b + 1]; ++q)
  {
    const double *Fp = &pair_force[3 * pair_of[q]];
    const double sign = first[q] ? -1.0 : 1.0;
    for (int a = 0; a < 3; ++a)
      F[a] += sign * Fp[a];
  }
}

// Appends bead b to `list` the first time it is flagged with `bit` (a set kept as a list in
// first-seen order, with the flags as the membership test).
void add_once(std::vector<std::uint8_t> &mark, std::uint8_t bit, std::vector<std::uint32_t> &list, std::uint32_t b)
{
  if (!(mark[b] & bit))
  {
    mark[b] |= bit;
    list.push_back(b);
  }
}
// Below this many beads (or pairs) a loop runs on one thread: forking a team costs more than
// it saves, and far more on an oversubscribed machine. The results do not depend on it.
constexpr std::size_t parallel_threshold = 512;
} // namespace

AppliedFieldFunction uniform_field(double Bx, double By, double Bz)
{
  return [Bx, By, Bz](const double *, double B[3], double gradB[3][3]) {
    B[0] = Bx;
    B[1] = By;
    B[2] = Bz;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        gradB[a][b] = 0.0;
  };
}

InducedDipoles::InducedDipoles(const MagneticSettings &settings, const std::array<double, 3> &box)
  : settings_(settings), box_(box)
{
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
  {
    int open = 0;
    for (int d = 0; d < 3; ++d)
      if (box_[d] == 0.0)
      {
        normal_axis_ = d;
        ++open;
      }
    if (open != 1)
      throw std::invalid_argument(
        "magnetics: the slab tail correction needs a slab periodic along exactly two axes and "
        "open along the third; found " + std::to_string(3 - open) +
        " periodic axes. Switch slab_tail_correction off for this box.");
  }
}

double InducedDipoles::cutoff_length(const BeadArrays &beads) const
{
  if (settings_.cutoff_length > 0.0)
    return settings_.cutoff_length;
  double sum = 0.0;
  for (std::size_t b = 0; b < beads.n; ++b)
    sum += beads.radius[b];
  const double mean_diameter = beads.n ? 2.0 * sum / beads.n : 0.0;
  return settings_.cutoff_diameters * mean_diameter;
}

MagneticStats InducedDipoles::compute(const BeadArrays &beads, const AppliedFieldFunction &field,
                                      double time, const ForceArrays &out)
{
  MagneticStats stats;
  const std::size_t n = beads.n;
  if (n == 0)
    return stats;
  if (!beads.x || !beads.y || !beads.z || !beads.radius || !beads.mu_r)
    throw std::invalid_argument("magnetics: bead arrays x, y, z, radius and mu_r are required.");

  beta_.resize(n);
  Ms_.resize(n);
  for (std::size_t b = 0; b < n; ++b)
  {
    beta_[b] = clausius_mossotti(beads.mu_r[b]);
    Ms_[b] = beads.saturation_magnetisation ? beads.saturation_magnetisation[b] : 0.0;
  }

  double clock = omp_get_wtime();
  auto lap = [&clock](double &phase) {
    const double now = omp_get_wtime();
    phase += now - clock;
    clock = now;
  };
  // No applied field anywhere (before a field ramp starts, or a schedule at 0 mT): the
  // induced dipoles are all zero, and so are the forces: nothing to solve. The next compute
  // starts cold (from the applied-field dipoles).
  evaluate_applied_field(beads, field);
  zero_field_ = std::all_of(B0_.begin(), B0_.end(), [](double v) { return v == 0.0; });
  if (zero_field_)
  {
    p_.clear();
    force_.assign(3 * n, 0.0);
    torque_.assign(3 * n, 0.0);
    store_limits(beads);
    for (std::size_t b = 0; b < n; ++b)
      store_reference_position(beads, b);
    t_last_ = time;
    computed_ = true;
    stats.zero_field = true;
    lap(stats.time_tensors);
    return stats;
  }
  lap(stats.time_tensors);
  double cutoff;
  {
    double sum = 0.0;
    for (std::size_t b = 0; b < n; ++b)
      sum += beads.radius[b];
    skin_ = settings_.skin_fraction * 2.0 * sum / n;
  }
  if (far_)
  {
    // No cutoff: the near pairs are those of neighbouring fine cells. Like a Verlet list,
    // the cells and the near pairs are kept until some bead moved more than half the skin
    // (a bead wrapped by the caller counts as a large move); in between, the beads keep the
    // cells they were sorted into and only their positions are updated.
    double sum = 0.0;
    for (std::size_t b = 0; b < n; ++b)
      sum += beads.radius[b];
    const double mean_diameter = 2.0 * sum / n;
    const double skin = settings_.skin_fraction * mean_diameter;
    if (!list_.built() || list_.particle_count() != n ||
        list_.max_displacement(n, beads.x, beads.y, beads.z) > 0.5 * skin)
    {
      far_->build(n, beads.x, beads.y, beads.z, settings_.far_cell_diameters * mean_diameter);
      list_.set_pairs(n, beads.x, beads.y, beads.z, box_, 0.0,
                      std::vector<MagneticNeighbourList::Pair>(far_->near_pairs()));
      stats.list_rebuilt = true;
    }
    else
      far_->update_positions(beads.x, beads.y, beads.z);
    stats.listed_pairs = list_.size();
    stats.far_cells = far_->fine_cells();
    stats.far_interactions = far_->interactions();
    if (settings_.model == DipoleModel::corrected)
      refresh_correction_list(beads);
    cutoff = std::numeric_limits<double>::infinity();
    stats.cutoff = 0.0;
  }
  else
  {
    cutoff = cutoff_length(beads);
    stats.cutoff = cutoff;
    refresh_list_if_needed(beads, cutoff, stats);
  }
  lap(stats.time_lists);
  evaluate_pair_tensors(beads, cutoff, stats);
  if (far_)
    build_near_entries();
  if (settings_.slab_tail_correction)
    prepare_tail(beads, cutoff);
  lap(stats.time_tensors);
  solve_dipoles(beads, stats);
  // Tables depend on the beads' β only: re-check when the list (hence the bead set) changed.
  if (settings_.model == DipoleModel::corrected && (stats.list_rebuilt || tables_.empty()))
    prepare_correction_tables();
  clock = omp_get_wtime();
  evaluate_pair_forces(beads, stats);
  if (far_ && settings_.model == DipoleModel::corrected)
    evaluate_correction_forces(beads, stats);
  gather_forces(out);
  lap(stats.time_forces);

  store_limits(beads);
  for (std::size_t b = 0; b < n; ++b)
    store_reference_position(beads, b);
  if (settings_.staleness_mode == StalenessMode::relative)
    select_close_pairs(beads);
  t_last_ = time;
  computed_ = true;
  return stats;
}

void InducedDipoles::select_close_pairs(const BeadArrays &beads)
{
  // The pairs that can come within relative_check_radius mean radii before the list expires.
  const auto &pairs = list_.pairs();
  close_.clear();
  close_of_pair_.assign(pairs.size(), -1);
  min_radius_ = *std::min_element(beads.radius, beads.radius + beads.n);
  max_radius_ = *std::max_element(beads.radius, beads.radius + beads.n);
  const double f = settings_.staleness_fraction;
  for (std::size_t k = 0; k < pairs.size(); ++k)
  {
    if (!active_[k])
      continue;
    const double a = 0.5 * (beads.radius[pairs[k].i] + beads.radius[pairs[k].j]);
    const double reach = settings_.relative_check_radius * a + skin_;
    const double *r = &r_[3 * k];
    if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] >= reach * reach)
      continue;
    close_of_pair_[k] = static_cast<std::int32_t>(close_.size());
    close_.push_back({pairs[k].i, pairs[k].j, {0, 0, 0}, f * f * a * a});
    update_close_pair(k);
  }
}

void InducedDipoles::update_close_pair(std::size_t k)
{
  if (close_of_pair_.size() != list_.pairs().size() || close_of_pair_[k] < 0)
    return;
  ClosePair &c = close_[static_cast<std::size_t>(close_of_pair_[k])];
  for (int d = 0; d < 3; ++d)
    c.c[d] = list_.pairs()[k].shift[d] - r_[3 * k + d];
}

double InducedDipoles::move_limit(const BeadArrays &beads, std::size_t b) const
{
  const double factor = settings_.staleness_mode == StalenessMode::relative ? settings_.absolute_factor : 1.0;
  return factor * settings_.staleness_fraction * beads.radius[b];
}

void InducedDipoles::store_limits(const BeadArrays &beads)
{
  limit2_.resize(beads.n);
  inv_radius2_.resize(beads.n);
  for (std::size_t b = 0; b < beads.n; ++b)
  {
    const double limit = move_limit(beads, b);
    limit2_[b] = limit * limit;
    inv_radius2_[b] = 1.0 / (beads.radius[b] * beads.radius[b]);
  }
}

void InducedDipoles::store_reference_position(const BeadArrays &beads, std::size_t b)
{
  x_last_.resize(3 * beads.n);
  x_last_[3 * b] = beads.x[b];
  x_last_[3 * b + 1] = beads.y[b];
  x_last_[3 * b + 2] = beads.z[b];
}

void InducedDipoles::refresh_list_if_needed(const BeadArrays &beads, double cutoff,
                                            MagneticStats &stats)
{
  double sum = 0.0;
  for (std::size_t b = 0; b < beads.n; ++b)
    sum += beads.radius[b];
  const double skin = settings_.skin_fraction * 2.0 * sum / beads.n; // fraction of the mean diameter
  const bool stale = !list_.built() || list_.particle_count() != beads.n || list_.box() != box_ ||
                     std::abs(list_.list_radius() - (cutoff + skin)) > 1e-12 * cutoff ||
                     list_.max_displacement(beads.n, beads.x, beads.y, beads.z) > 0.5 * skin;
  if (stale)
  {
    list_.build(beads.n, beads.x, beads.y, beads.z, box_, cutoff + skin);
    stats.list_rebuilt = true;
  }
  stats.listed_pairs = list_.size();
}

void InducedDipoles::evaluate_applied_field(const BeadArrays &beads,
                                            const AppliedFieldFunction &field)
{
  const std::size_t n = beads.n;
  B0_.resize(3 * n);
  gradB0_.resize(9 * n);
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
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

void InducedDipoles::evaluate_pair_tensors(const BeadArrays &beads, double cutoff,
                                           MagneticStats &stats)
{
  const std::size_t np = list_.pairs().size();
  tensor_.resize(np);
  r_.resize(3 * np);
  active_.resize(np);
  cutoff_ = cutoff;
  std::size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count) if (np >= parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
  {
    evaluate_pair_tensor(beads, k);
    count += active_[k];
  }
  stats.pairs = count;
}

void InducedDipoles::evaluate_pair_tensor(const BeadArrays &beads, std::size_t k)
{
  const auto &p = list_.pairs()[k];
  double r[3] = {beads.x[p.j] - beads.x[p.i] + p.shift[0],
                 beads.y[p.j] - beads.y[p.i] + p.shift[1],
                 beads.z[p.j] - beads.z[p.i] + p.shift[2]};
  const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  for (int d = 0; d < 3; ++d)
    r_[3 * k + d] = r[d];
  // Hard cutoff (as Kawamoto): pairs beyond it do not interact at all. Coincident
  // centres (r = 0) cannot occur between non-overlapping beads; they are skipped.
  active_[k] = (r2 < cutoff_ * cutoff_ && r2 > 0.0);
  if (active_[k])
    tensor_[k] = DipoleTensor::at(r);
  else
    tensor_[k] = {0, 0, 0, 0, 0, 0};
}

void InducedDipoles::build_near_entries()
{
  const auto &begin = list_.incident_begin();
  const auto &pair_of = list_.incident_pair();
  const auto &first = list_.incident_first();
  const auto &pairs = list_.pairs();
  const std::size_t n = begin.size() - 1;
  near_begin_.assign(begin.begin(), begin.end());
  near_other_.resize(begin[n]);
  near_tensor_.resize(6 * begin[n]);
  // Where each pair sits in the two beads' rows (a self-image pair twice in one row).
  pair_entry_.resize(2 * pairs.size());
  for (std::size_t b = 0; b < n; ++b)
    for (std::size_t q = begin[b]; q < begin[b + 1]; ++q)
      pair_entry_[2 * pair_of[q] + (first[q] ? 0 : 1)] = q;
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
  for (long b = 0; b < static_cast<long>(n); ++b)
    for (std::size_t q = begin[b]; q < begin[b + 1]; ++q)
    {
      const std::uint32_t k = pair_of[q];
      near_other_[q] = first[q] ? pairs[k].j : pairs[k].i;
      const DipoleTensor &T = tensor_[k]; // zero for an inactive (coincident) pair
      double *t = &near_tensor_[6 * q];
      t[0] = T.xx;
      t[1] = T.yy;
      t[2] = T.zz;
      t[3] = T.xy;
      t[4] = T.xz;
      t[5] = T.yz;
    }
}

void InducedDipoles::gather_local_field(std::size_t b, const std::vector<double> &p,
                                        double B[3]) const
{
  B[0] = B0_[3 * b];
  B[1] = B0_[3 * b + 1];
  B[2] = B0_[3 * b + 2];
  if (normal_axis_ >= 0)
    for (int d = 0; d < 3; ++d)
      B[d] += tail_B_[3 * b + d];
  if (far_)
  {
    double sx = B_far_[3 * b], sy = B_far_[3 * b + 1], sz = B_far_[3 * b + 2];
    const std::size_t q0 = near_begin_[b], q1 = near_begin_[b + 1];
    const std::uint32_t *other = near_other_.data();
    const double *t = near_tensor_.data();
    for (std::size_t q = q0; q < q1; ++q)
    {
      const double *pk = &p[3 * other[q]];
      const double *T = &t[6 * q];
      sx += T[0] * pk[0] + T[3] * pk[1] + T[4] * pk[2];
      sy += T[3] * pk[0] + T[1] * pk[1] + T[5] * pk[2];
      sz += T[4] * pk[0] + T[5] * pk[1] + T[2] * pk[2];
    }
    B[0] += sx;
    B[1] += sy;
    B[2] += sz;
    return;
  }
  const auto &begin = list_.incident_begin();
  const auto &pair_of = list_.incident_pair();
  const auto &first = list_.incident_first();
  const auto &pairs = list_.pairs();
  for (std::size_t q = begin[b]; q < begin[b + 1]; ++q)
  {
    const std::uint32_t k = pair_of[q];
    if (!active_[k])
      continue;
    const std::uint32_t other = first[q] ? pairs[k].j : pairs[k].i;
    tensor_[k].add_field(&p[3 * other], B);
  }
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
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
    for (long b = 0; b < static_cast<long>(n); ++b)
      induced_moment(beads.radius[b], beta_[b], Ms_[b], &B0_[3 * b], &p_[3 * b]);
  }

  auto far_pass = [&] {
    const double t0 = omp_get_wtime();
    B_far_.resize(3 * n);
    gradB_far_.resize(9 * n);
    far_->evaluate(p_.data(), B_far_.data(), gradB_far_.data());
    ++stats.far_passes;
    stats.time_far += omp_get_wtime() - t0;
  };
  if (settings_.model == DipoleModel::point_dipole)
  {
    // Dipoles from the applied field only; the local field is needed only for the papers'
    // torque diagnostic (and the far field for the forces).
    if (far_)
      far_pass();
    if (normal_axis_ >= 0)
      evaluate_tail(p_);
    if (settings_.torque == TorqueModel::paper)
    {
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
      for (long b = 0; b < static_cast<long>(n); ++b)
        gather_local_field(b, p_, &B_local_[3 * b]);
    }
    else
      B_local_ = B0_;
    if (far_ && settings_.torque != TorqueModel::paper)
      for (std::size_t k = 0; k < 3 * n; ++k)
        B_local_[k] += B_far_[k];
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
    const int passes = settings_.far_passes + (warm_start ? 0 : 1);
    for (int pass = 0; pass < passes; ++pass)
    {
      far_pass();
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

void InducedDipoles::sweep_to_tolerance(const BeadArrays &beads, MagneticStats &stats,
                                        const std::vector<std::uint32_t> *subset)
{
  const std::size_t n = subset ? subset->size() : beads.n;
  // Jacobi sweeps: every bead's new dipole from the old dipoles of its neighbours. Order-free
  // within a sweep, hence parallel and thread-count independent. Plain Jacobi diverges when
  // the coupling matrix αT has an eigenvalue below −1 (e.g. a touching monolayer across the
  // field for μr ≳ 24); under-relaxation p ← p + ω (p_Jacobi − p) maps every eigenvalue
  // λ < 1 into the unit circle for small enough ω, so ω is halved whenever the largest
  // dipole change grows twice in a row (deterministic: it depends on max-reductions only).
  stats.converged = false;
  double omega = 1.0, previous_change = 0.0;
  int growth = 0;
  const int first_sweep = stats.sweeps;
  for (int sweep = 1; sweep <= settings_.max_sweeps; ++sweep)
  {
    if (normal_axis_ >= 0)
      evaluate_tail(p_);
    double max_change2 = 0.0, max_p2 = 0.0;
#pragma omp parallel for schedule(static) reduction(max : max_change2, max_p2) if (n >= parallel_threshold)
    for (long m = 0; m < static_cast<long>(n); ++m)
    {
      const std::size_t b = subset ? (*subset)[m] : static_cast<std::size_t>(m);
      double *B = &B_local_[3 * b];
      gather_local_field(b, p_, B);
      double *p = &p_next_[3 * b];
      induced_moment(beads.radius[b], beta_[b], Ms_[b], B, p);
      double change2 = 0.0, p2 = 0.0;
      for (int d = 0; d < 3; ++d)
      {
        const double dp = p[d] - p_[3 * b + d];
        change2 += dp * dp;
        if (omega != 1.0)
          p[d] = p_[3 * b + d] + omega * dp;
        p2 += p[d] * p[d];
      }
      max_change2 = std::max(max_change2, change2);
      max_p2 = std::max(max_p2, p2);
    }
    if (subset) // only the subset's dipoles were updated
      for (const std::uint32_t b : *subset)
        for (int d = 0; d < 3; ++d)
          p_[3 * b + d] = p_next_[3 * b + d];
    else
      p_.swap(p_next_);
    stats.sweeps = first_sweep + sweep;
    stats.residual = max_p2 > 0.0 ? std::sqrt(max_change2 / max_p2) : 0.0;
    if (stats.residual <= settings_.tolerance)
    {
      stats.converged = true;
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
  stats.relaxation = omega;
  if (normal_axis_ >= 0)
    evaluate_tail(p_); // the tail force uses the final dipoles
}

void InducedDipoles::prepare_tail(const BeadArrays &beads, double cutoff)
{
  const std::size_t n = beads.n;
  const double *u = normal_axis_ == 0 ? beads.x : normal_axis_ == 1 ? beads.y : beads.z;
  tail_area_ = 1.0;
  for (int d = 0; d < 3; ++d)
    if (d != normal_axis_)
      tail_area_ *= box_[d];
  tail_cutoff_ = cutoff;
  // Sort along the open axis (ties by index: deterministic), centred to limit cancellation.
  tail_order_.resize(n);
  for (std::size_t b = 0; b < n; ++b)
    tail_order_[b] = static_cast<std::uint32_t>(b);
  std::sort(tail_order_.begin(), tail_order_.end(), [&](std::uint32_t i, std::uint32_t j) {
    return u[i] < u[j] || (u[i] == u[j] && i < j);
  });
  const double centre = 0.5 * (u[tail_order_.front()] + u[tail_order_.back()]);
  tail_u_.resize(n);
  for (std::size_t k = 0; k < n; ++k)
    tail_u_[k] = u[tail_order_[k]] - centre;
  // Window of every bead (in sorted positions): the sheets with |h| < R_c.
  tail_lo_.resize(n);
  tail_hi_.resize(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    const double uk = tail_u_[k];
    tail_lo_[k] = std::lower_bound(tail_u_.begin(), tail_u_.end(), uk - cutoff) - tail_u_.begin();
    tail_hi_[k] = std::upper_bound(tail_u_.begin(), tail_u_.end(), uk + cutoff) - tail_u_.begin();
  }
  tail_S0_.resize(3 * (n + 1));
  tail_S1_.resize(3 * (n + 1));
  tail_S2_.resize(3 * (n + 1));
  tail_B_.resize(3 * n);
  tail_dB_.resize(3 * n);
}

void InducedDipoles::evaluate_tail(const std::vector<double> &p)
{
  const std::size_t n = tail_order_.size();
  const int na = normal_axis_;
  // Prefix sums over the sorted beads of the sheet moments q = 2 p_n n̂ − p_t and of q u, q u².
  for (int d = 0; d < 3; ++d)
    tail_S0_[d] = tail_S1_[d] = tail_S2_[d] = 0.0;
  for (std::size_t k = 0; k < n; ++k)
  {
    const std::uint32_t b = tail_order_[k];
    const double uk = tail_u_[k];
    for (int d = 0; d < 3; ++d)
    {
      const double q = (d == na ? 2.0 : -1.0) * p[3 * b + d];
      tail_S0_[3 * (k + 1) + d] = tail_S0_[3 * k + d] + q;
      tail_S1_[3 * (k + 1) + d] = tail_S1_[3 * k + d] + q * uk;
      tail_S2_[3 * (k + 1) + d] = tail_S2_[3 * k + d] + q * uk * uk;
    }
  }
  const double Rc = tail_cutoff_, c = -mu0 / (4.0 * Rc * tail_area_);
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
  for (long k = 0; k < static_cast<long>(n); ++k)
  {
    const std::uint32_t b = tail_order_[k];
    const double ui = tail_u_[k];
    const std::size_t lo = tail_lo_[k], hi = tail_hi_[k];
    for (int d = 0; d < 3; ++d)
    {
      const double S0 = tail_S0_[3 * hi + d] - tail_S0_[3 * lo + d];
      const double S1 = tail_S1_[3 * hi + d] - tail_S1_[3 * lo + d];
      const double S2 = tail_S2_[3 * hi + d] - tail_S2_[3 * lo + d];
      // Σ_k (1 − (u_k − u_i)²/R_c²) q_k  and its derivative in u_i, Σ 2(u_k − u_i)/R_c² q_k.
      tail_B_[3 * b + d] = c * (S0 - (S2 - 2.0 * ui * S1 + ui * ui * S0) / (Rc * Rc));
      tail_dB_[3 * b + d] = c * 2.0 * (S1 - ui * S0) / (Rc * Rc);
    }
  }
}

void InducedDipoles::prepare_correction_tables()
{
  // One table per distinct pair β; almost always a single carrier material.
  std::vector<double> distinct(beta_.begin(), beta_.end());
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  for (std::size_t a = 0; a < distinct.size(); ++a)
    for (std::size_t b = a; b < distinct.size(); ++b)
    {
      const double beta = 0.5 * (distinct[a] + distinct[b]);
      if (!tables_.count(beta))
        tables_[beta] = TwoSphereTable::shared(beta, settings_.switch_end);
    }
}

void InducedDipoles::evaluate_pair_forces(const BeadArrays &beads, MagneticStats &stats)
{
  const std::size_t np = list_.pairs().size();
  pair_force_.resize(3 * np);
  const TwoSphereTable *single_table = tables_.size() == 1 ? tables_.begin()->second.get() : nullptr;
  std::size_t corrected_pairs = 0;
#pragma omp parallel for schedule(static) reduction(+ : corrected_pairs) if (np >= parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
    corrected_pairs += evaluate_pair_force(beads, k, single_table);
  stats.corrected_pairs = corrected_pairs;
}

bool InducedDipoles::evaluate_pair_force(const BeadArrays &beads, std::size_t k,
                                         const TwoSphereTable *single_table)
{
  double *F = &pair_force_[3 * k];
  if (!active_[k])
  {
    F[0] = F[1] = F[2] = 0.0;
    return false;
  }
  const std::uint32_t i = list_.pairs()[k].i, j = list_.pairs()[k].j;
  const double *r = &r_[3 * k];
  dipole_pair_force(r, &p_[3 * j], &p_[3 * i], F);
  if (settings_.model != DipoleModel::corrected || far_)
    return false; // (with the far field, the corrections have their own list)
  return add_correction(beads, i, j, r, tensor_[k], single_table, F);
}

bool InducedDipoles::add_correction(const BeadArrays &beads, std::uint32_t i, std::uint32_t j,
                                    const double r[3], const DipoleTensor &T,
                                    const TwoSphereTable *single_table, double F[3]) const
{
  const double s0 = settings_.switch_begin, s1 = settings_.switch_end;
  {
    // Exact two-sphere correction, Δf = f_exact − f_mutual, in the field the pair sits in:
    // the local field at each bead minus the partner's own contribution, averaged.
    const double a = 0.5 * (beads.radius[i] + beads.radius[j]);
    const double dist = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    const double D = dist / a;
    if (D >= s1)
      return false;
    const TwoSphereTable *table = single_table;
    if (!table)
      table = tables_.at(0.5 * (beta_[i] + beta_[j])).get();
    double Bi[3] = {B_local_[3 * i], B_local_[3 * i + 1], B_local_[3 * i + 2]};
    double Bj[3] = {B_local_[3 * j], B_local_[3 * j + 1], B_local_[3 * j + 2]};
    const DipoleTensor minus = {-T.xx, -T.yy, -T.zz, -T.xy, -T.xz, -T.yz};
    minus.add_field(&p_[3 * j], Bi);
    minus.add_field(&p_[3 * i], Bj);
    double H[3], e[3];
    for (int d = 0; d < 3; ++d)
    {
      H[d] = 0.5 * (Bi[d] + Bj[d]) / mu0;
      e[d] = r[d] / dist;
    }
    const double Hr = H[0] * e[0] + H[1] * e[1] + H[2] * e[2];
    const double Ht[3] = {H[0] - Hr * e[0], H[1] - Hr * e[1], H[2] - Hr * e[2]};
    const double Ht2 = Ht[0] * Ht[0] + Ht[1] * Ht[1] + Ht[2] * Ht[2];
    const TwoSphereForce c = table->correction(D);
    // Smooth switch-off (C¹ smoothstep) between switch_begin and switch_end.
    double w = 1.0;
    if (D > s0)
    {
      const double t = (D - s0) / (s1 - s0);
      w = 1.0 - t * t * (3.0 - 2.0 * t);
    }
    // Unequal beads: the identical-sphere table at the mean radius ā, rescaled by the dipole
    // scaling (a_i a_j)³/ā⁶ of a pair force (a ±15 % size pair: residual ~1–2 % of Δf).
    const double size_ratio = beads.radius[i] * beads.radius[j] / (a * a);
    const double scale = w * mu0 * a * a * size_ratio * size_ratio * size_ratio;
    const double radial = c.parallel * Hr * Hr + c.perpendicular * Ht2;
    // F·t̂ = f_t sinψ cosψ H² along t̂ (the direction that turns r̂ away from the field),
    // i.e. −f_t H_r H_t as a vector.
    for (int d = 0; d < 3; ++d)
      F[d] += scale * (radial * e[d] - c.transverse * Hr * Ht[d]);
    return true;
  }
}


void InducedDipoles::refresh_correction_list(const BeadArrays &beads)
{
  // Pairs within switch_end mean radii of each other (+ skin): their centres may lie in
  // non-neighbouring fine cells, so the correction has a list of its own.
  double sum = 0.0, largest = 0.0;
  for (std::size_t b = 0; b < beads.n; ++b)
  {
    sum += beads.radius[b];
    largest = std::max(largest, beads.radius[b]);
  }
  const double skin = settings_.skin_fraction * 2.0 * sum / beads.n;
  const double radius = settings_.switch_end * largest + skin;
  const bool stale = !correction_list_.built() || correction_list_.particle_count() != beads.n ||
                     correction_list_.box() != box_ ||
                     std::abs(correction_list_.list_radius() - radius) > 1e-12 * radius ||
                     correction_list_.max_displacement(beads.n, beads.x, beads.y, beads.z) > 0.5 * skin;
  if (stale)
    correction_list_.build(beads.n, beads.x, beads.y, beads.z, box_, radius);
}

void InducedDipoles::evaluate_correction_forces(const BeadArrays &beads, MagneticStats &stats)
{
  const std::size_t np = correction_list_.pairs().size();
  correction_force_.resize(3 * np);
  const TwoSphereTable *single_table = tables_.size() == 1 ? tables_.begin()->second.get() : nullptr;
  std::size_t corrected_pairs = 0;
#pragma omp parallel for schedule(static) reduction(+ : corrected_pairs) if (np >= parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
    corrected_pairs += evaluate_correction_force(beads, k, single_table);
  stats.corrected_pairs = corrected_pairs;
}

bool InducedDipoles::evaluate_correction_force(const BeadArrays &beads, std::size_t k,
                                               const TwoSphereTable *single_table)
{
  double *F = &correction_force_[3 * k];
  F[0] = F[1] = F[2] = 0.0;
  const auto &pair = correction_list_.pairs()[k];
  const double r[3] = {beads.x[pair.j] - beads.x[pair.i] + pair.shift[0],
                       beads.y[pair.j] - beads.y[pair.i] + pair.shift[1],
                       beads.z[pair.j] - beads.z[pair.i] + pair.shift[2]};
  if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] == 0.0)
    return false;
  return add_correction(beads, pair.i, pair.j, r, DipoleTensor::at(r), single_table, F);
}

void InducedDipoles::gather_forces(const ForceArrays &out)
{
  const std::size_t n = beta_.size();
  force_.resize(3 * n);
  torque_.resize(3 * n);
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
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
  if (normal_axis_ >= 0)
  {
    const double *dB = &tail_dB_[3 * b];
    F[normal_axis_] += p[0] * dB[0] + p[1] * dB[1] + p[2] * dB[2];
  }
  // Far field: (p·∇)B_far.
  if (far_)
  {
    const double *gf = &gradB_far_[9 * b];
    for (int a = 0; a < 3; ++a)
      F[a] += p[0] * gf[3 * a] + p[1] * gf[3 * a + 1] + p[2] * gf[3 * a + 2];
  }
  add_incident_pair_forces(list_, pair_force_, b, F);
  if (far_ && settings_.model == DipoleModel::corrected)
    add_incident_pair_forces(correction_list_, correction_force_, b, F);
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

void InducedDipoles::add_held_forces(const ForceArrays &out) const
{
  const std::size_t n = force_.size() / 3;
  const bool torques = settings_.torque == TorqueModel::paper && out.tx && out.ty && out.tz;
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
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
  permute(x_last_);
  list_ = MagneticNeighbourList(); // pair indices refer to the old order
  correction_list_ = MagneticNeighbourList();
  close_.clear();                  // (the watched pairs too, until the next compute)
  close_of_pair_.clear();
}

bool InducedDipoles::needs_refresh(const BeadArrays &beads, double time) const
{
  return check_staleness(beads, time).reason != RefreshReason::none;
}

StalenessCheck InducedDipoles::check_staleness(const BeadArrays &beads, double time) const
{
  StalenessCheck c;
  if (!computed_)
  {
    c.reason = RefreshReason::first;
    return c;
  }
  if (x_last_.size() != 3 * beads.n)
  {
    c.reason = RefreshReason::bead_count;
    return c;
  }
  if (settings_.refresh_interval <= 0.0 ||
      time - t_last_ >= settings_.refresh_interval * (1.0 - 1e-9))
  {
    c.reason = RefreshReason::interval;
    return c;
  }
  // A bead is stale when it moved more than staleness_fraction × its radius since its force
  // was evaluated. The minimum image: a bead wrapped across a periodic face by the caller did
  // not move (the neighbour lists see the jump and are rebuilt at the next compute).
  const bool relative = settings_.staleness_mode == StalenessMode::relative && list_.built() &&
                        list_.particle_count() == beads.n;
  if (relative)
    move2_.resize(beads.n);
  std::size_t stale = 0;
  double worst2 = 0.0;
  for (std::size_t b = 0; b < beads.n; ++b)
  {
    const double move2 = squared_move(beads, b);
    stale += move2 > limit2_[b];
    worst2 = std::max(worst2, move2 * inv_radius2_[b]);
    if (relative)
      move2_[b] = move2;
  }
  c.stale_beads = stale;
  c.max_move = std::sqrt(worst2);
  // relative: the watched pairs whose vector changed by more than the fraction. A pair can
  // only be stale if one of its beads moved half its limit (|Δr| ≤ |Δx_i| + |Δx_j|): the
  // pair loop is skipped while no bead has, and pairs of beads that have not are skipped.
  if (relative && 2.0 * c.max_move * max_radius_ > settings_.staleness_fraction * min_radius_)
  {
    std::size_t stale_pairs = 0;
    for (const ClosePair &p : close_)
      if (4.0 * std::max(move2_[p.i], move2_[p.j]) > p.limit2)
        stale_pairs += drift2(beads, p) > p.limit2;
    c.stale_pairs = stale_pairs;
  }
  if (stale > 0 || c.stale_pairs > 0)
    c.reason = RefreshReason::moved;
  return c;
}

double InducedDipoles::squared_move(const BeadArrays &beads, std::size_t b) const
{
  double d[3] = {beads.x[b] - x_last_[3 * b], beads.y[b] - x_last_[3 * b + 1],
                 beads.z[b] - x_last_[3 * b + 2]};
  for (int a = 0; a < 3; ++a)
    if (box_[a] > 0.0 && std::abs(d[a]) > 0.5 * box_[a])
      d[a] -= box_[a] * std::round(d[a] / box_[a]);
  return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
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
  for (auto *v : {&B0_, &gradB0_, &p_, &B_local_, &B_far_, &gradB_far_, &tail_B_, &tail_dB_})
    for (double &x : *v)
      x *= ratio;
  const double ratio2 = ratio * ratio;
  for (auto *v : {&force_, &torque_, &pair_force_, &correction_force_})
    for (double &x : *v)
      x *= ratio2;
}

bool InducedDipoles::refresh_locally(const BeadArrays &beads, const AppliedFieldFunction &field,
                                     double time, MagneticStats &stats)
{
  (void)time; // the refresh interval counts from the last full compute()
  stats = MagneticStats();
  const std::size_t n = beads.n;
  const double t_start = omp_get_wtime();
  region_.clear();
  // Can a local refresh stand in for a full one? The neighbour lists must still hold every
  // pair the full evaluation would use (no bead moved half the skin, none was wrapped).
  if (!computed_ || zero_field_ || x_last_.size() != 3 * n || p_.size() != 3 * n ||
      force_.size() != 3 * n || normal_axis_ >= 0 || !list_.built() || list_.particle_count() != n)
    return false;
  if (list_.max_displacement(n, beads.x, beads.y, beads.z) > 0.5 * skin_)
    return false;
  const bool far_corrections = far_ && settings_.model == DipoleModel::corrected;
  if (far_corrections && (!correction_list_.built() || correction_list_.particle_count() != n ||
                          correction_list_.max_displacement(n, beads.x, beads.y, beads.z) > 0.5 * skin_))
    return false;

  // 1. The moved beads, and the region R: them and their near neighbours.
  // Batched: once one bead is past the limit, every bead past local_batch_fraction of it
  // comes along, so that the next one does not trigger another refresh a step later.
  // relative: the beads of the watched pairs whose vector changed past the batch fraction.
  moved_.clear();
  bool due = false;
  const double batch2 = settings_.local_batch_fraction * settings_.local_batch_fraction;
  bead_mark_.assign(n, 0);
  enum : std::uint8_t { in_region = 1, in_gather = 2, is_moved = 4 };
  auto add_moved = [&](std::uint32_t b) { add_once(bead_mark_, is_moved, moved_, b); };
  for (std::size_t b = 0; b < n; ++b)
  {
    const double move2 = squared_move(beads, b);
    due |= move2 > limit2_[b];
    if (move2 > batch2 * limit2_[b])
      add_moved(static_cast<std::uint32_t>(b));
  }
  if (settings_.staleness_mode == StalenessMode::relative)
  {
    for (const ClosePair &p : close_)
    {
      const double d2 = drift2(beads, p);
      due |= d2 > p.limit2;
      if (d2 > batch2 * p.limit2)
      {
        // The bead(s) that made the drift: |Δr| ≤ |Δx_i| + |Δx_j|, so at least one of them
        // moved half of it (re-evaluating one re-evaluates the pair).
        const double half2 = 0.25 * d2;
        if (squared_move(beads, p.i) >= half2)
          add_moved(p.i);
        if (squared_move(beads, p.j) >= half2)
          add_moved(p.j);
      }
    }
  }
  if (!due)
    return true;
  std::sort(moved_.begin(), moved_.end());
  const auto &pairs = list_.pairs();
  const auto &begin = list_.incident_begin();
  const auto &pair_of = list_.incident_pair();
  const auto &first = list_.incident_first();
  region_.clear();
  auto add_to_region = [&](std::uint32_t b) { add_once(bead_mark_, in_region, region_, b); };
  for (const std::uint32_t b : moved_)
  {
    add_to_region(b);
    // Its neighbours within local_region_radius of its own radius (current positions).
    const double reach = settings_.local_region_radius * beads.radius[b];
    for (std::size_t q = begin[b]; q < begin[b + 1]; ++q)
    {
      const auto &pair = pairs[pair_of[q]];
      const double r[3] = {beads.x[pair.j] - beads.x[pair.i] + pair.shift[0],
                           beads.y[pair.j] - beads.y[pair.i] + pair.shift[1],
                           beads.z[pair.j] - beads.z[pair.i] + pair.shift[2]};
      if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < reach * reach)
        add_to_region(first[q] ? pair.j : pair.i);
    }
  }
  // (A small region is always cheaper than a full refresh, whatever the fraction.)
  if (region_.size() > 64 &&
      static_cast<double>(region_.size()) > settings_.local_region_limit * static_cast<double>(n))
    return false;
  std::sort(region_.begin(), region_.end()); // a fixed order, whatever the discovery order

  // 2. The moved beads' applied field and the tensors of their pairs (each pair once).
  for (const std::uint32_t b : moved_)
  {
    evaluate_applied_field_at(beads, field, b);
    store_reference_position(beads, b);
  }
  pair_mark_.assign(pairs.size(), 0);
  touched_pairs_.clear();
  for (const std::uint32_t b : moved_)
    for (std::size_t q = begin[b]; q < begin[b + 1]; ++q)
      if (!pair_mark_[pair_of[q]])
      {
        pair_mark_[pair_of[q]] = 1;
        touched_pairs_.push_back(pair_of[q]);
      }
  for (const std::uint32_t k : touched_pairs_)
  {
    evaluate_pair_tensor(beads, k);
    update_close_pair(k);
    if (far_)
    { // the per-bead copies the sweeps read
      const DipoleTensor &T = tensor_[k];
      for (int side = 0; side < 2; ++side)
      {
        double *t = &near_tensor_[6 * pair_entry_[2 * k + side]];
        t[0] = T.xx;
        t[1] = T.yy;
        t[2] = T.zz;
        t[3] = T.xy;
        t[4] = T.xz;
        t[5] = T.yz;
      }
    }
  }

  // 3. The dipoles of R, from the held ones, with everything outside R held.
  const double t_sweeps = omp_get_wtime();
  region_p_.resize(3 * region_.size());
  for (std::size_t m = 0; m < region_.size(); ++m)
    for (int d = 0; d < 3; ++d)
      region_p_[3 * m + d] = p_[3 * region_[m] + d];
  sweep_to_tolerance(beads, stats, &region_);
  stats.time_sweeps = omp_get_wtime() - t_sweeps;
  // The beads whose interactions changed: the moved ones, and those of R whose dipole changed
  // by more than local_dipole_change (the dipole change decays like 1/r³ from a moved bead:
  // beyond its touching neighbours it is far below a per cent of the moved bead's own).
  changed_.clear();
  const double tol2 = settings_.local_dipole_change * settings_.local_dipole_change;
  for (std::size_t m = 0; m < region_.size(); ++m)
  {
    const std::uint32_t b = region_[m];
    double dp2 = 0.0, p2 = 0.0;
    for (int d = 0; d < 3; ++d)
    {
      const double dp = p_[3 * b + d] - region_p_[3 * m + d];
      dp2 += dp * dp;
      p2 += p_[3 * b + d] * p_[3 * b + d];
    }
    if ((bead_mark_[b] & is_moved) || tol2 == 0.0 || dp2 > tol2 * p2)
      changed_.push_back(b);
  }

  // 4. The force of every pair touching a changed bead, and 5. the total force of every bead
  //    touching those pairs (pair forces stored once, applied ±: Newton's third law exact).
  const double t_forces = omp_get_wtime();
  const TwoSphereTable *single_table = tables_.size() == 1 ? tables_.begin()->second.get() : nullptr;
  gathered_.clear();
  auto add_to_gather = [&](std::uint32_t b) { add_once(bead_mark_, in_gather, gathered_, b); };
  for (const std::uint32_t b : changed_)
    for (std::size_t q = begin[b]; q < begin[b + 1]; ++q)
      if (pair_mark_[pair_of[q]] != 2)
      {
        const std::uint32_t k = pair_of[q];
        pair_mark_[k] = 2;
        stats.corrected_pairs += evaluate_pair_force(beads, k, single_table);
        ++stats.local_pairs;
        add_to_gather(pairs[k].i);
        add_to_gather(pairs[k].j);
      }
  if (far_corrections)
  {
    const auto &cpairs = correction_list_.pairs();
    const auto &cbegin = correction_list_.incident_begin();
    const auto &cpair = correction_list_.incident_pair();
    correction_mark_.assign(cpairs.size(), 0);
    for (const std::uint32_t b : changed_)
      for (std::size_t q = cbegin[b]; q < cbegin[b + 1]; ++q)
        if (!correction_mark_[cpair[q]])
        {
          const std::uint32_t k = cpair[q];
          correction_mark_[k] = 1;
          stats.corrected_pairs += evaluate_correction_force(beads, k, single_table);
          add_to_gather(cpairs[k].i);
          add_to_gather(cpairs[k].j);
        }
  }
  for (const std::uint32_t b : gathered_)
    gather_bead(b);
  stats.time_forces = omp_get_wtime() - t_forces;

  stats.local_moved = moved_.size();
  stats.local_region = region_.size();
  stats.local_gathered = gathered_.size();
  stats.pairs = touched_pairs_.size();
  stats.time_tensors = t_sweeps - t_start;
  return true;
}

} // namespace magbrush::magnetics
