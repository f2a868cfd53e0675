// From materials to contact coefficients: the mixing rules, the two damping forms and
// Kawamoto's polygon rule for the rolling-friction coefficient.
#pragma once

#include "dem/contact_law.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::dem {

// Kawamoto's polygon rule. A sphere is modelled as a regular n-gon of circumradius r resting
// on one side. Tipping it over a corner needs a torque W r sin(π/n) about the centre, so the
// rolling resistance torque is r μ_r |F_n| with
//     μ_r = sin(π / n)          (n = 12, Kawamoto's carrier: μ_r = 0.2588).
double rolling_friction_from_polygon(int corners);

// LIGGGHTS/LAMMPS restitution form, β = ln e / √(ln²e + π²):
//   normal     γ_n = 2√(5/6) |β| √(S_n m*), S_n = 2E*√(R*δ)  ⇔  α_n = √5 |β|
//   tangential γ_t = 2√(5/6) |β| √(S_t m*), S_t = k_t       ⇔  α_t = 2√(5/6) |β|
// It is exact only for a linear spring; with Hertz it gives a restitution that differs from e
// (see hertz_restitution and the verification test).
double ln_e_alpha_normal(double e);
double ln_e_alpha_tangential(double e);

// The restitution coefficient that Hertz + the dashpot c_n = α √(m* k_n) δ^¼ gives in a
// head-on impact. For this dashpot it is independent of the impact speed, so it is one number
// per α, computed by integrating the dimensionless contact ODE
//     ξ'' = −ξ^{3/2} − α ξ^{1/4} ξ',  ξ(0) = 0, ξ'(0) = 1
// until the (non-attractive) force vanishes; e = −ξ'(end).
double hertz_restitution(double alpha);
// Its inverse by bisection: the α for which Hertz gives exactly e (restitution_model
// "hertz_exact").
double hertz_alpha_for_restitution(double e);

// A table of coefficients for every interaction type: species × (species ∪ wall materials).
class ContactTable
{
public:
  // `species_materials[s]` names the material of population s, `wall_materials[w]` that of
  // wall w. Mixing: E*, G* exactly as in Hertz–Mindlin; μ, μ_r, damping of two particles the
  // mean of both; against a wall: the wall's μ (Kawamoto quotes particle–wall friction as a
  // wall property), the particle's μ_r and damping (or the wall's restitution if it has one).
  void build(const Case &c, const std::vector<std::string> &species_materials,
             const std::vector<std::string> &wall_materials);

  // Van der Waals adhesion of each interaction type (same layout as the coefficients). The
  // Hamaker constant of two materials is √(A₁ A₂) unless the case lists the pair in
  // adhesion_pairs; a material with A > 0 that meets one without a written hamaker is an
  // error naming the pair (write 0 J there for none). Asperity radii of 0 (not given) are +∞.
  const AdhesionCoefficients &adhesion_pair(int s, int t) const
  {
    return adhesion_[static_cast<std::size_t>(s) * columns_ + static_cast<std::size_t>(t)];
  }
  const AdhesionCoefficients &adhesion_wall(int s, int w) const
  {
    return adhesion_[static_cast<std::size_t>(s) * columns_ + n_species_ + static_cast<std::size_t>(w)];
  }
  const AdhesionCoefficients *adhesion_data() const { return adhesion_.data(); }
  // Whether any pair of the particles, or any particle and wall, sticks.
  bool adhesive() const { return adhesive_; }
  bool particles_adhesive() const { return particles_adhesive_; }
  // The cut-off gap z0 and the range z_c of the force (0 when nothing sticks): the neighbour
  // list and the wall detection must reach this far beyond contact.
  double adhesion_cutoff() const { return cutoff_; }
  double adhesion_range() const { return adhesive_ ? range_ : 0.0; }

  const ContactCoefficients &particle_pair(int s, int t) const
  {
    return table_[static_cast<std::size_t>(s) * columns_ + static_cast<std::size_t>(t)];
  }
  const ContactCoefficients &particle_wall(int s, int w) const
  {
    return table_[static_cast<std::size_t>(s) * columns_ + n_species_ + static_cast<std::size_t>(w)];
  }
  std::size_t species() const { return n_species_; }
  // Raw row-major view for the vectorised pair kernel: particle_pair(s, t) is
  // data()[s * columns() + t].
  const ContactCoefficients *data() const { return table_.data(); }
  std::size_t columns() const { return columns_; }
  // One line per interaction type, for the log.
  std::string describe() const;

private:
  std::size_t n_species_ = 0, columns_ = 0;
  std::vector<ContactCoefficients> table_;
  std::vector<AdhesionCoefficients> adhesion_;
  std::vector<std::string> names_;
  bool adhesive_ = false, particles_adhesive_ = false;
  double cutoff_ = 0.0, range_ = 0.0;
};

// The coefficients of one pair of materials (used by the table and by tests).
ContactCoefficients mix_materials(const Material &a, const Material &b, bool b_is_wall,
                                  const std::string &restitution_model);

// The Hamaker constant of two materials that meet: the case's adhesion_pairs entry, else
// √(A_a A_b). Throws, naming the pair, when one has A > 0 and the other none written.
double hamaker_of_pair(const Case &c, const Material &a, const Material &b);

// The material of population `s` as its contacts see it: a toner's Young's modulus scaled by
// dem.toner_stiffness_factor (a softer toner allows a larger time step).
Material contact_material(const Case &c, std::size_t population);

} // namespace magbrush::dem
