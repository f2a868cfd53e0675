// The DEM force term of the charges' own images in the conductors: the grounded drum
// substrate under its photoconductor layer (εr = drum.pc_eps_r, thickness drum.pc_thickness;
// the layered image series of electrostatics/layered_images.h) and the sleeve (a bare
// grounded conductor: the sleeve's bias is part of the applied field qE, not of the images).
// On when some population is charged and electric.conductor_images is true (false keeps
// Kweon's assumption that the field is unchanged by the toner) and the scene has a sleeve.
//
// Each charge q at height h above a surface feels F = q²/(4πε0) S(h) n (S < 0: attraction;
// −1/(4h²) for the bare conductor), n the surface normal at its foot point, the surface taken
// locally planar (grounded_surface.h states the error). The charge sits at the particle's
// centre, in the air between the surfaces: a particle overlapping a wall (its centre closer
// than its radius) is given its images at h = its radius, as if it just touched, so a contact
// overlap does not stiffen the image force and a centre on the wrong side never divides by
// zero. The images of one charge acting on the others are the Coulomb term's (coulomb.h).
#pragma once

#include "dem/force_term.h"
#include "electrostatics/grounded_surface.h"

#include "case/case_model.h"

#include <vector>

namespace magbrush::electrostatics {

class ConductorImages : public dem::ForceTerm
{
public:
  explicit ConductorImages(std::vector<GroundedSurface> surfaces);
  // The drum (with its layer) when present, and the sleeve.
  static std::vector<GroundedSurface> surfaces_of(const Case &c);

  const char *name() const override { return "conductor images"; }
  void add_forces(const dem::ParticleState &state, dem::ForceBuffers &forces, double t) override;
  bool acts_on_each_particle_alone() const override { return true; }
  void add_forces_of(const dem::ParticleState &state, dem::ForceBuffers &forces, double t,
                     const std::vector<std::uint32_t> &which) override;

private:
  std::vector<GroundedSurface> surfaces_;

  // The images of particles index(0) … index(count − 1).
  template <typename Index>
  void add_forces_over(const dem::ParticleState &state, dem::ForceBuffers &forces, long count, Index index) const;
};

} // namespace magbrush::electrostatics
