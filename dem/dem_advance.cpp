// The step loop of the DEM engine: velocity Verlet, phase by phase, run by one OpenMP team
// for as many steps as possible (see DemSystem::advance in dem_system.h).
//
// One step, in the order of the papers' algorithm (Kawamoto A1):
//
//   kick and drift      v += (dt/2) F/m, x += dt v          each thread: its static share
//   ── barrier K ──      every thread sees every position and every thread's drift
//   (list rebuild)      when some particle drifted half the skin: serial, outside the team
//   pair contacts       Hertz–Mindlin per listed pair, row sums     dynamic blocks
//   ── barrier P ──      every pair force is in its slot
//   column sums         −F of the pairs where the particle is the partner   static share
//   (toner substeps)    with dem.toner_substeps: the toner's k substeps     one thread
//   ── its barrier ──
//   wall contacts       cylinders, planes, prisms                           static share
//   (fast reaction)     the carriers' share of the toner's contacts         static share
//   force terms         gravity, drag: inside the team (static share); magnetics, ...:
//                       inside the team on the steps where they hold their forces
//                       (shared loops), else a serial call outside the team (they
//                       parallelise themselves)
//   final kick          v += (dt/2) F/m                                      static share
//
// When the team goes straight on to the next step, the final kick and the next step's kick
// and drift run as one pass over the particles (final_kick_and_next_drift_phase: the same
// operations per particle in the same order, so the same bits, with the particle and force
// arrays read once instead of twice); before a pause (the end of the run, the energy guard)
// the final kick runs alone, so the state between steps is what it always was.
//
// The last three loops and the next step's kick-and-drift share one static split of the
// particles, so each thread carries its own particles from the column sums to the next drift
// without waiting: a step costs two barriers (K and P) and nothing else. Before, each step
// was its own parallel region (a fork and a join on top of K and P; two regions with force
// terms), and with sleeping idle threads each hand-over costs ~25 µs (measured, see
// docs/dem_vs_lammps.md) — a fifth of a 2-thread step of 14k particles.
//
// Decisions inside the team (stop for a rebuild, an alarm, the force terms, the energy guard)
// are taken by every thread from the same data, read in a window where nobody writes it:
//   * the drifts and the last step's wall/NaN alarms after barrier K (they are written
//     before K: the drifts in the kick loop, the alarms in the previous step's wall and kick
//     loops);
//   * this step's overlap alarms after barrier P (written in the pair loop, before P);
// so every thread leaves the loop at the same point. After the team, the alarms are raised
// serially with the usual messages (dem_system.cpp).
#include "dem/dem_system.h"

#include "dem/phase_clock.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace magbrush::dem {

DemSystem::StepFlags &DemSystem::my_flags() { return thread_flags_[static_cast<std::size_t>(omp_get_thread_num())]; }

double DemSystem::max_drift2_of_team() const
{
  double m = 0.0;
  for (int t = 0; t < omp_get_num_threads(); ++t)
    m = std::max(m, thread_flags_[static_cast<std::size_t>(t)].max_drift2);
  return m;
}

double DemSystem::max_step_move_of_team() const
{
  double m = 0.0;
  for (int t = 0; t < omp_get_num_threads(); ++t)
    m = std::max(m, thread_flags_[static_cast<std::size_t>(t)].max_step2);
  return std::sqrt(m);
}

bool DemSystem::team_has_state_alarm() const
{
  for (int t = 0; t < omp_get_num_threads(); ++t)
  {
    if (thread_flags_[static_cast<std::size_t>(t)].has_state_alarm())
      return true;
  }
  return false;
}

bool DemSystem::team_has_overlap_alarm() const
{
  for (int t = 0; t < omp_get_num_threads(); ++t)
    if (thread_flags_[static_cast<std::size_t>(t)].overlap_alarm)
      return true;
  return false;
}

StepAlarms DemSystem::team_alarms() const
{
  StepAlarms all;
  for (const StepFlags &f : thread_flags_)
    all.merge(f);
  return all;
}

void DemSystem::begin_step()
{
  ++step_;
  time_ = static_cast<double>(step_) * dt_;
  walls_.prepare(time_, walls_frozen_);
}

void DemSystem::step() { advance(1); }

// The exchange schedule (dem/particle_exchange.h) cuts the steps into runs of the team: the
// steps up to the one before an exchange step, then the exchange step alone, whose forced
// list rebuild is where the exchange happens (advance_steps, Pause::rebuild). The cut
// depends on the step number only, so advance(n) stays bit-identical to n × step().
void DemSystem::advance(long steps)
{
  if (!initialized_)
    throw std::logic_error("DemSystem::step()/advance() before initialize()");
  while (steps > 0)
  {
    long run = steps;
    if (exchange_)
    {
      const long every = exchange_->interval_steps();
      const long next = step_ + 1; // the step the run starts with
      if (next >= 1 && next % every == 0)
      {
        exchange_pending_ = true;
        run = 1;
      }
      else
      {
        const long first_exchange = next < 1 ? every : (next / every + 1) * every;
        run = std::min(steps, first_exchange - next);
      }
    }
    advance_steps(run);
    steps -= run;
  }
}

void DemSystem::advance_steps(long steps)
{
  // A team may be larger now than at initialize() (omp_set_num_threads between calls).
  if (thread_flags_.size() < static_cast<std::size_t>(omp_get_max_threads()))
    thread_flags_.resize(static_cast<std::size_t>(omp_get_max_threads()));
  for (StepFlags &f : thread_flags_)
    f.clear_alarms();
  // The force terms that can run inside the team: the leading ones (the others run serially
  // after them, so every particle's force is summed in the order of terms_, as always).
  team_terms_ = 0;
  while (team_terms_ < terms_.size() && terms_[team_terms_]->runs_in_team())
    ++team_terms_;
  Resume from = Resume::step_start;
  while (true)
  {
    const Pause why = run_team(steps, from);
    raise_alarms(team_alarms()); // after the team every alarm is final
    switch (why)
    {
    case Pause::done:
      return;
    case Pause::rebuild: // the step has begun (kick and drift done); its contacts follow
    {
      const bool exchange_step = exchange_pending_;
      exchange_pending_ = false;
      const bool exchanged = exchange_step && run_scheduled_exchange(); // rebuilds the list itself
      // An empty exchange on a step whose list is still good leaves the list as it is.
      if (!exchanged && list_is_stale(pause_drift2_))
        rebuild_neighbour_list();
    }
      from = Resume::contacts;
      break;
    case Pause::force_terms: // contacts and team terms done; the others add theirs, then the final kick
      for (std::size_t t = serial_from_; t < terms_.size(); ++t)
      {
        PhaseTimer timer(times_.terms[t]);
        terms_[t]->add_forces(particles_, forces_, time_);
      }
      from = Resume::final_kick;
      break;
    case Pause::energy_guard: // a step is complete
      check_energy();
      if (steps == 0)
        return;
      from = Resume::step_start;
      break;
    case Pause::alarm:
      throw std::logic_error("DemSystem: a thread stopped for an alarm that raise_alarms() did not find");
    }
  }
}

// The team's loop. `steps_left` counts the steps not yet completed (the one in progress
// included when resuming inside a step); every thread keeps the same count and takes the
// same decisions, so they leave together.
DemSystem::Pause DemSystem::run_team(long &steps_left, Resume from)
{
  Pause why = Pause::done;
  long left_at_exit = steps_left;
#pragma omp parallel if (parallel())
  {
    PhaseClock clock;
    StepFlags &mine = my_flags();
    long left = steps_left;
    Resume at = from;
    Pause stop = Pause::done;
    bool drifted = false; // this step's kick and drift came with the last final kick
    while (true)
    {
      if (at == Resume::step_start)
      {
        if (left == 0)
          break; // Pause::done
        if (!drifted)
          kick_and_drift_phase(mine); // ends with barrier K
        drifted = false;
        clock.charge(times_.integrate);
        if (team_has_state_alarm()) // the previous step's walls or final kick
        {
          stop = Pause::alarm;
          break;
        }
#pragma omp master
        begin_step(); // read by the wall phase, after barrier P
        const double drift2 = max_drift2_of_team();
        if (must_pause_before_contacts(drift2))
        {
#pragma omp master
          pause_drift2_ = drift2; // read after the team, where the threads' flags are out of reach
          stop = Pause::rebuild;
          break;
        }
      }
      if (at != Resume::final_kick)
      {
        // The toner's substeps (toner_substeps.h): its motion over this step, before the
        // slow forces at the step's end (the threads share it, toner_substeps.h).
        if (substeps_.on())
        {
          toner_substeps_phase(mine);
          clock.charge(times_.substeps);
        }
        // This step's largest drift, for the terms that hold their forces (read before
        // barrier P: no thread drifts again before every thread has passed it).
        const double step_move = max_step_move_of_team();
        pair_and_row_phase(mine); // ends with barrier P
        clock.charge(times_.particle_contacts);
        if (team_has_overlap_alarm())
        {
          stop = Pause::alarm;
          break;
        }
        column_phase();
        clock.charge(times_.particle_contacts);
        if (walls_.size() > 0)
        {
          wall_phase(mine);
          clock.charge(times_.wall_contacts);
        }
        if (substeps_.on())
        {
          add_fast_reaction_phase();
          clock.charge(times_.substeps);
        }
        for (std::size_t t = 0; t < team_terms_; ++t)
        {
          terms_[t]->add_forces_in_team(particles_, forces_, time_);
          clock.charge(times_.terms[t]);
        }
        // The other terms in order, inside the team while each can hold its forces; from
        // the first that cannot, the caller runs them and resumes at the final kick.
        std::size_t serial_from = team_terms_;
        if (serial_from < terms_.size())
        {
          // The per-particle phases above end without a barrier; the terms below add forces
          // to particles of other threads' shares. The wait for the slowest thread is charged
          // to the contacts, whose imbalance it is, not to the term that happens to come next.
#pragma omp barrier
          clock.charge(walls_.size() > 0 ? times_.wall_contacts : times_.particle_contacts);
        }
        while (serial_from < terms_.size() &&
               terms_[serial_from]->add_forces_in_team_if_held(particles_, forces_, time_, step_move))
          clock.charge(times_.terms[serial_from++]);
        if (serial_from < terms_.size())
        {
          clock.charge(times_.terms[serial_from]); // (what it did before it gave up)
#pragma omp master
          serial_from_ = serial_from;
          stop = Pause::force_terms;
          break;
        }
      }
      --left;
      at = Resume::step_start;
      const bool energy_guard = step_ % 100 == 0;
      // Straight on to the next step: its kick and drift share the final kick's pass.
      drifted = left > 0 && !energy_guard;
      if (drifted)
        final_kick_and_next_drift_phase(mine); // ends with the next step's barrier K
      else
        final_kick_phase(mine);
      clock.charge(times_.integrate);
      if (energy_guard)
      {
        stop = Pause::energy_guard;
        break;
      }
    }
#pragma omp master
    {
      why = stop;
      left_at_exit = left;
    }
  }
  steps_left = left_at_exit;
  return why;
}

void DemSystem::settle(double duration)
{
  if (duration <= 0.0)
    return;
  // The settling phase happens before t = 0: the clock runs from −duration up to 0, so that
  // everything prescribed in time (the field ramp, wall paths) starts once the particles are at
  // rest, as in Kawamoto's procedure (fall, come to rest, then apply the field gradually).
  walls_frozen_ = true;
  const long steps = static_cast<long>(std::ceil(duration / dt_));
  step_ = -steps;
  time_ = static_cast<double>(step_) * dt_;
  advance(steps);
  walls_frozen_ = false;
  step_ = 0;
  time_ = 0.0;
  guards_.set_last_energy(-1.0);
}

} // namespace magbrush::dem
