#include "electrostatics/layered_images.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::electrostatics {

LayeredImages::LayeredImages(double eps_r, double thickness)
  : eps_r_(eps_r), thickness_(thickness), beta_((eps_r - 1.0) / (eps_r + 1.0))
{
  if (!(eps_r >= 1.0) || !(thickness >= 0.0))
    throw std::invalid_argument("layered images: expected εr ≥ 1 and a thickness ≥ 0, found εr = " +
                                std::to_string(eps_r) + ", thickness " + std::to_string(thickness) + " m.");
  // Terms until |β|^n < 1e-17 (the 1/n² of the distances only helps).
  series_terms_ = beta_ > 0.0 ? static_cast<int>(std::ceil(std::log(1e-17) / std::log(beta_))) + 1 : 1;
  if (series_terms_ > 100000)
    series_terms_ = 100000;
}

double LayeredImages::self_force(double h) const
{
  // F/(q²/4πε0) = Σ c_n / (2h + 2nL)²: the distance from the charge to image n.
  if (bare_conductor())
    return -1.0 / (4.0 * h * h);
  const double L = thickness_;
  double sum = -beta_ / (4.0 * h * h);
  double c = -(1.0 - beta_ * beta_);
  for (int n = 1; n <= series_terms_; ++n)
  {
    const double d = 2.0 * h + 2.0 * n * L;
    sum += c / (d * d);
    c *= -beta_;
  }
  return sum;
}

double LayeredImages::image_potential(double h, double rho, double z) const
{
  auto at = [&](double depth) { return 1.0 / std::sqrt(rho * rho + (z + depth) * (z + depth)); };
  if (bare_conductor())
    return -at(h);
  double sum = -beta_ * at(h);
  double c = -(1.0 - beta_ * beta_);
  for (int n = 1; n <= series_terms_; ++n)
  {
    sum += c * at(h + 2.0 * n * thickness_);
    c *= -beta_;
  }
  return sum;
}

void LayeredImages::pair_images(double h, int terms, std::vector<double> &charge, std::vector<double> &depth) const
{
  if (terms < 1)
    throw std::invalid_argument("layered images: pair images need at least one explicit term; found " +
                                std::to_string(terms) + ".");
  charge.clear();
  depth.clear();
  if (bare_conductor())
  {
    charge.push_back(-1.0);
    depth.push_back(h);
    return;
  }
  // Explicit images n = 0 … terms − 1.
  const double L = thickness_;
  double c = -(1.0 - beta_ * beta_);
  charge.push_back(-beta_);
  depth.push_back(h);
  for (int n = 1; n < terms; ++n)
  {
    charge.push_back(c);
    depth.push_back(h + 2.0 * n * L);
    c *= -beta_;
  }
  // The rest, n ≥ K = terms: Σ c_n = −(1 − β)(−β)^(K−1)·(…) in closed form, with x = −β:
  //   Σ_{n≥K} c_n = −(1 − β²) x^(K−1)/(1 − x),
  //   Σ_{n≥K} n c_n / Σ_{n≥K} c_n = K + x/(1 − x),
  // so the lumped image sits at depth h + 2L (K − β/(1 + β)) and keeps the series' total
  // charge and dipole moment.
  const double x = -beta_;
  const double rest = -(1.0 - beta_ * beta_) * std::pow(x, terms - 1) / (1.0 - x);
  charge.push_back(rest);
  depth.push_back(h + 2.0 * L * (terms + x / (1.0 - x)));
}

} // namespace magbrush::electrostatics
