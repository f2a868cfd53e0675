// The DEM engine: particles, walls, the neighbour list with its contact history, the force
// terms, and the velocity-Verlet step that ties them together.
//
//   step():  half kick → drift → (rebuild the neighbour list if stale) →
//            forces: particle contacts, wall contacts, every ForceTerm → half kick → guards
//   advance(n): n steps, as many of them as possible in ONE OpenMP team (dem_advance.cpp)
//
// Its parts, each in a file of its own: the particles (particle_state.h), the pair list with
// the contact history (neighbour_list.h), the contact law (contact_law.h), the walls and their
// contact slots (wall_contacts.h, wall_contact_slots.h), the force terms (force_term.h,
// force_terms/), the stability guards (stability_guards.h) and the checkpoint file
// (checkpoint_file.h). This class owns them and runs the step; the pair kernel and the
// phases are in dem_system.cpp, the team's step loop in dem_advance.cpp.
//
// Everything here is deterministic: the same input gives the same bits on any number of
// OpenMP threads, and a restart from a checkpoint continues bit-identically.
#pragma once

#include "dem/contact_parameters.h"
#include "dem/force_term.h"
#include "dem/neighbour_list.h"
#include "dem/pair_kernel.h"
#include "dem/particle_exchange.h"
#include "dem/particle_state.h"
#include "dem/stability_guards.h"
#include "dem/time_step.h"
#include "dem/toner_substeps.h"
#include "dem/wall_contact_slots.h"
#include "dem/wall_contacts.h"

#include "case/case_model.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush::dem {

struct CheckpointIdentity;

// Wall time spent in each phase of the step [s].
struct PhaseTimes
{
  double neighbour = 0, particle_contacts = 0, wall_contacts = 0, integrate = 0, guards = 0;
  double substeps = 0; // the toner's substeps (toner_substeps.h)
  std::vector<double> terms; // one per force term
};

class DemSystem
{
public:
  // Walls, periodic box and materials come from the case; particles are added separately
  // (insert_particles, or directly through particles() in tests, then initialize()).
  explicit DemSystem(const Case &c);
  // The same with an explicit wall set instead of build_wall_primitives(c) (tests, scenes
  // whose walls are assembled by hand, e.g. a drum with the particles inside).
  DemSystem(const Case &c, const WallSet &walls);

  void insert_particles();                 // the case's populations
  ParticleState &particles() { return particles_; }
  const ParticleState &particles() const { return particles_; }
  // Derives the contact table, the time step (throws if the user step is unstable) and builds
  // the first neighbour list. Call once after the particles are in place.
  void initialize();

  void add_force_term(std::unique_ptr<ForceTerm> term);
  // Puts `term` in the place of the term called `name` (same position in the force list);
  // throws std::invalid_argument when there is none. For studies of a term's settings.
  void replace_force_term(const std::string &name, std::unique_ptr<ForceTerm> term);
  const std::vector<std::unique_ptr<ForceTerm>> &force_terms() const { return terms_; }

  // Particles entering and leaving (dem/particle_exchange.h): from now on, during every step
  // that is a multiple of exchange->interval_steps(), the exchange decides who leaves and
  // who enters. Set before initialize() (its smallest particles enter the stable time step).
  void set_particle_exchange(std::unique_ptr<ParticleExchange> exchange);
  ParticleExchange *particle_exchange() const { return exchange_.get(); }
  // Removes the particles at indices `leave` (each once, any order) and appends those of
  // `enter` under new ids, now: every surviving pair and wall contact keeps its history
  // bit for bit, the leavers' contacts vanish, the newcomers start free, the force terms are
  // told and the neighbour list is rebuilt (re-sorting the particles). The scheduled
  // exchange calls it inside a step, before the forces; called between steps, the forces of
  // the next half kick are those of the old set (the newcomers' are zero).
  void exchange_particles(const std::vector<std::int32_t> &leave, const ParticleState &enter);
  // Particles that entered and left through exchange_particles() since the start.
  long particles_entered() const { return entered_; }
  long particles_left() const { return left_; }

  // One velocity-Verlet step; the same as advance(1).
  void step();
  // `steps` steps, bit-identical to calling step() `steps` times. The threads stay in one
  // parallel region for as long as the steps need no serial work (a list rebuild, the force
  // terms, the energy guard every 100 steps): a fork/join or barrier costs tens of µs when
  // idle threads sleep, a real share of a step of a few thousand particles.
  void advance(long steps);
  // Rebuild (and re-sort) the neighbour list at the next step even if no particle moved far.
  void request_neighbour_rebuild() { force_rebuild_ = true; }
  // Runs with the walls at rest for `duration` on a clock from −duration to t = 0 (a field
  // ramp or a wall path given from t = 0 has not started yet).
  void settle(double duration);

  // The case the system was built from (its settings as resolved; diagnostics read them).
  const Case &scene_case() const { return case_; }
  double time() const { return time_; }
  long step_count() const { return step_; }
  double time_step() const { return dt_; }
  // The toner's substeps (dem.toner_substeps; toner_substeps.h): on() is false without them.
  const TonerSubsteps &toner_substeps() const { return substeps_; }
  const StableTimeStep &stable_time_step_info() const { return stable_; }
  const ContactTable &contact_table() const { return table_; }
  const DemWalls &walls() const { return walls_; }
  const PeriodicBox &box() const { return box_; }
  const NeighbourList &neighbour_list() const { return list_; }
  const ForceBuffers &forces() const { return forces_; }
  const WallContactSlots &wall_slots() const { return wall_slots_; }
  const std::vector<std::int32_t> &contact_count() const { return contact_count_; }
  const PhaseTimes &phase_times() const { return times_; }
  long neighbour_rebuilds() const { return rebuilds_; }
  double skin() const { return skin_; }

  // Diagnostics, summed in a fixed order (thread-independent).
  double kinetic_energy() const;      // translational
  double rotational_energy() const;
  double elastic_energy() const;      // Hertz normal springs of touching particle pairs
  long particle_contacts() const;     // touching particle pairs
  std::vector<WallLoad> wall_loads() const;
  // The particles touching wall `w` now, in particle-index order (deterministic). `out` is
  // cleared first; reuse it between calls to avoid allocation.
  void wall_contacts(std::size_t w, std::vector<WallContactRecord> &out) const;
  std::size_t memory_bytes() const;   // particle, list, history and wall-slot storage

  // Checkpoint: the complete dynamic state (particles in their current order, forces,
  // neighbour list with contact history, wall slots, clock, each force term's own state),
  // with the identity of the case that wrote it (checkpoint_file.h). Written atomically.
  // `appendix` writes what the caller keeps beside the engine (a run's measurements) after the
  // engine's state, inside the same checksummed file; read_checkpoint hands its `appendix` the
  // stream positioned there (nothing left to read in a file written without one).
  void write_checkpoint(const std::string &path);
  void write_checkpoint(const std::string &path, const CheckpointIdentity &identity,
                        const std::function<void(StateOut &)> &appendix = {});
  // Replaces the state by the checkpoint's; the case must be the same scene.
  void read_checkpoint(const std::string &path, const std::function<void(StateIn &)> &appendix = {});

  // Maximum number of walls one particle may touch at once.
  static constexpr int max_wall_contacts = WallContactSlots::per_particle;
  // Rows (particles) per block of the contact kernel: fixed, so that the work split, and
  // hence every floating-point sum, is the same on any number of threads.
  static constexpr long contact_block_rows = 128;

private:
  Case case_;
  DemWalls walls_;
  PeriodicBox box_;
  ContactTable table_;
  std::vector<double> coefficient_fields_; // table_ as six arrays (E*, G*, μ, μ_r, α_n, α_t)
  StableTimeStep stable_;
  ParticleState particles_;
  ForceBuffers forces_;
  NeighbourList list_;
  std::vector<std::unique_ptr<ForceTerm>> terms_;
  std::unique_ptr<ParticleExchange> exchange_;
  long entered_ = 0, left_ = 0;
  // exchange_particles()'s scratch (kept: no allocation per exchange beyond growth).
  std::vector<std::int32_t> keep_, origin_, leave_plan_;
  std::vector<char> leaving_;
  ParticleState enter_plan_;
  std::vector<std::int32_t> contact_count_;
  std::vector<double> x0_, y0_, z0_; // positions at the last list build
  WallContactSlots wall_slots_;
  std::vector<double> scratch_;
  std::vector<std::int32_t> iscratch_;

  double dt_ = 0.0, time_ = 0.0, skin_ = 0.0;
  long step_ = 0, rebuilds_ = 0;
  bool walls_frozen_ = false, force_rebuild_ = true, initialized_ = false;
  TonerSubsteps substeps_;
  StabilityGuards guards_;
  double energy_floor_ = 0.0;        // the energy guard ignores growth below this
  PhaseTimes times_;

  // What the phases of a step report: one record per thread, written only by its thread and
  // read by all after a barrier (no reduction clause, so no extra barrier). The alarms
  // (stability_guards.h) are sticky for the whole advance() call (it stops at the first one);
  // max_drift2 is this step's. Padded to a cache line: neighbouring threads' records do not
  // share one.
  struct alignas(64) StepFlags : StepAlarms
  {
    double max_drift2 = 0.0;   // largest squared displacement since the list build
    double max_step2 = 0.0;    // largest squared displacement in this step's drift
    std::vector<double> row_torques; // scratch of the pair phase (kept: no allocation per step)
    // Scratch of a particle's wall contacts: kept here because an array of these on the stack
    // is zeroed at every call (their members have initialisers), a third of the wall phase.
    std::array<WallContactGeometry, max_wall_contacts + 1> wall_geometry;
  };
  std::vector<StepFlags> thread_flags_; // one per thread of the team
  std::size_t team_terms_ = 0;           // leading force terms that run inside the team
  std::size_t serial_from_ = 0;          // this step's first force term that runs outside the team
  // Where a team (re)starts within a step, and why it stopped.
  enum class Resume { step_start, contacts, final_kick };
  enum class Pause { done, rebuild, force_terms, energy_guard, alarm };

  void setup_derived();
  void rebuild_neighbour_list(const std::vector<std::int32_t> *origin = nullptr);
  // advance() without the exchange schedule (the team's loop; dem_advance.cpp).
  void advance_steps(long steps);
  bool exchange_pending_ = false; // exchange at the rebuild of the step in progress
  double pause_drift2_ = 0.0;     // the team's largest squared drift when it paused to rebuild
  bool run_scheduled_exchange();
  void permute_particles(const std::vector<std::int32_t> &order);
  bool parallel() const { return particles_.size() > 512; } // below: one thread is faster
  // The team pauses for serial work before the contacts when the list has expired, a rebuild
  // was requested, or the step is an exchange step (the exchange happens in that pause).
  bool list_is_stale(double max_drift2) const { return force_rebuild_ || max_drift2 > 0.25 * skin_ * skin_; }
  bool must_pause_before_contacts(double max_drift2) const { return exchange_pending_ || list_is_stale(max_drift2); }
  // The phases of a step. Each is called by every thread of an enclosing parallel region
  // (work-shared loops inside, reporting into the calling thread's StepFlags); see
  // dem_advance.cpp for their order and barriers.
  void kick_and_drift_phase(StepFlags &mine);
  void pair_and_row_phase(StepFlags &mine);
  PairKernelData pair_kernel_data();
  int one_thread_pairs_rows_and_columns(PairKernelData D, std::vector<double> &scratch);
  void column_phase();
  void wall_phase(StepFlags &mine);
  // The wall contacts of particle i with step dt: adds its force and torque to `out`; records
  // an overlap beyond the guard (alarm = i) or too many walls (too_many = i).
  void particle_wall_contacts(std::size_t i, double dt, const ForceArrays &out, long &alarm, long &too_many);
  // Those records into this thread's flags (the largest index of each kind).
  void record_wall_alarms(StepFlags &mine, long alarm, long too_many) const;
  // The toner's substeps (toner_substeps.h, toner_substeps.cpp): the number of substeps and
  // the fast species, after the step is known; the fast pairs, after every list build; the
  // substeps of one step (all threads call it; one works); the fast particles' forces at the
  // current positions with step dt (their fast pairs' and walls' into forces_.fast_*, the
  // slow partners' reaction added to `reaction`, when given); the slow particles' average
  // reaction into their forces (static share, after the slow forces).
  void configure_substeps(const std::vector<Material> &materials, const std::vector<std::string> &names,
                          const ParticleState &all);
  void find_fast_pairs();
  void toner_substeps_phase(StepFlags &mine);
  int fast_forces(double dt, StepFlags &mine);
  void initial_fast_forces(StepFlags &mine);
  void copy_fast_history(bool into_list); // the list's slots <-> the substeps' compact copy
  void add_fast_reaction_phase();
  void final_kick_phase(StepFlags &mine);
  // final_kick_phase, then the next step's kick_and_drift_phase, in one pass over the
  // particles (dem_advance.cpp: when the team goes straight on to the next step).
  void final_kick_and_next_drift_phase(StepFlags &mine);
  // x += dt v of particle i; its squared drift since the build (and `step2` raised to this drift's)
  double drift(std::size_t i, double dt, double &step2);
  // A particle in substeps: its squared drift since the build plus a bound on its next step's.
  double substep_drift_bound(std::size_t i, double dt) const;
  void begin_step(); // the clock and the walls' pose at the new time (one thread)
  // advance(): the team's loop over steps, from `from` until it needs serial work.
  Pause run_team(long &steps_left, Resume from);
  StepFlags &my_flags();
  double max_drift2_of_team() const;   // after the drift's barrier
  double max_step_move_of_team() const; // after the drift's barrier, before the next drift
  bool team_has_state_alarm() const;   // the last step's wall / NaN alarms, after a barrier
  bool team_has_overlap_alarm() const; // this step's pair alarm, after the pair barrier
  StepAlarms team_alarms() const;       // all threads' alarms combined (serial)
  // After the region: turn the alarms into StabilityErrors with a useful message.
  void raise_alarms(const StepAlarms &alarms) const;
  void raise_worst_pair_overlap() const;
  void check_energy();
  StepClock clock() const { return {step_, time_, dt_}; }
  std::string describe_particle(std::size_t i) const; // at its current position
  std::string describe_particle(std::size_t i, const Vector3 &at) const;
};

} // namespace magbrush::dem
