// The stability guards of the DEM step: what they watch, how the threads of a step report
// what they saw, and the messages that stop a run that went unstable.
//
// A run that blows up must stop at the step where it happened, with a message that names the
// step, the particle, the cause and the likely fix, and keep the last good checkpoint. The
// guards are:
//   * a particle pair overlapping by more than dem.max_overlap_fraction of the smaller radius;
//   * a particle overlapping a wall by more than that fraction of its radius, or touching more
//     walls at once than it has contact slots for (the geometry leaves no room);
//   * a NaN or infinity in a particle's state;
//   * the kinetic energy growing by more than dem.max_kinetic_energy_growth within 100 steps
//     (energy created numerically: a time step too large for a contact or a force term).
// The step's phases only set flags (StepAlarms, one record per thread, no reductions and no
// barriers of their own); after the team the flags of all threads are combined in a fixed
// rule (StepAlarms::merge) and turned into the error (StabilityGuards), so the same fault
// gives the same message on any number of threads.
#pragma once

#include "dem/particle_state.h"
#include "dem/vector3.h"

#include <stdexcept>
#include <string>

namespace magbrush::dem {

// Thrown by the stability guards: the message names step, particle, cause and likely fix.
class StabilityError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

// A particle (index, −1: none) and where it was when an alarm was raised: the team notices
// wall and NaN alarms only at the next step's barrier, after another drift.
struct ParticleAlarm
{
  long particle = -1;
  Vector3 at;
  void set(long i, const Vector3 &x) { particle = i, at = x; }
};

// What one thread saw in a step. Sticky for a whole DemSystem::advance() call (it stops at the
// first alarm).
struct StepAlarms
{
  int overlap_alarm = 0;      // a particle pair overlaps beyond the guard
  ParticleAlarm wall_overlap; // overlaps a wall beyond the guard (the largest index)
  ParticleAlarm wall_crowded; // touches more walls than it has slots (the largest index)
  ParticleAlarm not_finite;   // NaN/Inf in its state after the final kick (the smallest index)

  void clear_alarms() { overlap_alarm = 0, wall_overlap = {}, wall_crowded = {}, not_finite = {}; }
  bool has_state_alarm() const { return wall_overlap.particle >= 0 || wall_crowded.particle >= 0 || not_finite.particle >= 0; }
  // Combines another thread's alarms into these (the rule above each field).
  void merge(const StepAlarms &other);
};

// Where the run is, for the messages.
struct StepClock
{
  long step = 0;
  double time = 0.0, dt = 0.0;
};

// The messages, and the energy guard's memory between its checks.
class StabilityGuards
{
public:
  StabilityGuards(double max_overlap_fraction, double max_kinetic_energy_growth)
    : max_overlap_(max_overlap_fraction), max_growth_(max_kinetic_energy_growth)
  {
  }

  // "particle id 12 (species 0, r = 3e-05 m, at (…) m)".
  static std::string describe_particle(const ParticleState &s, std::size_t i, const Vector3 &at);

  [[noreturn]] void pair_overlap(const StepClock &clock, const std::string &particle, int partner_id,
                                 double overlap_fraction) const;
  [[noreturn]] void wall_crowded(const StepClock &clock, const std::string &particle, int slots) const;
  [[noreturn]] void wall_overlap(const StepClock &clock, const std::string &particle) const;
  [[noreturn]] void not_finite(const StepClock &clock, const std::string &particle) const;

  // The energy guard: `kinetic` = translational + rotational energy now. Throws when it grew
  // beyond the limit since the last check (growth below `floor` is ignored: a scene starting
  // from rest); remembers it for the next check.
  void check_energy(const StepClock &clock, const ParticleState &s, double kinetic, double floor);
  // The energy at the last check (−1: none yet), kept in checkpoints.
  double last_energy() const { return last_energy_; }
  void set_last_energy(double e) { last_energy_ = e; }

private:
  double max_overlap_, max_growth_;
  double last_energy_ = -1.0;
};

} // namespace magbrush::dem
