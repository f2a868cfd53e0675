// The force of the nip's applied electric field on the charged particles (Kweon eq. 6, the qE
// part): F = q E(x, y, u(t)) for every particle with q ≠ 0, E from the stored electric grid
// (the bias solution plus the latent image carried by the drum surface; fields/
// nip_potential_field.h, which also defines the image's phase u(t) and its origin).
//
// DEM coordinates are the field's: the cross-section plane is x-y with the roller axis z at the
// origin, z is ignored (E_z = 0), and along periodic axes the engine's image of the position is
// looked up — the same mapping as the magnetic term (magnetic_force_term.cpp lookup_at).
//
// Outside the grid window E = 0 (nip_potential_field.h; docs/electrostatics.md says why): the
// term counts such lookups (lookups_outside()) and warns on stderr the first time one happens,
// naming the particle and the window.
//
// On when the case enables the electric section and some population is charged (the rule in the
// .cpp says why not otherwise). No state between steps: nothing to checkpoint or re-sort. The
// loop is per particle (each force computed alone, in a fixed order), so the forces have the
// same bits on any number of threads.
#pragma once

#include "dem/force_term.h"

#include "case/case_model.h"
#include "fields/nip_potential_field.h"

#include <array>
#include <memory>

namespace magbrush::dem {

class ElectricFieldForce : public ForceTerm
{
public:
  // `box` = the DEM's periodic lengths (0 = open).
  ElectricFieldForce(std::shared_ptr<const NipPotentialField> field, const Drum &drum,
                     const std::array<double, 3> &box);

  const char *name() const override { return "applied electric field qE"; }
  void add_forces(const ParticleState &state, ForceBuffers &forces, double t) override;
  bool acts_on_each_particle_alone() const override { return true; }
  void add_forces_of(const ParticleState &state, ForceBuffers &forces, double t,
                     const std::vector<std::uint32_t> &which) override;

  // Lookups of charged particles so far, and how many of them fell outside the window.
  long lookups() const { return lookups_; }
  long lookups_outside() const { return outside_; }
  const NipPotentialField &field() const { return *field_; }

private:
  std::shared_ptr<const NipPotentialField> field_;
  Drum drum_;
  std::array<double, 3> box_;
  NipPotentialField::PhaseWeights weights_;
  long lookups_ = 0, outside_ = 0;
  bool warned_ = false;

  // qE on particles index(0) … index(count − 1).
  template <typename Index>
  void add_forces_over(const ParticleState &s, ForceBuffers &f, double t, long count, Index index);
};

} // namespace magbrush::dem
