// The nip's electrostatic field (Kweon eq. 7–8): −∇·(ε∇Φ) = 0 between the biased sleeve and
// the grounded drum substrate, through the photoconductor layer (thickness t, εr) and the air
// gap, with the latent image either as a surface charge σ(s) on the layer (a face integral on
// the layer/air interface) or as a prescribed surface potential (then the layer itself is not
// meshed: its surface is a Dirichlet boundary). E = −∇Φ by exact differentiation.
//
// The mesh (layered_meshes.h make_nip_mesh) uses the bipolar coordinates of the sleeve and the
// drum surface, so both surfaces and the gap are exact and graded toward the nip by
// themselves.
#pragma once

#include "case/case_model.h"
#include "field_solver/layered_meshes.h"
#include "field_solver/potential_problem.h"

#include <memory>
#include <vector>

namespace magbrush::field {

struct NipDiscretisation
{
  unsigned int degree = 2;
  unsigned int n_tau = 4;      // cells across the air from drum to sleeve
  unsigned int n_sigma = 64;   // cells around (bipolar σ)
  unsigned int n_layer = 1;    // cells across the photoconductor
  unsigned int refinements = 0;
  double solver_tolerance = 1e-12;
  PotentialProblemDescription::LinearSolver linear_solver =
    PotentialProblemDescription::LinearSolver::cg_amg;
  LinearAlgebraBackend linear_algebra = LA; // the configured backend (linear_algebra.h)
};

// The latent image along the drum surface as a function of the arc length s from the nip
// point (the drum surface point nearest the sleeve), s increasing counter-clockwise about the
// drum centre: exposed ("light") where frac(s/period + duty/2) < duty — an exposed strip
// centred on the nip — dark elsewhere; uniformly dark when period = 0. With an edge width w
// the value changes from dark to light along a raised cosine over w centred on each edge. This is the image at
// phase 0 (t ≤ 0 in the DEM); once the drum has turned, the value at s is the one this gives
// at s − u, u the arc length the surface travelled (fields/nip_potential_field.h).
double latent_image_value(const LatentImage &image, double s);

class NipElectrostatics
{
public:
  // `image_shift` u [m]: the image carried along the drum surface by u (the surface value at s
  // is latent_image_value(image, s − u)). The field is linear in (bias, image values): the
  // field stage solves the bias alone and the image alone at its phase samples.
  NipElectrostatics(MPI_Comm communicator, const NipLayout &layout, double layer_eps_r,
                    double bias, const LatentImage &image, const NipDiscretisation &disc,
                    double image_shift = 0.0);
  ~NipElectrostatics();

  void run();

  // Φ at points (collective). Points inside the sleeve get the bias, points inside the drum
  // substrate 0 V (conductors); all others must be in the meshed region.
  std::vector<double> potential(const std::vector<Vec2> &points) const;
  std::vector<Vec2> electric_field(const std::vector<Vec2> &points) const; // meshed region only

  // Φ of the air, continued smoothly below the surfaces that bound it (collective): in the air
  // the solution; at a point inside the sleeve, or below the drum surface (the photoconductor
  // included), the first-order Taylor extension of the air solution from the nearest surface
  // point x_s along the surface normal, Φ(x_s) + ∇Φ(x_s)·(x − x_s), with Φ and ∇Φ taken on the
  // air side. The extension is C1 across the surface (value and both derivatives match), so a
  // spline through grid nodes on both sides interpolates the air field up to the surface
  // without the kink that the conductor's constant value (potential()) puts there. The values
  // below the surfaces are not the potential there: nothing charged is ever inside a solid.
  std::vector<double> air_potential(const std::vector<Vec2> &points) const;

  // Arc length from the nip point along the drum surface of the point x [m].
  double arc_length_from_nip(const Point<2> &x) const;

  void write_vtu(const std::string &directory, const std::string &basename) const;
  const PotentialProblem &problem() const { return *solver; }
  const NipLayout &layout() const { return nip; }

private:
  PotentialProblemDescription describe() const;
  double image_at(const Point<2> &x) const; // the surface value at x (charge or potential)

  MPI_Comm communicator;
  NipLayout nip;
  double layer_eps_r, bias;
  LatentImage image;
  double image_shift;
  NipDiscretisation discretisation;
  dealii::parallel::shared::Triangulation<2> triangulation;
  std::unique_ptr<PotentialProblem> solver;
};

} // namespace magbrush::field
