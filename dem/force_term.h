// The plug-in interface for the forces of a step beyond the contacts: gravity, Stokes drag
// (Kawamoto A12), the induced-dipole magnetics (A8–A11), and the electrostatic terms to come.
// Each term lives in one file of dem/force_terms/ and registers itself there with the rule
// that says whether a scene needs it (force_term_registry.h). Each term is called ONCE per
// step with the whole particle state (structure of arrays) and ADDS its forces and torques,
// so a term is free to vectorise, parallelise, or refresh itself only every few steps.
//
// Determinism contract: a term must produce the same bits on any number of threads (each
// particle's contribution computed in a fixed order), or the engine's 1-vs-N-threads
// guarantee is lost.
#pragma once

#include "dem/particle_state.h"

#include <cstdint>
#include <string>
#include <vector>

namespace magbrush::dem {

class CheckpointWriter;
class CheckpointReader;

class ForceTerm
{
public:
  virtual ~ForceTerm() = default;
  virtual const char *name() const = 0;
  virtual void add_forces(const ParticleState &state, ForceBuffers &forces, double t) = 0;
  // Optional, for terms whose force on a particle depends on that particle's own state and the
  // time only (qE in the applied field, a charge's own images): add_forces_of() adds the forces
  // of the listed particles alone, the same bits as add_forces() gives them. Held forces
  // (force_terms/held_forces.h) then evaluate again only the particles that moved.
  virtual bool acts_on_each_particle_alone() const { return false; }
  virtual void add_forces_of(const ParticleState & /*state*/, ForceBuffers & /*forces*/, double /*t*/,
                             const std::vector<std::uint32_t> & /*which*/)
  {}
  // Optional, for a term held as a whole (force_terms/held_forces.h) that can renew what a few
  // moved particles change without evaluating everybody (Coulomb: the rows the moved charges
  // stand in). `held` holds this term's forces alone; `moved` lists the particles that moved
  // the hold distance since their last evaluation or renewal (ascending). The term updates in
  // place the held forces of every particle whose force those moves change, as if those
  // particles alone had been evaluated again where they are now, and returns true; or it
  // returns false, touching nothing held, when it cannot this step (then everybody is
  // evaluated). The same bits on any number of threads.
  virtual bool renew_moved(const ParticleState & /*state*/, ForceBuffers & /*held*/, double /*t*/,
                           const std::vector<std::uint32_t> & /*moved*/)
  {
    return false;
  }
  // Optional, for terms that are a plain loop over the particles (gravity, drag): they may
  // run inside the engine's OpenMP team instead of in a parallel region of their own, which
  // saves a fork and a join per step (~45 µs with sleeping idle threads, measured). Such a
  // term returns true from runs_in_team() and implements add_forces_in_team(), which EVERY
  // thread of the team calls; it shares its loop with `#pragma omp for schedule(static)
  // nowait` over the particle index (the split of the engine's per-particle phases, so no
  // barrier is needed) and gives the same bits as add_forces().
  virtual bool runs_in_team() const { return false; }
  virtual void add_forces_in_team(const ParticleState & /*state*/, ForceBuffers & /*forces*/, double /*t*/) {}
  // Optional, for a term that must step outside the team now and then (an evaluation with
  // parallel regions of its own: the magnetics) but on most steps only adds forces it holds.
  // EVERY thread of the team calls add_forces_in_team_if_held() where add_forces() would
  // come; it returns true when it added the forces there (the same bits as add_forces()),
  // false when this step needs add_forces(), which the engine then calls outside the team.
  // The answer must be the same on every thread (decided from data they all see). The
  // engine's per-particle phases are complete when it is called (a barrier). This saves
  // the team's stop and restart around the term at every step: the idle thread would go to
  // sleep and be woken again (~25 µs per hand-over on a virtual machine, measured).
  // `step_move` [m] is the largest displacement of any particle in this step's drift
  // (dt |v(t + dt/2)|): summed over the steps since some moment, it bounds how far every
  // particle can have moved since, so a term can tell without looking that nothing it holds
  // has gone stale. It covers the steps of the team only: a step outside it (add_forces())
  // must be looked at.
  virtual bool add_forces_in_team_if_held(const ParticleState & /*state*/, ForceBuffers & /*forces*/,
                                          double /*t*/, double /*step_move*/)
  {
    return false;
  }
  // Particle arrays were re-sorted (new[k] = old[order[k]]): terms that cache per-particle
  // data (e.g. dipole moments) reorder it here.
  virtual void particles_reordered(const std::vector<std::int32_t> & /*order*/) {}
  // Particles left and entered the scene (dem/particle_exchange.h): origin[k] = the index
  // that particle k had before, −1 for one that entered; an old index that appears nowhere
  // left. Terms with per-particle state drop the leavers' and start the newcomers' here.
  // Called before the particles_reordered() of the list rebuild that follows.
  virtual void particles_changed(const std::vector<std::int32_t> & /*origin*/) {}
  // Checkpoint: a term whose forces depend on more than the particle state of this step
  // (held forces between refreshes, a far field kept from the last solve, a random stream)
  // writes that state here and reads it back, so that a restarted run continues bit for bit.
  // The engine frames each term's block with its name (DemSystem::write_checkpoint); a term
  // without such state writes nothing.
  virtual void write_state(CheckpointWriter & /*out*/) const {}
  virtual void read_state(CheckpointReader & /*in*/) {}
  // A line for the run log's time table on what the term's cost is made of (e.g. how often a
  // held force was evaluated); "" for none.
  virtual std::string cost_note() const { return ""; }
};

// A term that is a plain loop over the particles (gravity, drag): it runs inside the engine's
// team; add_forces() opens a parallel region of its own for callers outside one
// (DemSystem::initialize(), tests). Derived classes implement add_forces_in_team() only.
class PerParticleForceTerm : public ForceTerm
{
public:
  void add_forces(const ParticleState &state, ForceBuffers &forces, double t) final;
  bool runs_in_team() const final { return true; }
};

} // namespace magbrush::dem
