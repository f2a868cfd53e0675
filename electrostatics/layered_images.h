// The images of a point charge in a grounded conductor covered by a dielectric layer: the drum
// substrate under its photoconductor (relative permittivity εr, thickness L), seen from the
// air above the layer; L = 0 is a bare grounded conductor (the sleeve).
//
// A charge q at height h above the layer's surface (air side). In the Hankel (in-plane
// Fourier) representation the air-side potential is
//
//   φ(ρ, z) = q/(4πε0) ∫_0^∞ J0(kρ) [e^(−k|z−h|) + R(k) e^(−k(z+h))] dk,
//   R(k) = (1 − εr coth kL)/(1 + εr coth kL) = −(β + x)/(1 + βx),   x = e^(−2kL),
//
// β = (εr − 1)/(εr + 1). Expanding R in powers of x turns every term into a point image below
// the surface (depth = distance under the surface):
//
//   c_0 = −β               at depth h,
//   c_n = −(1 − β²)(−β)^(n−1)   at depth h + 2nL   (n ≥ 1),
//
// in units of q. The limits: L → 0 (or εr → ∞) sums to one image −q at depth h, the grounded
// conductor; L → ∞ leaves −β q at depth h, the dielectric half-space. Σ c_n = −1 for any
// finite L (the substrate is grounded: the images carry the opposite charge), and
// Σ n c_n = −1/εr (the dipole moment of the charge and its images is 2q(h + L/εr) per charge:
// a sheet σ on the layer drops the potential by σ(h + L/εr)/ε0 to the substrate).
//
// The series converges like β^n (β = 0.5 at εr = 3): the self force is summed to double
// precision; the pair images (the image of charge j acting on charge i, as sources of the
// Coulomb far field) keep `terms` explicit images and lump the rest into one image at the
// depth that keeps the total charge and dipole moment of the series exact.
#pragma once

#include <vector>

namespace magbrush::electrostatics {

class LayeredImages
{
public:
  // eps_r ≥ 1; thickness ≥ 0 [m] (0: a bare conductor).
  LayeredImages(double eps_r, double thickness);

  double beta() const { return beta_; }
  bool bare_conductor() const { return thickness_ == 0.0 || beta_ == 1.0; }

  // The normal force on a charge q at height h > 0 above the surface from all its images,
  // in units of q²/(4πε0) [1/m²]: F = q²/(4πε0) × self_force(h), positive away from the
  // surface (it is negative: the images attract). Bare conductor: −1/(4h²).
  double self_force(double h) const;

  // The air-side potential of the images of a unit charge at height h, at height z and
  // in-plane distance ρ, in units of q/(4πε0) [1/m] (the potential of the charge itself not
  // included).
  double image_potential(double h, double rho, double z) const;

  // Pair images of a charge at height h: `terms` explicit images and the lumped rest (when
  // the layer is not a bare conductor), as charges in units of q and depths under the
  // surface [m]; `charge` and `depth` are overwritten (size terms + 1, or 1).
  void pair_images(double h, int terms, std::vector<double> &charge, std::vector<double> &depth) const;
  // How many images pair_images() gives for `terms`.
  int pair_image_count(int terms) const { return bare_conductor() ? 1 : terms + 1; }

private:
  double eps_r_, thickness_, beta_;
  int series_terms_; // images summed for the self force (β^n below 1e-17)
};

} // namespace magbrush::electrostatics
