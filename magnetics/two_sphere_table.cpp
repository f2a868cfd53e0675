#include "magnetics/two_sphere_table.h"

#include "magnetics/dipole_physics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

namespace magbrush::magnetics {

TwoSphereTable::TwoSphereTable(double beta, double D_max, int nodes)
  : beta_(beta), D_max_(D_max)
{
  if (!(beta > -0.5 && beta < 1.0))
    throw std::invalid_argument("two-sphere table: expected −0.5 < β < 1, found " +
                                std::to_string(beta) + ".");
  if (!(D_max > 2.0) || nodes < 4)
    throw std::invalid_argument("two-sphere table: expected D_max > 2 and ≥ 4 nodes; found "
                                "D_max = " + std::to_string(D_max) + ", nodes = " +
                                std::to_string(nodes) + ".");
  const double mu = mu_r_from_beta(beta);
  du_ = std::sqrt(D_max - 2.0) / (nodes - 1);
  par_.resize(nodes);
  perp_.resize(nodes);
  trans_.resize(nodes);
  for (int k = 0; k < nodes; ++k)
  {
    const double D = 2.0 + (k * du_) * (k * du_);
    const TwoSphereForce ex = two_sphere_force({1.0, 1.0, mu, mu, D}, 1e-10);
    const TwoSphereForce md = mutual_dipole_pair_force(1.0, beta, D);
    par_[k] = ex.parallel - md.parallel;
    perp_[k] = ex.perpendicular - md.perpendicular;
    trans_[k] = ex.transverse - md.transverse;
  }
}

std::shared_ptr<const TwoSphereTable> TwoSphereTable::shared(double beta, double D_max)
{
  static std::mutex mutex;
  static std::map<std::pair<double, double>, std::shared_ptr<const TwoSphereTable>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto &slot = cache[{beta, D_max}];
  if (!slot)
    slot = std::make_shared<const TwoSphereTable>(beta, D_max);
  return slot;
}

TwoSphereTable::Node TwoSphereTable::node(double D) const
{
  const int n = static_cast<int>(par_.size());
  const double u = std::sqrt(std::clamp(D, 2.0, D_max_) - 2.0) / du_;
  const int k = std::clamp(static_cast<int>(u), 0, n - 2);
  return {k, u - k};
}

double TwoSphereTable::interpolate_at(const std::vector<double> &f, const Node &at) const
{
  const int n = static_cast<int>(f.size());
  const int k = at.k;
  const double t = at.t;
  // Catmull–Rom tangents (second-order one-sided at the ends).
  auto value = [&](int i) { return f[std::clamp(i, 0, n - 1)]; };
  const double m0 = (k == 0) ? 0.5 * (-3 * f[0] + 4 * f[1] - f[2]) : 0.5 * (f[k + 1] - f[k - 1]);
  const double m1 =
    (k + 1 == n - 1) ? 0.5 * (3 * f[n - 1] - 4 * f[n - 2] + f[n - 3]) : 0.5 * (value(k + 2) - f[k]);
  const double t2 = t * t, t3 = t2 * t;
  return (2 * t3 - 3 * t2 + 1) * f[k] + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * f[k + 1] +
         (t3 - t2) * m1;
}

TwoSphereForce TwoSphereTable::correction(double D) const
{
  // (The three tables share their nodes: one square root for all three.)
  const Node at = node(D);
  return {interpolate_at(par_, at), interpolate_at(perp_, at), interpolate_at(trans_, at), 0};
}

TwoSphereForce TwoSphereTable::mutual(double D) const
{
  return mutual_dipole_pair_force(1.0, beta_, std::max(D, 2.0));
}

TwoSphereForce TwoSphereTable::exact(double D) const
{
  const TwoSphereForce c = correction(D), m = mutual(D);
  return {m.parallel + c.parallel, m.perpendicular + c.perpendicular,
          m.transverse + c.transverse, 0};
}

} // namespace magbrush::magnetics
