// The staleness modes side by side (magnetic_settings.h StalenessMode), on the two scenes
// where the refresh count sets the cost: the flowing nip and the forming compression brush.
// For each mode the same run (same start, same steps) reports
//   * full evaluations and local refreshes per simulated ms (and what caused the full ones);
//   * the held-force error: every `sample` of simulated time, the magnetic forces the term
//     added at that step against a fresh full evaluation at the same positions (same settings,
//     tolerance 1e-6): RMS over the carriers of |F_held − F_fresh| / RMS |F_fresh|, the worst
//     bead's |F_held − F_fresh| / RMS |F_fresh|, and the error of the total magnetic force on
//     the beads touching the drum (nip) or the stage (compression), each averaged over the
//     samples (i.e. over the holds) and its maximum;
//   * the magnetic share: the engine's own clock of the magnetic term against all its other
//     phases in the same steps (robust to the machine's load).
//
// Scenes:
//   nip:         tests/scenes/nip/kawamoto_nip_reduced.yaml (1,300 beads, 0.3 mm slab, roller field,
//                40 ns steps) with the project's default far field (cell multipole); settled
//                once for 0.3 ms, then every mode runs the same `flow` of turning from that
//                checkpoint. The roller field is computed by `magbrush field` first.
//   compression: cases/kawamoto_brush_compression.yaml on a 1 × 1 mm² square (1,105 beads
//                of 60 µm): (1) from the insertion through the field ramp (0.3 ms) and the
//                hold before the plate moves, every mode runs 0 … `until`; (2) the plate
//                coming down at 0.1 m/s: run once to `descent_at`, then every mode runs the
//                same `descent` window from that checkpoint (error on the plate force).
//
//   nip_quick:   the same on the placed quick scene (cases/kawamoto_nip.yaml, 4,300 beads,
//                1 mm slab, 40 ns steps).
//
//   regulation:  cases/kweon_regulation.yaml (the sump inflow, the doctor blade, the outflow):
//                run to `until` once, then every mode runs the same `flow` window (function
//                fed() below: a state of `magbrush run` can be reused).
//   nip_fed:     cases/kawamoto_nip_fed.yaml (the default: the layer supplied through the
//                gap), the same way; the force error on the drum.
//   full_roller: cases/kweon_full_roller.yaml (the closed loop: sump, guide, blade, nip,
//                release), the same way; the force error on the sleeve.
//
//   bench_magnetic_staleness [nip|nip_quick|compression|both|regulation|nip_fed|full_roller] [flow_us (nip, 300)] [until_us (compression, 500)]
//                            [sample_us (2)] [modes (absolute,local,relative)] [refresh_us (the case's: 5)]
//                            [descent_at_us (2500)] [descent_us (300; 0 = skip)]
// Environment (knobs without a case key): MAGBRUSH_LOCAL_REGION_LIMIT, MAGBRUSH_LOCAL_BATCH,
// MAGBRUSH_ABSOLUTE_FACTOR, MAGBRUSH_MAGNETIC_SKIN (MagneticSettings local_region_limit,
// local_batch_fraction, absolute_factor, skin_fraction: the magnetic lists' skin, otherwise
// dem.verlet_skin). MAGBRUSH_BENCH_REFERENCE_FAR_PASSES (4): far-field passes of the reference
// solve; MAGBRUSH_BENCH_WORST=1: per sample, the five beads farthest from the reference.
//
// The reference is a fresh solve at tolerance 1e-6 with its far field evaluated again until it
// no longer lags the dipoles, started cold whenever the set of beads changed (until 2026-12-03
// it started warm from its previous solve by position in the id order, which an exchange shifts,
// and evaluated its far field once: in a fed brush that reference itself was off by 1-10 %).
#include "dem/force_terms/magnetic_force_term.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_parser.h"
#include "dem/dem_run.h"
#include "fields/field_files.h"

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace magbrush;
using namespace magbrush::magnetics;
namespace fs = std::filesystem;

namespace {

// Far-field passes of the reference solve (MAGBRUSH_BENCH_REFERENCE_FAR_PASSES, default 4).
int reference_far_passes()
{
  const char *v = std::getenv("MAGBRUSH_BENCH_REFERENCE_FAR_PASSES");
  return v ? std::atoi(v) : 4;
}

// Held magnetic forces against a fresh full evaluation, sampled during the run.
class HeldForceError : public dem::Measurement
{
public:
  HeldForceError(const Case &c, const MagneticForceTerm *term, MagneticSettings settings,
                 const AppliedMagneticField &field, const std::array<double, 3> &box, std::size_t wall,
                 double interval)
    : term_(term), field_(field), wall_(wall), interval_(interval)
  {
    settings.refresh_interval = 0.0;
    settings.staleness_mode = StalenessMode::absolute;
    settings.tolerance = 1e-6;
    settings.hold_dipoles = false; // (the reference solves; nothing is held between samples)
    // The reference's far field is evaluated again until it no longer lags the dipoles (one
    // pass lags them by ~1e-3 of the force in a brush, more after a cold start).
    settings.far_passes = reference_far_passes();
    reference_settings_ = settings;
    box_ = box;
    fresh_ = std::make_unique<InducedDipoles>(settings, box);
    live_ = std::make_unique<InducedDipoles>(settings, box);
    for (const Population &p : c.populations)
    {
      carrier_species_.push_back(p.kind == ParticleKind::carrier);
      mu_.push_back(p.kind == ParticleKind::carrier ? c.material(p.material).mu_r : 1.0);
    }
  }
  const char *name() const override { return "held magnetic force error"; }
  double interval() const override { return interval_; }
  void write(const std::string &) const override {}
  // The probe measures the window of the run it is attached to: a restarted run opens its
  // window again at its first sample (nothing is carried over).
  void write_state(StateOut &) const override {}
  void read_state(StateIn &) override {}

  void sample(const dem::DemSystem &system) override
  {
    if (!started_) // the window's counters start here (a restored term brings the settling's)
    {
      started_ = true;
      start_time_ = system.time();
      start_counts_ = term_->refresh_counts();
      start_full_ = term_->evaluations();
      start_local_ = term_->local_refreshes();
    }
    const auto &s = system.particles();
    std::vector<double> hx, hy, hz;
    term_->last_forces(hx, hy, hz);
    if (hx.size() != s.size())
      return;
    // The carriers by stable id (the engine re-sorts; the reference keeps its warm start).
    // (Ids need not be 0 … n−1: the inflow and outflow exchange particles.)
    order_.clear();
    for (std::size_t k = 0; k < s.size(); ++k)
      if (carrier_species_[static_cast<std::size_t>(s.species[k])])
        order_.push_back(k);
    std::sort(order_.begin(), order_.end(), [&s](std::size_t a, std::size_t b) { return s.id[a] < s.id[b]; });
    const std::size_t n = order_.size();
    for (auto *v : {&x_, &y_, &z_, &r_, &mu_r_, &fx_, &fy_, &fz_})
      v->assign(n, 0.0);
    for (std::size_t k = 0; k < n; ++k)
    {
      const std::size_t i = order_[k];
      x_[k] = s.x[i];
      y_[k] = s.y[i];
      z_[k] = s.z[i];
      r_[k] = s.radius[i];
      mu_r_[k] = mu_[static_cast<std::size_t>(s.species[i])];
    }
    const double t = system.time();
    const AppliedMagneticField &field = field_;
    // The reference starts warm from its last solve only when the beads are the same ones:
    // its dipoles are indexed by position in the id order, which an exchange shifts.
    ids_now_.assign(n, 0);
    for (std::size_t k = 0; k < n; ++k)
      ids_now_[k] = s.id[order_[k]];
    if (ids_now_ != ids_last_)
      fresh_ = std::make_unique<InducedDipoles>(reference_settings_, box_);
    ids_last_.swap(ids_now_);
    const MagneticStats fs = fresh_->compute({n, x_.data(), y_.data(), z_.data(), r_.data(), mu_r_.data(), nullptr},
                    [&field, t](const double x[3], double B[3], double g[3][3]) { field.evaluate(x, t, B, g); },
                    t, {fx_.data(), fy_.data(), fz_.data()});
    double e2 = 0.0, f2 = 0.0, emax2 = 0.0;
    for (std::size_t k = 0; k < n; ++k)
    {
      const std::size_t i = order_[k];
      const double e = std::pow(hx[i] - fx_[k], 2) + std::pow(hy[i] - fy_[k], 2) + std::pow(hz[i] - fz_[k], 2);
      e2 += e;
      emax2 = std::max(emax2, e);
      f2 += fx_[k] * fx_[k] + fy_[k] * fy_[k] + fz_[k] * fz_[k];
    }
    if (!(f2 > 0.0))
      return; // no field yet
    const double rms = std::sqrt(e2 / f2), worst = std::sqrt(emax2 / (f2 / n));
    if (std::getenv("MAGBRUSH_BENCH_WORST"))
      print_worst_beads(s, hx, hy, hz, t, rms, f2, fs);
    // Held dipoles, live geometry: the same error measure.
    term_->held_dipoles(held_p_);
    live_p_.assign(3 * n, 0.0);
    for (auto *v : {&lx_, &ly_, &lz_})
      v->assign(n, 0.0);
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t d = 0; d < 3; ++d)
        live_p_[3 * k + d] = held_p_[3 * order_[k] + d];
    live_->forces_of_dipoles({n, x_.data(), y_.data(), z_.data(), r_.data(), mu_r_.data(), nullptr},
                             [&field, t](const double x[3], double B[3], double g[3][3]) { field.evaluate(x, t, B, g); },
                             t, live_p_, {lx_.data(), ly_.data(), lz_.data()});
    double l2 = 0.0, lmax2 = 0.0;
    for (std::size_t k = 0; k < n; ++k)
    {
      const double e = std::pow(lx_[k] - fx_[k], 2) + std::pow(ly_[k] - fy_[k], 2) + std::pow(lz_[k] - fz_[k], 2);
      l2 += e;
      lmax2 = std::max(lmax2, e);
    }
    sum_live_rms_ += std::sqrt(l2 / f2);
    sum_live_max_ += std::sqrt(lmax2 / (f2 / n));
    max_live_rms_ = std::max(max_live_rms_, std::sqrt(l2 / f2));
    // The total magnetic force on the beads touching the wall.
    std::vector<dem::WallContactRecord> touching;
    system.wall_contacts(wall_, touching);
    std::vector<double> fresh_of(3 * s.size(), 0.0);
    for (std::size_t k = 0; k < n; ++k)
    {
      fresh_of[3 * order_[k]] = fx_[k];
      fresh_of[3 * order_[k] + 1] = fy_[k];
      fresh_of[3 * order_[k] + 2] = fz_[k];
    }
    double held[3] = {0, 0, 0}, fresh[3] = {0, 0, 0};
    for (const auto &c : touching)
    {
      held[0] += hx[c.particle];
      held[1] += hy[c.particle];
      held[2] += hz[c.particle];
      for (int d = 0; d < 3; ++d)
        fresh[d] += fresh_of[3 * c.particle + d];
    }
    const double wall_norm = std::sqrt(fresh[0] * fresh[0] + fresh[1] * fresh[1] + fresh[2] * fresh[2]);
    const double wall_err = wall_norm > 0.0 ? std::sqrt(std::pow(held[0] - fresh[0], 2) + std::pow(held[1] - fresh[1], 2) +
                                                        std::pow(held[2] - fresh[2], 2)) / wall_norm
                                            : 0.0;
    ++samples_;
    sum_rms_ += rms;
    sum_max_ += worst;
    sum_wall_ += wall_err;
    max_rms_ = std::max(max_rms_, rms);
    max_max_ = std::max(max_max_, worst);
    max_wall_ = std::max(max_wall_, wall_err);
  }

  // MAGBRUSH_BENCH_WORST: where the error sits. Per sample the reference solve's own state
  // (sweeps, residual, far-field passes) and the five beads farthest from it: id, angle about
  // the z axis (the roller's), distance from it, speed, error and force in units of the RMS
  // force, the held and the fresh force.
  void print_worst_beads(const dem::ParticleState &s, const std::vector<double> &hx, const std::vector<double> &hy,
                         const std::vector<double> &hz, double t, double rms, double f2,
                         const MagneticStats &reference) const
  {
    const std::size_t n = order_.size();
    std::vector<std::pair<double, std::size_t>> err(n);
    for (std::size_t k = 0; k < n; ++k)
    {
      const std::size_t i = order_[k];
      err[k] = {std::pow(hx[i] - fx_[k], 2) + std::pow(hy[i] - fy_[k], 2) + std::pow(hz[i] - fz_[k], 2), k};
    }
    std::sort(err.rbegin(), err.rend());
    std::printf("t %.4f ms: RMS error %.4f; reference: %d sweeps, residual %.2e, %d far-field passes\n", t * 1e3, rms,
                reference.sweeps, reference.residual, reference.far_passes);
    const double f_rms = std::sqrt(f2 / n);
    for (std::size_t q = 0; q < std::min<std::size_t>(5, n); ++q)
    {
      const std::size_t k = err[q].second, i = order_[k];
      const double angle = std::fmod(std::atan2(s.y[i], s.x[i]) * 180.0 / M_PI + 360.0, 360.0);
      std::printf("  id %d at %.2f deg, %.4f mm from the axis, speed %.3f m/s: error %.3f, force %.3f (RMS force); "
                  "held (%.3e, %.3e, %.3e) fresh (%.3e, %.3e, %.3e) N\n",
                  static_cast<int>(s.id[i]), angle, std::hypot(s.x[i], s.y[i]) * 1e3,
                  std::sqrt(s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i] + s.vz[i] * s.vz[i]), std::sqrt(err[q].first) / f_rms,
                  std::sqrt(fx_[k] * fx_[k] + fy_[k] * fy_[k] + fz_[k] * fz_[k]) / f_rms, hx[i], hy[i], hz[i], fx_[k],
                  fy_[k], fz_[k]);
    }
  }

  long samples_ = 0;
  // The term's counters at the first sample, and its time: the table counts from there.
  bool started_ = false;
  double start_time_ = 0.0;
  MagneticForceTerm::RefreshCounts start_counts_;
  long start_full_ = 0, start_local_ = 0;
  double sum_rms_ = 0, sum_max_ = 0, sum_wall_ = 0, max_rms_ = 0, max_max_ = 0, max_wall_ = 0;
  double sum_live_rms_ = 0, sum_live_max_ = 0, max_live_rms_ = 0;

private:
  const MagneticForceTerm *term_;
  AppliedMagneticField field_;
  std::size_t wall_;
  double interval_;
  std::unique_ptr<InducedDipoles> fresh_;
  MagneticSettings reference_settings_;
  std::array<double, 3> box_{};
  std::vector<std::int32_t> ids_now_, ids_last_;
  // The held dipoles' forces at the current positions (InducedDipoles::forces_of_dipoles):
  // what holding the dipoles instead of the forces would give.
  std::unique_ptr<InducedDipoles> live_;
  std::vector<double> held_p_, live_p_, lx_, ly_, lz_;
  std::vector<bool> carrier_species_;
  std::vector<double> mu_;
  std::vector<std::size_t> order_;
  std::vector<double> x_, y_, z_, r_, mu_r_, fx_, fy_, fz_;
};

std::vector<std::string> split(const std::string &list, char separator = ',')
{
  std::vector<std::string> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, separator);)
    out.push_back(item);
  return out;
}

struct ModeResult
{
  std::string mode;
  double simulated_ms = 0;
  long full = 0, local = 0;
  MagneticForceTerm::RefreshCounts counts;
  double magnetic_s = 0, rest_s = 0;
  long samples = 0;
  double mean_rms = 0, mean_max = 0, mean_wall = 0, max_rms = 0, max_max = 0, max_wall = 0;
  double mean_live_rms = 0, mean_live_max = 0, max_live_rms = 0; // held dipoles, live geometry
};

// The counts accumulated between two readings of a term's counters.
MagneticForceTerm::RefreshCounts since(const MagneticForceTerm::RefreshCounts &now,
                                       const MagneticForceTerm::RefreshCounts &then)
{
  using Counts = MagneticForceTerm::RefreshCounts;
  const std::array<long Counts::*, 11> counts = {&Counts::first, &Counts::interval, &Counts::moved,
                                                 &Counts::zero_field, &Counts::region_beads, &Counts::rebuilds,
                                                 &Counts::moved_lists, &Counts::moved_region, &Counts::set_changed,
                                                 &Counts::admitted, &Counts::admit_region_beads};
  const std::array<double Counts::*, 10> seconds = {&Counts::full_s, &Counts::local_s, &Counts::check_s,
                                                    &Counts::lists_s, &Counts::tensors_s, &Counts::far_s,
                                                    &Counts::sweeps_s, &Counts::forces_s, &Counts::admit_s,
                                                    &Counts::live_s};
  Counts d = now;
  for (const auto m : counts)
    d.*m -= then.*m;
  for (const auto m : seconds)
    d.*m -= then.*m;
  return d;
}

// One run of `c` (fresh, or from `restart`) to its dem.duration with the magnetics in `mode`.
ModeResult run_mode(Case c, const std::string &mode, const std::string &restart, const fs::path &dir,
                    std::size_t wall, double sample, double t0)
{
  // A mode may carry variants of knobs without a case key, side by side in the same run:
  // "relative+R1+S0.6" = relative with local_region_limit 1 and the magnetic lists' skin 0.6
  // diameters; "+X0" = defer_exchange off (a full evaluation at every particle exchange);
  // "+A1" / "+A0" = admit_exchange on / off (admission without a rebuild at the next step);
  // "+Q0" = no quiet steps, "+T0" = no held steps inside the engine's team, "+O0" = the compact
  // order as the exchanges leave it (not following the engine's);
  // "+F0.1" = magnetic_staleness 0.1; "+H1" = hold the dipoles (the close pairs' forces live),
  // with "+L3" live pairs within 3 mean radii (+ skin), "+N10" their changes every 10 steps;
  // "+P20" = magnetic_refresh 20 us (so that rows with different intervals share one run).
  const std::vector<std::string> parts = split(mode, '+');
  c.dem.magnetic_staleness_mode = parts[0];
  for (std::size_t k = 1; k < parts.size(); ++k)
    if (parts[k][0] == 'P')
      c.dem.magnetic_refresh = std::atof(parts[k].c_str() + 1) * 1e-6;
  dem::RunOptions options;
  options.restart_file = restart;
  // Every mode turns from the same checkpoint, written under another mode on purpose: its
  // magnetic state is not restored (other settings) and the first step evaluates afresh.
  options.restart_anyway = true;
  options.output_dir = (dir / ("run_" + mode)).string();
  options.progress_interval = 1e9;
  std::ostringstream log;
  dem::DemRun run(c, options, log);
  auto &system = run.system();
  const AppliedMagneticField field =
    c.applied_field.kind == AppliedField::Kind::roller
      ? AppliedMagneticField::for_case(c, field::magnetic_grid_path(c))
      : AppliedMagneticField::from_settings(c.applied_field);
  MagneticSettings settings = MagneticSettings::from_case(c.dem);
  // Knobs without a case key, for exploring (environment, unset = the library defaults).
  if (const char *v = std::getenv("MAGBRUSH_LOCAL_REGION_LIMIT"))
    settings.local_region_limit = std::atof(v);
  if (const char *v = std::getenv("MAGBRUSH_LOCAL_BATCH"))
    settings.local_batch_fraction = std::atof(v);
  if (const char *v = std::getenv("MAGBRUSH_ABSOLUTE_FACTOR"))
    settings.absolute_factor = std::atof(v);
  if (const char *v = std::getenv("MAGBRUSH_MAGNETIC_SKIN"))
    settings.skin_fraction = std::atof(v);
  for (std::size_t k = 1; k < parts.size(); ++k)
  {
    const double v = std::atof(parts[k].c_str() + 1);
    if (parts[k][0] == 'R')
      settings.local_region_limit = v;
    else if (parts[k][0] == 'S')
      settings.skin_fraction = v;
    else if (parts[k][0] == 'X')
      settings.defer_exchange = v != 0.0;
    else if (parts[k][0] == 'A')
      settings.admit_exchange = v != 0.0;
    else if (parts[k][0] == 'F')
      settings.staleness_fraction = v;
    else if (parts[k][0] == 'H')
      settings.hold_dipoles = v != 0.0;
    else if (parts[k][0] == 'L')
      settings.live_pair_radius = v;
    else if (parts[k][0] == 'N')
      settings.live_pair_steps = static_cast<int>(v);
    else if (parts[k][0] == 'Q' || parts[k][0] == 'T' || parts[k][0] == 'O' || parts[k][0] == 'P')
      continue; // (the term's switches below; the interval above)
    else
      throw std::runtime_error("unknown mode variant " + parts[k]);
  }
  auto owned = std::make_unique<MagneticForceTerm>(c, settings, field, system.box().length);
  // "+Q0": no quiet steps (every held step in the team checks); "+T0": no held steps inside
  // the engine's team at all.
  for (std::size_t k = 1; k < parts.size(); ++k)
    if (parts[k][0] == 'Q')
      owned->set_quiet_steps(std::atof(parts[k].c_str() + 1) != 0.0);
    else if (parts[k][0] == 'T')
      owned->set_held_steps_in_team(std::atof(parts[k].c_str() + 1) != 0.0);
    else if (parts[k][0] == 'O')
      owned->set_follow_engine_order(std::atof(parts[k].c_str() + 1) != 0.0);
  const MagneticForceTerm *term = owned.get();
  system.replace_force_term("magnetic dipoles", std::move(owned));
  auto probe = std::make_unique<HeldForceError>(c, term, settings, field, system.box().length, wall, sample);
  const HeldForceError *error = probe.get();
  run.add_measurement(std::move(probe));
  run.run();
  ModeResult r;
  r.mode = mode;
  // The counters from the first sample on: a term restored from the settling run's checkpoint
  // (the mode it was written under) brings that run's counts along. The cold first evaluation
  // is this run's only when the term started afresh.
  const double from = error->started_ ? error->start_time_ : t0;
  r.simulated_ms = (c.dem.duration - from) * 1e3;
  r.full = term->evaluations() - error->start_full_;
  r.local = term->local_refreshes() - error->start_local_;
  r.counts = since(term->refresh_counts(), error->start_counts_);
  r.counts.cold_s = term->restored_state() ? 0.0 : term->refresh_counts().cold_s;
  const dem::PhaseTimes p = system.phase_times();
  for (std::size_t k = 0; k < system.force_terms().size(); ++k)
    (system.force_terms()[k].get() == term ? r.magnetic_s : r.rest_s) += p.terms[k];
  r.rest_s += p.neighbour + p.particle_contacts + p.wall_contacts + p.integrate + p.guards;
  r.samples = error->samples_;
  if (r.samples > 0)
  {
    r.mean_rms = error->sum_rms_ / r.samples;
    r.mean_max = error->sum_max_ / r.samples;
    r.mean_wall = error->sum_wall_ / r.samples;
    r.mean_live_rms = error->sum_live_rms_ / r.samples;
    r.mean_live_max = error->sum_live_max_ / r.samples;
  }
  r.max_live_rms = error->max_live_rms_;
  r.max_rms = error->max_rms_;
  r.max_max = error->max_max_;
  r.max_wall = error->max_wall_;
  return r;
}

void print(const char *title, const char *wall_name, const std::vector<ModeResult> &results)
{
  std::printf("\n%s\n\n", title);
  std::printf("| staleness mode | full evaluations / ms (interval, moved, first) | local refreshes / ms (mean region) | "
              "held-force error RMS: mean / max | worst bead: mean / max | %s force: mean / max | "
              "magnetic term [s]: full / local / checks / total | rest of the step [s] | magnetics / rest (without the cold first evaluation) |\n",
              wall_name);
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const ModeResult &r : results)
    std::printf("| %s | %.0f (%ld, %ld, %ld) | %.0f (%.0f) | %.2e / %.2e | %.2e / %.2e | %.2e / %.2e | %.2f / %.2f / %.2f / %.2f | %.2f | %+.0f %% |\n",
                r.mode.c_str(), r.full / r.simulated_ms, r.counts.interval, r.counts.moved, r.counts.first,
                r.local / r.simulated_ms, r.local ? double(r.counts.region_beads) / r.local : 0.0, r.mean_rms,
                r.max_rms, r.mean_max, r.max_max, r.mean_wall, r.max_wall, r.counts.full_s, r.counts.local_s,
                r.counts.check_s, r.magnetic_s, r.rest_s, 100.0 * (r.magnetic_s - r.counts.cold_s) / r.rest_s);
  std::printf("\nFull evaluations, phases summed [s]:\n\n| staleness mode | evaluations | list rebuilds | exchanges joined | moved: lists expired / region too large | the cold first one | lists/cells | "
              "applied field + tensors | far field | sweeps | forces |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const ModeResult &r : results)
    std::printf("| %s | %ld | %ld | %ld | %ld / %ld | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n", r.mode.c_str(), r.full, r.counts.rebuilds,
                r.counts.set_changed, r.counts.moved_lists, r.counts.moved_region, r.counts.cold_s, r.counts.lists_s, r.counts.tensors_s, r.counts.far_s, r.counts.sweeps_s, r.counts.forces_s);
  std::printf("\nHolding the dipoles instead of the forces (the held dipoles' forces at the current positions, "
              "InducedDipoles::forces_of_dipoles) against the same fresh solve:\n\n| staleness mode | held forces: RMS mean / max | "
              "held dipoles, live geometry: RMS mean / max | worst bead: held forces / held dipoles (means) | "
              "the term's live close pairs (hold_dipoles) [s] |\n|---|---|---|---|---|\n");
  for (const ModeResult &r : results)
    std::printf("| %s | %.2e / %.2e | %.2e / %.2e | %.2e / %.2e | %.2f |\n", r.mode.c_str(), r.mean_rms, r.max_rms,
                r.mean_live_rms, r.max_live_rms, r.mean_max, r.mean_live_max, r.counts.live_s);
  std::printf("\nExchanges admitted without a full evaluation (admit_exchange):\n\n| staleness mode | admissions | wall [s] | mean region |\n|---|---|---|---|\n");
  for (const ModeResult &r : results)
    std::printf("| %s | %ld | %.2f | %.0f |\n", r.mode.c_str(), r.counts.admitted, r.counts.admit_s,
                r.counts.admitted ? double(r.counts.admit_region_beads) / r.counts.admitted : 0.0);
  std::printf("\n(%ld samples per mode over %.3g ms)\n", results.empty() ? 0L : results[0].samples,
              results.empty() ? 0.0 : results[0].simulated_ms);
  std::fflush(stdout);
}


double refresh_override_us = 0.0; // > 0: dem.magnetic_refresh for every run

// quick = the placed quick scene (cases/kawamoto_nip.yaml, 4,300 beads in a 1 mm slab),
// otherwise the reduced regression scene.
void nip(const fs::path &dir, double flow_us, double sample_us, const std::vector<std::string> &modes,
         bool quick)
{
  const std::string file = std::string(MAGBRUSH_SOURCE_DIR) +
                           (quick ? "/cases/kawamoto_nip.yaml" : "/tests/scenes/nip/kawamoto_nip_reduced.yaml");
  std::vector<std::string> overrides = {
    "dem.magnetic_far_field=cell_multipole", "field.output_dir=" + (dir / "fields").string(),
    "output.directory=" + dir.string(), "dem.output_interval=0 s"};
  if (quick) // as tools/run
    for (const char *o : {"populations.carrier.count=4300",
                          "populations.carrier.insert_box=[[12.1mm,-2.5mm,0mm],[13.0mm,1.5mm,1mm]]",
                          "dem.time_step=40ns"})
      overrides.push_back(o);
  std::string cmd = "cd '" + dir.string() + "' && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 '" +
                    std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush' field '" + file + "'";
  for (const auto &o : overrides)
    cmd += " --set '" + o + "'";
  cmd += " > field.log 2>&1";
  if (std::system(cmd.c_str()) != 0)
  {
    std::printf("nip: `magbrush field` failed (see %s/field.log): is magbrush-field built?\n", dir.c_str());
    return;
  }
  Case c = load_case(file, overrides);
  if (refresh_override_us > 0.0)
    c.dem.magnetic_refresh = refresh_override_us * 1e-6;
  const double settle = c.dem.settle_time;
  // Settle once (the walls at rest), then every mode turns from the same checkpoint.
  Case settling = c;
  settling.dem.duration = settle;
  const double t_wall = omp_get_wtime();
  run_mode(settling, "relative", "", dir / "settle", 1, 1e9, 0.0);
  const std::string checkpoint = (dir / "settle" / "run_relative" / "checkpoint.bin").string();
  std::printf("nip: settled %.3g ms in %.0f s\n", settle * 1e3, omp_get_wtime() - t_wall);
  c.dem.duration = settle + flow_us * 1e-6;
  std::vector<ModeResult> results;
  for (const auto &mode : modes)
    results.push_back(run_mode(c, mode, checkpoint, dir, 1, sample_us * 1e-6, settle));
  char title[512];
  std::snprintf(title, sizeof title,
                "Flowing nip (%s, far field cell_multipole, %zu beads): "
                "%.3g ms of turning after %.3g ms of settling, step %.3g ns, refresh %.3g us, staleness %.3g",
                quick ? "cases/kawamoto_nip.yaml, the placed quick scene" : "tests/scenes/nip/kawamoto_nip_reduced.yaml",
                static_cast<std::size_t>(c.populations[0].count), flow_us * 1e-3, settle * 1e3, c.dem.time_step * 1e9,
                c.dem.magnetic_refresh * 1e6, c.dem.magnetic_staleness);
  print(title, "drum", results);
}

double descent_at_us = 2500.0, descent_us = 300.0;

void compression(const fs::path &dir, double until_us, double sample_us, const std::vector<std::string> &modes)
{
  const std::string file = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_brush_compression.yaml";
  const std::vector<std::string> square = {
    "dem.periodic_length_x=1 mm", "dem.periodic_length_y=1 mm", "populations.carrier.count=1105",
    "populations.carrier.insert_box=[[0 mm, 0 mm, 0.03 mm], [1 mm, 1 mm, 0.9 mm]]",
    "output.directory=" + dir.string(), "dem.output_interval=0 s"};
  Case c = load_case(file, square);
  if (refresh_override_us > 0.0)
    c.dem.magnetic_refresh = refresh_override_us * 1e-6;
  // (1) The brush forming: insertion, field ramp, hold; every mode from the start.
  c.dem.duration = until_us * 1e-6;
  std::vector<ModeResult> results;
  for (const auto &mode : modes)
    results.push_back(run_mode(c, mode, "", dir, 0, sample_us * 1e-6, 0.0));
  char title[512];
  std::snprintf(title, sizeof title,
                "Compression brush forming (cases/kawamoto_brush_compression.yaml on 1 x 1 mm², 1,105 beads): "
                "0 ... %.3g ms (field ramp to 130 mT over 0.3 ms, then held), step %.3g ns, refresh %.3g us",
                until_us * 1e-3, c.dem.time_step * 1e9, c.dem.magnetic_refresh * 1e6);
  print(title, "stage", results);
  // (2) The plate compressing it (0.1 m/s from 0.5 ms): run once to descent_at, then every
  //     mode the same window from that checkpoint. The plate force is the quantity measured.
  if (descent_us <= 0.0)
    return;
  c.dem.duration = descent_at_us * 1e-6;
  const double t_wall = omp_get_wtime();
  run_mode(c, "relative", "", dir / "descent", 1, 1e9, 0.0);
  const std::string checkpoint = (dir / "descent" / "run_relative" / "checkpoint.bin").string();
  std::printf("compression: ran to %.3g ms in %.0f s\n", descent_at_us * 1e-3, omp_get_wtime() - t_wall);
  c.dem.duration = (descent_at_us + descent_us) * 1e-6;
  results.clear();
  for (const auto &mode : modes)
    results.push_back(run_mode(c, mode, checkpoint, dir, 1, sample_us * 1e-6, descent_at_us * 1e-6));
  std::snprintf(title, sizeof title,
                "Compression brush under the descending plate (the same square): %.3g ... %.3g ms, plate gap "
                "%.3g ... %.3g mm",
                descent_at_us * 1e-3, (descent_at_us + descent_us) * 1e-3, 1.2 - 0.1 * (descent_at_us * 1e-3 - 0.5),
                1.2 - 0.1 * ((descent_at_us + descent_us) * 1e-3 - 0.5));
  print(title, "plate", results);
}

// A fed scene: the doctor-blade regulation cell (cases/kweon_regulation.yaml: developer fed by
// the sump inflow every 2 us onto the turning sleeve, piled in front of the blade, sheared
// through its gap, removed by the outflow; the wall force is the sleeve's) or the fed nip
// (cases/kawamoto_nip_fed.yaml: the layer supplied by the sleeve through the development gap;
// the wall force is the drum's). Run (or take) the state at `until`, then every mode runs the
// same `flow` window from it. Environment, to reuse a state written by
// `magbrush run <case> --set dem.duration=...` (or `magbrush-dem`):
// MAGBRUSH_BENCH_<SCENE>_RESTART (its dem/checkpoint.bin; `until` must be its time) and
// MAGBRUSH_BENCH_<SCENE>_FIELDS (its field.output_dir), <SCENE> = REGULATION, NIP_FED or
// FULL_ROLLER.
struct FedScene
{
  const char *case_file;  // under the source tree
  const char *env_prefix; // MAGBRUSH_BENCH_<prefix>_RESTART / _FIELDS
  const char *label;      // the table's title
  std::size_t wall;       // whose force error is reported
  const char *wall_name;
};

const FedScene regulation_scene{"cases/kweon_regulation.yaml", "REGULATION",
                                "Regulation cell (cases/kweon_regulation.yaml)", 0, "sleeve"};
const FedScene full_roller_scene{"cases/kweon_full_roller.yaml", "FULL_ROLLER",
                                 "Full roller (cases/kweon_full_roller.yaml)", 0, "sleeve"};
const FedScene fed_nip_scene{"cases/kawamoto_nip_fed.yaml", "NIP_FED",
                             "Fed nip (cases/kawamoto_nip_fed.yaml)", 1, "drum"};

void fed(const FedScene &scene, const fs::path &dir, double until_us, double flow_us, double sample_us,
         const std::vector<std::string> &modes)
{
  const std::string file = std::string(MAGBRUSH_SOURCE_DIR) + "/" + scene.case_file;
  const std::string prefix = std::string("MAGBRUSH_BENCH_") + scene.env_prefix;
  const char *fields = std::getenv((prefix + "_FIELDS").c_str());
  const char *restart = std::getenv((prefix + "_RESTART").c_str());
  std::vector<std::string> overrides = {
    "field.output_dir=" + (fields ? std::string(fields) : (dir / "fields").string()),
    "output.directory=" + dir.string(), "dem.output_interval=0 s"};
  if (!fields)
  {
    std::string cmd = "cd '" + dir.string() + "' && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 '" +
                      std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush' field '" + file + "'";
    for (const auto &o : overrides)
      cmd += " --set '" + o + "'";
    if (std::system((cmd + " > field.log 2>&1").c_str()) != 0)
    {
      std::printf("%s: `magbrush field` failed (see %s/field.log)\n", scene.env_prefix, dir.c_str());
      return;
    }
  }
  Case c = load_case(file, overrides);
  if (refresh_override_us > 0.0)
    c.dem.magnetic_refresh = refresh_override_us * 1e-6;
  const double start = until_us * 1e-6;
  std::string checkpoint = restart ? std::string(restart) : std::string();
  if (checkpoint.empty())
  {
    Case first = c;
    first.dem.duration = start;
    const double t_wall = omp_get_wtime();
    run_mode(first, "relative", "", dir / "first", 0, 1e9, 0.0);
    checkpoint = (dir / "first" / "run_relative" / "checkpoint.bin").string();
    std::printf("%s: ran to %.3g ms in %.0f s\n", scene.env_prefix, start * 1e3, omp_get_wtime() - t_wall);
  }
  c.dem.duration = start + flow_us * 1e-6;
  std::vector<ModeResult> results;
  for (const auto &mode : modes)
    results.push_back(run_mode(c, mode, checkpoint, dir, scene.wall, sample_us * 1e-6, start));
  char title[512];
  std::snprintf(title, sizeof title,
                "%s: %.3g ... %.3g ms, step %.3g ns, refresh %.3g us, staleness %.3g, inflow every %.3g us",
                scene.label, start * 1e3, c.dem.duration * 1e3, c.dem.time_step * 1e9, c.dem.magnetic_refresh * 1e6,
                c.dem.magnetic_staleness, c.flow.interval * 1e6);
  print(title, scene.wall_name, results);
}

} // namespace

int main(int argc, char **argv)
{
  const std::string scene = argc > 1 ? argv[1] : "both";
  const double flow_us = argc > 2 ? std::atof(argv[2]) : 300.0;
  const double until_us = argc > 3 ? std::atof(argv[3]) : 500.0;
  const double sample_us = argc > 4 ? std::atof(argv[4]) : 2.0;
  const std::vector<std::string> modes = split(argc > 5 ? argv[5] : "absolute,local,relative");
  refresh_override_us = argc > 6 ? std::atof(argv[6]) : 0.0;
  descent_at_us = argc > 7 ? std::atof(argv[7]) : 2500.0;
  descent_us = argc > 8 ? std::atof(argv[8]) : 300.0;
  const fs::path dir = fs::temp_directory_path() / ("magbrush_bench_staleness_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::printf("# bench_magnetic_staleness: %d OpenMP threads\n", omp_get_max_threads());
  try
  {
    if (scene == "nip" || scene == "both")
      nip(dir, flow_us, sample_us, modes, false);
    if (scene == "nip_quick")
      nip(dir, flow_us, sample_us, modes, true);
    if (scene == "compression" || scene == "both")
      compression(dir, until_us, sample_us, modes);
    if (scene == "regulation")
      fed(regulation_scene, dir, until_us, flow_us, sample_us, modes);
    if (scene == "nip_fed")
      fed(fed_nip_scene, dir, until_us, flow_us, sample_us, modes);
    if (scene == "full_roller")
      fed(full_roller_scene, dir, until_us, flow_us, sample_us, modes);
  }
  catch (const std::exception &e)
  {
    std::printf("bench_magnetic_staleness: %s\n", e.what());
  }
  fs::remove_all(dir);
  return 0;
}
