// The DEM force term of Coulomb between the particles' charges (Kweon eq. 6), toner–toner,
// toner–carrier and carrier–carrier, without a cutoff: every periodic image of the slab, and
// — with `electric.pair_image_terms` > 0 and a drum — the images of every charge in the drum
// (through its photoconductor layer) acting on the other charges. It plugs
// electrostatics/periodic_coulomb.h into the engine's ForceTerm interface. On when some
// population is charged, unless `electric.coulomb: false`.
//
// The charged particles are gathered into a compact order of the term's own (fixed when they
// are selected; the engine's re-sorting only changes which engine index each reads; particles
// entering or leaving make it select them again at the next step), with
// positions unwrapped along periodic axes. Per step, F_i = q_i E_i with E = the held far field
// + the exact near pairs at the current positions. The far field is evaluated again (and the
// cells rebuilt) when `electric.coulomb_refresh` has elapsed, when some charge moved a quarter
// of a cell since the cells were built (a charge must stay near its cell for the near/far
// split to hold), or when a charge changed.
//
// Held between moves (dem/force_terms/held_forces.h holds it as a whole), the term can also
// renew only the few charges that moved the hold distance while the rest did not
// (renew_moved): their own rows, and their entries in the other charges' rows, at the cost
// of those entries instead of everybody's rows. In a nip the fastest few — toner flying
// across the gap at metres per second — would otherwise renew everybody several times per
// hold of the developer riding the sleeve at 0.4 m/s. Every pair's held force is then off by
// the moves of its two charges since each was last renewed, each under the hold distance:
// the bound of the whole hold.
//
// Checkpoint: the compact order, the positions at the last rebuild, the unwrapped positions at
// which each charge was last evaluated or renewed, the time of the last rebuild and the held
// far field; a restarted run rebuilds the cells from the stored positions (deterministic),
// places the sources where they stood, and continues bit for bit.
#pragma once

#include "dem/force_term.h"
#include "electrostatics/periodic_coulomb.h"

#include "case/case_model.h"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace magbrush::electrostatics {

struct CoulombTermSettings
{
  CoulombSettings far;
  double refresh = 2e-6;      // far-field refresh interval [s] (0 = every step)
  double max_move_cells = 0.25; // rebuild when a charge moved this × the cell size
  std::optional<GroundedSurface> image_surface; // pair images in this surface
  int image_terms = 2;

  static CoulombTermSettings from_case(const Case &c);
};

class CoulombTerm : public dem::ForceTerm
{
public:
  CoulombTerm(const CoulombTermSettings &settings, const std::array<double, 3> &box);

  const char *name() const override { return "Coulomb"; }
  void add_forces(const dem::ParticleState &state, dem::ForceBuffers &forces, double t) override;
  void particles_reordered(const std::vector<std::int32_t> &order) override;
  void particles_changed(const std::vector<std::int32_t> &origin) override;
  void write_state(dem::CheckpointWriter &out) const override;
  void read_state(dem::CheckpointReader &in) override;
  bool renew_moved(const dem::ParticleState &state, dem::ForceBuffers &held, double t,
                   const std::vector<std::uint32_t> &moved) override;

  std::string cost_note() const override;

  long evaluations() const { return evaluations_; } // far-field evaluations (rebuilds) so far

  std::size_t charges() const { return index_.size(); }

private:
  CoulombTermSettings settings_;
  std::array<double, 3> box_;
  PeriodicCoulomb coulomb_;
  std::size_t state_size_ = 0;
  bool must_select_ = true, must_rebuild_ = true;
  double built_at_ = 0.0;
  long evaluations_ = 0;
  // Why the far field was rebuilt, since this run (re)started (the cost note): particles
  // entered or left, a charge changed, the refresh interval elapsed, a charge left its cell's reach.
  struct RebuildCauses
  {
    long exchange = 0, charge = 0, refresh = 0, move = 0;
  } causes_;
  // Compact charged particles: engine index, charge, radius (image floor), unwrapped
  // positions now and at the last rebuild, field.
  std::vector<std::uint32_t> index_;
  std::vector<double> q_, radius_, x_, y_, z_, bx_, by_, bz_, E_;
  std::vector<std::int32_t> compact_of_; // per engine index: its compact index, −1 uncharged
  // renew_moved()'s scratch (kept: no allocation per renewal beyond growth).
  std::vector<std::uint32_t> moved_, touched_;
  std::vector<double> dE_, E_moved_;

  void select(const dem::ParticleState &state);
  void index_compactly();
  void gather(const dem::ParticleState &state);
  bool moved_too_far() const;
  void rebuild(double t);
};

} // namespace magbrush::electrostatics
