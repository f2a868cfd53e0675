// Fast lookups of the exact two-sphere force for two identical spheres (factor β) in a
// uniform field, tabulated at start-up from the multipole series (two_sphere_exact.h).
//
// What is stored is the short-range CORRECTION to the isolated-pair mutual-dipole force,
//   Δf(D) = f_exact(D) − f_mutual(D),   D = d/a ∈ [2, D_max],
// per μ0 H0² a² (dimensionless), for the three coefficients f∥, f⊥, f_t of the quadratic form
//   F·r̂ = μ0 H0² a² [f∥ cos²ψ + f⊥ sin²ψ],   F·t̂ = μ0 H0² a² f_t sinψ cosψ.
// The table is uniform in u = √(D − 2), which crowds the nodes toward contact where the
// force varies fastest, and interpolated with cubic Catmull–Rom splines (C¹).
#pragma once

#include "magnetics/two_sphere_exact.h"

#include <memory>
#include <vector>

namespace magbrush::magnetics {

class TwoSphereTable
{
public:
  TwoSphereTable(double beta, double D_max, int nodes = 96);

  // A process-wide cache: tables are built once per (β, D_max) and shared (thread-safe).
  static std::shared_ptr<const TwoSphereTable> shared(double beta, double D_max);

  double beta() const { return beta_; }
  double D_max() const { return D_max_; }

  // Dimensionless coefficients (a = 1, H0 = 1, μ0 = 1). D is clamped to [2, D_max].
  TwoSphereForce correction(double D) const;
  TwoSphereForce exact(double D) const;   // = mutual(D) + correction(D)
  TwoSphereForce mutual(double D) const;  // closed form

private:
  double beta_, D_max_, du_;
  std::vector<double> par_, perp_, trans_;
  // Where D falls on the nodes (uniform in √(D − 2)): the interval k and the fraction t in it.
  struct Node
  {
    int k;
    double t;
  };
  Node node(double D) const;
  double interpolate_at(const std::vector<double> &f, const Node &at) const;
};

} // namespace magbrush::magnetics
