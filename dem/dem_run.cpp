// A whole DEM run with its outputs (see dem_run.h).
#include "dem/dem_run.h"

#include "dem/run_summary.h"
#include "dem/particle_flow.h"
#include "dem/snapshot_outputs.h"
#include "dem/openmp_waiting.h"
#include "dem/restart_check.h"

#include "case/case_hash.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <stdexcept>

namespace magbrush::dem {

namespace fs = std::filesystem;

DemRun::DemRun(const Case &c, const RunOptions &options, std::ostream &log)
    : case_(c), options_(options), log_(log)
{
  const int threads = options_.threads > 0 ? options_.threads : case_.dem.threads;
  if (threads > 0)
    omp_set_num_threads(threads);
  out_dir_ = options_.output_dir.empty() ? (fs::path(case_.output.directory) / "dem").string() : options_.output_dir;
  fs::create_directories(out_dir_);
  if (options_.resume)
    take_own_checkpoint();
  system_ = std::make_unique<DemSystem>(case_);
  force_terms_ = add_case_force_terms(*system_, case_);
  identity_.case_hash = case_hash(case_);
  identity_.inputs = case_inputs(case_);
  if (case_.flow.inflow() || case_.flow.outflow() || carried_toner_population(case_) >= 0)
    system_->set_particle_exchange(std::make_unique<ParticleFlow>(case_, *system_));
}

std::string DemRun::checkpoint_path() const { return (fs::path(out_dir_) / "checkpoint.bin").string(); }

// The checkpoint must be the state of this case: only run control may differ, unless the user
// said --restart-anyway (restart_check.h). The file's checksum is verified on the way.
std::string DemRun::check_restart_case() const
{
  const CheckpointIdentity written = CheckpointReader(options_.restart_file).identity();
  const std::vector<CaseDifference> differences = case_differences(written, identity_);
  std::vector<CaseDifference> scene, control, added;
  for (const CaseDifference &d : differences)
    (d.run_control ? control : d.added_at_default ? added : scene).push_back(d);
  if (!control.empty())
    log_ << "restart: run control changed since the checkpoint (the state continues):\n" << describe(control);
  if (!added.empty())
    log_ << "restart: keys newer than the checkpoint, at their defaults (what the program that wrote it did):\n"
         << describe(added);
  // The measurements continue the checkpoint's only when they measure as they did.
  std::string afresh;
  for (const CaseDifference &d : control)
    if (is_measurement_key(d.key))
      afresh = d.key + " changed";
  if (scene.empty())
    return afresh;
  if (!options_.restart_anyway)
    throw std::runtime_error("checkpoint '" + options_.restart_file + "' was written by case hash " + written.case_hash +
                             ", this case has " + identity_.case_hash + "; they differ in " +
                             std::to_string(scene.size()) + (scene.size() == 1 ? " key" : " keys") +
                             " beyond run control:\n" + describe(scene) +
                             "restart with the case that wrote it, or pass --restart-anyway to continue its "
                             "state under this case (the run is then not a continuation of the one that wrote it)");
  log_ << "restart anyway (--restart-anyway): the checkpoint's case differs in\n" << describe(scene);
  return "the scene changed (--restart-anyway)";
}

// After the engine's state, in the same checksummed file:
//   "measurements", their count, then per measurement its name and its state as one block
// (a block is read through its own stream, so that a measurement that reads more or less
// than it wrote is caught at its own door rather than misreading the next one). The name
// carries the state's layout from version 2 on ("developer mass per area (state v2)"), so a
// block in another layout reads as another measurement: started afresh, not misread.
namespace {
std::string state_label(const Measurement &m)
{
  const int version = m.state_version();
  return version == 1 ? std::string(m.name()) : std::string(m.name()) + " (state v" + std::to_string(version) + ")";
}
} // namespace

void DemRun::write_measurement_states(StateOut &out) const
{
  out.put_string("measurements");
  out.put<std::uint64_t>(measurements_.size());
  for (const auto &m : measurements_)
  {
    MemoryStateOut block;
    m->write_state(block);
    out.put_string(state_label(*m));
    out.put_string(block.bytes());
  }
}

void DemRun::read_measurement_states(StateIn &in, const std::string &afresh_because)
{
  auto afresh = [this](const std::string &why) {
    if (!measurements_.empty())
      log_ << "restart: the measurements start afresh at the restart (" << why
           << "): their files cover the continuation only\n";
  };
  if (in.remaining() == 0)
    return afresh("the checkpoint holds none: written by a magbrush that kept them out of checkpoints");
  if (in.get_string() != "measurements")
    in.fail("is corrupt (what follows the engine's state is not the measurements)");
  const auto n = in.get<std::uint64_t>();
  std::vector<std::pair<std::string, std::string>> blocks;
  for (std::uint64_t k = 0; k < n && in.remaining() > 0; ++k)
  {
    std::string name = in.get_string();
    blocks.emplace_back(std::move(name), in.get_string());
  }
  if (blocks.size() != n)
    in.fail("is corrupt (fewer measurements than it says it holds)");
  if (!afresh_because.empty())
    return afresh(afresh_because);
  if (blocks.size() != measurements_.size())
    return afresh("the checkpoint holds other measurements than this run makes");
  for (std::size_t k = 0; k < blocks.size(); ++k)
    if (blocks[k].first != state_label(*measurements_[k]))
      return afresh(blocks[k].first.rfind(measurements_[k]->name(), 0) == 0
                        ? "the checkpoint keeps the " + std::string(measurements_[k]->name()) +
                              " in another layout than this magbrush's ('" + state_label(*measurements_[k]) + "')"
                        : "the checkpoint holds other measurements than this run makes");
  for (std::size_t k = 0; k < blocks.size(); ++k)
  {
    MemoryStateIn block(std::move(blocks[k].second),
                        "checkpoint '" + options_.restart_file + "', measurement '" + blocks[k].first + "',");
    measurements_[k]->read_state(block);
    if (block.remaining() != 0)
      block.fail("holds more than the measurement reads: restart with the magbrush that wrote it");
  }
  if (!measurements_.empty())
    log_ << "restart: the measurements continue from the checkpoint (their files cover the whole run)\n";
}

// Atomically, keeping the one before it.
void DemRun::write_checkpoint()
{
  if (system_->step_count() == last_checkpoint_step_)
    return; // (the end fell on an interval: written already)
  last_checkpoint_step_ = system_->step_count();
  const std::string path = checkpoint_path();
  keep_previous_checkpoint(path);
  system_->write_checkpoint(path, identity_, [this](StateOut &out) { write_measurement_states(out); });
  ++checkpoints_;
  char line[256];
  std::snprintf(line, sizeof line, "checkpoint at t = %.6g s (step %ld): %s\n", system_->time(),
                system_->step_count(), path.c_str());
  log_ << line;
  log_.flush();
}

void DemRun::log_setup() const
{
  const DemSystem &s = *system_;
  char line[512];
  log_ << "magbrush-dem: case '" << case_.name << "', " << s.particles().size() << " particles, "
       << s.walls().size() << " walls, " << omp_get_max_threads() << " OpenMP threads\n";
  if (omp_get_max_threads() > 1)
    log_ << "  idle threads: " << openmp_waiting_description() << "\n";
  for (std::size_t w = 0; w < s.walls().size(); ++w)
    log_ << "  wall " << w << ": " << s.walls().name(w) << " (material " << s.walls().material(w) << ")\n";
  const auto &b = s.box().length;
  std::snprintf(line, sizeof line, "  periodic lengths x/y/z: %g / %g / %g m (0 = walls or open)\n", b[0], b[1], b[2]);
  log_ << line;
  log_ << "  contact law: Hertz + Voigt damping, Mindlin tangential + Coulomb, rolling friction (Kawamoto A2-A7)\n"
       << s.contact_table().describe();
  const auto &st = s.stable_time_step_info();
  // A restart keeps the checkpoint's step (time = step count x step), whatever the case says now.
  const char *origin = !options_.restart_file.empty() ? "the checkpoint's"
                       : case_.dem.time_step > 0      ? "user"
                                                      : "automatic";
  std::snprintf(line, sizeof line,
                "  time step %.4g s (%s; stable limit %.4g s set by the %s; Rayleigh %.4g s, Hertz t_c/10 %.4g s)\n",
                s.time_step(), origin, st.limit, st.limiting.c_str(), st.rayleigh, st.hertz);
  log_ << line;
  if (const TonerSubsteps &sub = s.toner_substeps(); sub.on())
  {
    std::snprintf(line, sizeof line,
                  "  toner in %d substeps of %.4g s (the step above is the carriers'; their own limit %.4g s, set by "
                  "the %s)\n",
                  sub.substeps, sub.substep, sub.carrier_limit, sub.carrier_limiting.c_str());
    log_ << line;
  }
  std::snprintf(line, sizeof line, "  Verlet skin %.3g m\n", s.skin());
  log_ << line;
  // The force list of the step, in the order the forces are added.
  log_ << "  force terms on: contacts";
  for (const auto &t : s.force_terms())
    log_ << ", " << t->name();
  log_ << "\n";
  for (const ForceTermChoice &choice : force_terms_)
    if (!choice.on)
      log_ << "  force term off: " << choice.name << " (" << choice.reason << ")\n";
  // Where the carriers' applied field comes from: a uniform field costs no grid lookup.
  bool magnetic = false;
  for (const ForceTermChoice &choice : force_terms_)
    magnetic = magnetic || (choice.on && choice.name == "magnetic dipoles");
  if (magnetic && case_.applied_field.kind == AppliedField::Kind::uniform)
  {
    std::snprintf(line, sizeof line,
                  "  applied magnetic field: uniform, |B| up to %.4g T, in closed form (no grid lookups)\n",
                  case_.applied_field.uniform_magnitude);
    log_ << line;
  }
  else if (magnetic)
    log_ << "  applied magnetic field: the roller's stored grid, interpolated at every carrier\n";
  if (const auto *flow = dynamic_cast<const ParticleFlow *>(s.particle_exchange()))
  {
    const FlowSettings &f = case_.flow;
    if (flow->source())
    {
      std::snprintf(line, sizeof line,
                    "  inflow: %.4g kg/m^2 of developer onto the sleeve past %.4g deg, within %.3g mm of it, "
                    "every %ld steps (%.4g kg/s at full sleeve speed)\n",
                    f.inflow_areal_mass, f.inflow_angle * 180.0 / M_PI, f.inflow_layer_height * 1e3,
                    flow->interval_steps(),
                    f.inflow_areal_mass * case_.sleeve->surface_speed() * s.box().length[2]);
      log_ << line;
      if (flow->source()->prefilled_count() > 0)
      {
        std::snprintf(line, sizeof line,
                      "  prefilled: %ld particles (%.4g kg) of that layer over %.4g deg downstream of the entry at the start\n",
                      flow->source()->prefilled_count(), flow->source()->prefilled_mass(),
                      f.inflow_prefill_arc * 180.0 / M_PI);
        log_ << line;
        const ParticleSource &source = *flow->source();
        if (source.prefill_thinned_mass() > 0.0)
        {
          std::snprintf(line, sizeof line,
                        "  prefill thinned where the layer finds no room: %.4g kg of carriers not placed; past its "
                        "narrowest place (%.4g deg) the layer holds %.3g of the fed mass per area\n",
                        source.prefill_thinned_mass(), source.prefill_narrowest_angle() * 180.0 / M_PI,
                        source.prefill_passed_fraction());
          log_ << line;
        }
      }
    }
    if (flow->sink())
    {
      std::snprintf(line, sizeof line, "  outflow: sector %.4g deg wide from %.4g deg; beyond %.4g mm from the axis%s\n",
                    f.outflow_width * 180.0 / M_PI, f.outflow_angle * 180.0 / M_PI, f.outflow_radius * 1e3,
                    f.outflow_radius > 0.0 ? "" : " (off)");
      log_ << line;
    }
  }
  if (!measurements_.empty())
  {
    log_ << "  measurements:";
    for (const auto &m : measurements_)
      log_ << " " << m->name() << (&m == &measurements_.back() ? "" : ",");
    log_ << "\n";
  }
  log_.flush();
}

void DemRun::log_timings(double wall) const
{
  const DemSystem &s = *system_;
  const PhaseTimes &t = s.phase_times();
  auto row = [&](const char *name, double v) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-22s %10.3f s  %5.1f %%\n", name, v, wall > 0 ? 100.0 * v / wall : 0.0);
    log_ << line;
  };
  log_ << "time per phase (wall clock):\n";
  row("neighbour list", t.neighbour);
  row("particle contacts", t.particle_contacts);
  row("wall contacts", t.wall_contacts);
  if (const TonerSubsteps &sub = s.toner_substeps(); sub.on())
  {
    row("toner substeps", t.substeps);
    log_ << "      (" << sub.substeps << " substeps a step; at the end " << sub.movers.size() << " toner particles in "
         << sub.pair.size() << " listed pairs, " << sub.dragged.size() << " carriers among their partners)\n";
  }
  for (std::size_t k = 0; k < s.force_terms().size(); ++k)
  {
    row(s.force_terms()[k]->name(), t.terms[k]);
    const std::string note = s.force_terms()[k]->cost_note();
    if (!note.empty())
      log_ << "      (" << note << ")\n";
  }
  row("integration", t.integrate);
  row("guards", t.guards);
  double rest = wall - t.neighbour - t.particle_contacts - t.wall_contacts - t.integrate - t.guards - t.substeps;
  for (double v : t.terms)
    rest -= v;
  row("output and other", rest);
  row("total", wall);
}

void DemRun::write_measurements(bool so_far) const
{
  for (const auto &m : measurements_)
  {
    m->write(out_dir_);
    if (!so_far)
      log_ << "measurement '" << m->name() << "' written to " << out_dir_ << "\n";
  }
  write_run_summary(out_dir_, measurements_, case_.statistics);
}

// --resume: the folder's own checkpoint becomes the restart file. It is read whole before the
// run writes its first checkpoint over it (the writer renames a finished file into place).
void DemRun::take_own_checkpoint()
{
  if (!options_.restart_file.empty())
    throw std::invalid_argument("resume continues from the output folder's own checkpoint: give it without a "
                                "restart file (--restart names another one)");
  const fs::path own = fs::path(out_dir_) / "checkpoint.bin";
  if (fs::exists(own))
  {
    options_.restart_file = own.string();
    log_ << "resume: continuing from this folder's checkpoint '" << own.string() << "'\n";
  }
  else
    log_ << "resume: no checkpoint in '" << out_dir_ << "' yet: the run starts from the beginning\n";
}

void DemRun::run()
{
  DemSystem &s = *system_;
  SnapshotOutputs snapshots(out_dir_, case_.output);
  const std::string csv = (fs::path(out_dir_) / "time_series.csv").string();
  const bool restart = !options_.restart_file.empty();
  if (restart)
  {
    const std::string measurements_afresh = check_restart_case();
    s.read_checkpoint(options_.restart_file,
                      [&](StateIn &in) { read_measurement_states(in, measurements_afresh); });
    log_ << "restarted from '" << options_.restart_file << "' at step " << s.step_count() << ", t = " << s.time()
         << " s\n";
  }
  else
  {
    s.insert_particles();
    s.initialize();
  }
  TimeSeriesWriter series(csv, s);
  log_setup();
  const double t_wall0 = omp_get_wtime();
  if (restart)
  {
    snapshots.resume(s.time());
    series.resume(s.step_count());
  }
  else if (case_.dem.settle_time > 0.0)
  {
    log_ << "settling for " << case_.dem.settle_time << " s with the walls at rest ...\n";
    s.settle(case_.dem.settle_time);
  }

  const double dt = s.time_step();
  auto every = [dt](double interval) { return interval > 0.0 ? std::max(1L, std::lround(interval / dt)) : 0L; };
  const long end_step = std::lround(case_.dem.duration / dt);
  const long out_every = every(case_.dem.output_interval);
  const long ckpt_every = every(case_.dem.checkpoint_interval);
  const long series_every = out_every > 0 ? std::max(1L, out_every / 10) : std::max(1L, end_step / 1000);
  if (!restart)
  {
    series.record(s);
    snapshots.write(s);
  }
  const long start_step = s.step_count();
  // Measurement k samples every sample_every[k] steps (at least every step).
  std::vector<long> sample_every;
  for (const auto &m : measurements_)
    sample_every.push_back(std::max(1L, std::lround(m->interval() / dt)));
  double last_progress = omp_get_wtime();
  // Wall-clock checkpoints: a checkpoint leaves the run's bits alone, so taking one at a
  // moment set by the clock keeps the results independent of the machine's speed.
  const double wall_every = case_.dem.checkpoint_wall_interval;
  double last_checkpoint_wall = omp_get_wtime();
  try
  {
    while (s.step_count() < end_step)
    {
      // Run in one go up to the next step where something is recorded (the team of threads
      // stays together in between), at most 1000 steps so that the progress line stays live.
      long next = std::min(end_step, s.step_count() + 1000);
      auto upto_multiple = [&next, &s](long every) {
        if (every > 0)
          next = std::min(next, (s.step_count() / every + 1) * every);
      };
      upto_multiple(series_every);
      upto_multiple(out_every);
      upto_multiple(ckpt_every);
      for (long every : sample_every)
        upto_multiple(every);
      s.advance(next - s.step_count());
      const long k = s.step_count();
      if (k % series_every == 0)
        series.record(s);
      if (out_every > 0 && k % out_every == 0)
        snapshots.write(s);
      for (std::size_t m = 0; m < measurements_.size(); ++m)
        if (k % sample_every[m] == 0)
          measurements_[m]->sample(s);
      const bool wall_due = wall_every > 0.0 && omp_get_wtime() - last_checkpoint_wall >= wall_every;
      if ((ckpt_every > 0 && k % ckpt_every == 0) || wall_due)
      {
        write_checkpoint();
        // The measurements' files so far: a long run can be watched while it runs (magbrush
        // report), and one stopped later (a time limit, a crash) leaves them to this point.
        write_measurements(/*so_far=*/true);
        last_checkpoint_wall = omp_get_wtime();
      }
      const double now = omp_get_wtime();
      if (now - last_progress >= options_.progress_interval)
      {
        last_progress = now;
        const double done = static_cast<double>(k - start_step), left = static_cast<double>(end_step - k);
        const double rate = done / (now - t_wall0);
        char line[256];
        std::snprintf(line, sizeof line,
                      "  t = %.5g / %.5g s (%5.1f %%), step %ld, %.3g particle-steps/s, ETA %.0f s, %ld contacts\n",
                      s.time(), case_.dem.duration, 100.0 * k / std::max(1L, end_step), k,
                      rate * static_cast<double>(s.particles().size()), left / std::max(rate, 1e-30),
                      s.particle_contacts());
        log_ << line;
        if (s.particle_exchange())
          log_ << "    particles: " << s.particles().size() << " present, " << s.particles_entered() << " entered, "
               << s.particles_left() << " left\n";
        log_.flush();
      }
    }
  }
  catch (const StabilityError &e)
  {
    log_ << e.what() << "\n";
    if (fs::exists(checkpoint_path()))
      log_ << "the last good checkpoint is kept: " << checkpoint_path() << " (restart from it with --restart; the one "
           << "before it: " << previous_checkpoint_path(checkpoint_path()) << ")\n";
    else
      log_ << "no checkpoint was written before the failure (dem.checkpoint_interval and "
              "dem.checkpoint_wall_interval set how often one is)\n";
    write_measurements();
    log_timings(omp_get_wtime() - t_wall0);
    throw;
  }
  // The last step's snapshot and row, unless its interval has just written them, or nothing
  // ran (a finished run restarted: they are in its files already).
  const bool advanced = s.step_count() > start_step;
  if (advanced && (out_every == 0 || s.step_count() % out_every != 0))
    snapshots.write(s);
  if (advanced && s.step_count() % series_every != 0)
    series.record(s);
  write_checkpoint();
  write_measurements();
  const double wall = omp_get_wtime() - t_wall0;
  char line[256];
  std::snprintf(line, sizeof line, "done: %ld steps to t = %.6g s in %.2f s wall (%.3g particle-steps/s), %ld list rebuilds\n",
                s.step_count() - start_step, s.time(), wall,
                static_cast<double>(s.step_count() - start_step) * static_cast<double>(s.particles().size()) / std::max(wall, 1e-9),
                s.neighbour_rebuilds());
  log_ << line;
  if (s.particle_exchange())
    log_ << "particles: " << s.particles_entered() << " entered, " << s.particles_left() << " left, "
         << s.particles().size() << " present\n";
  log_ << "outputs: " << out_dir_ << "/{particles.xdmf, snapshots/, time_series.csv, checkpoint.bin, "
       << "checkpoint.previous.bin}\n";
  log_timings(wall);
}

} // namespace magbrush::dem
