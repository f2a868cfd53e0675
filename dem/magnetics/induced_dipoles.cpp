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
  double cutoff;
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
  evaluate_applied_field(beads, field);
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

  x_last_.resize(3 * n);
  for (std::size_t b = 0; b < n; ++b)
  {
    x_last_[3 * b] = beads.x[b];
    x_last_[3 * b + 1] = beads.y[b];
    x_last_[3 * b + 2] = beads.z[b];
  }
  t_last_ = time;
  computed_ = true;
  return stats;
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
}

void InducedDipoles::evaluate_pair_tensors(const BeadArrays &beads, double cutoff,
                                           MagneticStats &stats)
{
  const auto &pairs = list_.pairs();
  const std::size_t np = pairs.size();
  tensor_.resize(np);
  r_.resize(3 * np);
  active_.resize(np);
  const double rc2 = cutoff * cutoff;
  std::size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count) if (np >= parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
  {
    const auto &p = pairs[k];
    double r[3] = {beads.x[p.j] - beads.x[p.i] + p.shift[0],
                   beads.y[p.j] - beads.y[p.i] + p.shift[1],
                   beads.z[p.j] - beads.z[p.i] + p.shift[2]};
    const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    for (int d = 0; d < 3; ++d)
      r_[3 * k + d] = r[d];
    // Hard cutoff (as Kawamoto): pairs beyond it do not interact at all. Coincident
    // centres (r = 0) cannot occur between non-overlapping beads; they are skipped.
    active_[k] = (r2 < rc2 && r2 > 0.0);
    if (active_[k])
    {
      tensor_[k] = DipoleTensor::at(r);
      ++count;
    }
    else
      tensor_[k] = {0, 0, 0, 0, 0, 0};
  }
  stats.pairs = count;
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

void InducedDipoles::sweep_to_tolerance(const BeadArrays &beads, MagneticStats &stats)
{
  const std::size_t n = beads.n;
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
    for (long b = 0; b < static_cast<long>(n); ++b)
    {
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
  const auto &pairs = list_.pairs();
  const std::size_t np = pairs.size();
  pair_force_.resize(3 * np);
  const bool corrected = settings_.model == DipoleModel::corrected;
  const TwoSphereTable *single_table = tables_.size() == 1 ? tables_.begin()->second.get() : nullptr;
  std::size_t corrected_pairs = 0;
#pragma omp parallel for schedule(static) reduction(+ : corrected_pairs) if (np >= parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
  {
    double *F = &pair_force_[3 * k];
    if (!active_[k])
    {
      F[0] = F[1] = F[2] = 0.0;
      continue;
    }
    const std::uint32_t i = pairs[k].i, j = pairs[k].j;
    const double *r = &r_[3 * k];
    dipole_pair_force(r, &p_[3 * j], &p_[3 * i], F);
    if (!corrected || far_)
      continue; // (with the far field, the corrections have their own list)
    if (add_correction(beads, i, j, r, tensor_[k], single_table, F))
      ++corrected_pairs;
  }
  stats.corrected_pairs = corrected_pairs;
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
  const auto &pairs = correction_list_.pairs();
  const std::size_t np = pairs.size();
  correction_force_.resize(3 * np);
  const TwoSphereTable *single_table = tables_.size() == 1 ? tables_.begin()->second.get() : nullptr;
  std::size_t corrected_pairs = 0;
#pragma omp parallel for schedule(static) reduction(+ : corrected_pairs) if (np >= parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
  {
    double *F = &correction_force_[3 * k];
    F[0] = F[1] = F[2] = 0.0;
    const auto &pair = pairs[k];
    const double r[3] = {beads.x[pair.j] - beads.x[pair.i] + pair.shift[0],
                         beads.y[pair.j] - beads.y[pair.i] + pair.shift[1],
                         beads.z[pair.j] - beads.z[pair.i] + pair.shift[2]};
    if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] == 0.0)
      continue;
    if (add_correction(beads, pair.i, pair.j, r, DipoleTensor::at(r), single_table, F))
      ++corrected_pairs;
  }
  stats.corrected_pairs = corrected_pairs;
}

void InducedDipoles::gather_forces(const ForceArrays &out)
{
  const std::size_t n = beta_.size();
  force_.resize(3 * n);
  torque_.resize(3 * n);
  const auto &begin = list_.incident_begin();
  const auto &pair_of = list_.incident_pair();
  const auto &first = list_.incident_first();
  const bool paper_torque = settings_.torque == TorqueModel::paper;
  const bool corrected = settings_.model == DipoleModel::corrected;
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
  for (long b = 0; b < static_cast<long>(n); ++b)
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
    // Pair forces are stored as the force on the pair's j bead; its i bead gets the negative.
    for (std::size_t q = begin[b]; q < begin[b + 1]; ++q)
    {
      const double *Fp = &pair_force_[3 * pair_of[q]];
      const double sign = first[q] ? -1.0 : 1.0;
      for (int a = 0; a < 3; ++a)
        F[a] += sign * Fp[a];
    }
    if (far_ && corrected)
    {
      const auto &cbegin = correction_list_.incident_begin();
      const auto &cpair = correction_list_.incident_pair();
      const auto &cfirst = correction_list_.incident_first();
      for (std::size_t q = cbegin[b]; q < cbegin[b + 1]; ++q)
      {
        const double *Fp = &correction_force_[3 * cpair[q]];
        const double sign = cfirst[q] ? -1.0 : 1.0;
        for (int a = 0; a < 3; ++a)
          F[a] += sign * Fp[a];
      }
    }
    double *T = &torque_[3 * b];
    if (paper_torque)
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
  add_held_forces(out);
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
}

bool InducedDipoles::needs_refresh(const BeadArrays &beads, double time) const
{
  if (!computed_ || x_last_.size() != 3 * beads.n)
    return true;
  if (settings_.refresh_interval <= 0.0 ||
      time - t_last_ >= settings_.refresh_interval * (1.0 - 1e-9))
    return true;
  bool moved = false;
#pragma omp parallel for schedule(static) reduction(|| : moved) if (beads.n >= parallel_threshold)
  for (long b = 0; b < static_cast<long>(beads.n); ++b)
  {
    const double dx = beads.x[b] - x_last_[3 * b], dy = beads.y[b] - x_last_[3 * b + 1],
                 dz = beads.z[b] - x_last_[3 * b + 2];
    const double limit = settings_.staleness_fraction * beads.radius[b];
    if (dx * dx + dy * dy + dz * dz > limit * limit)
      moved = true;
  }
  return moved;
}

} // namespace magbrush::magnetics
