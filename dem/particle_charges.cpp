#include "dem/particle_charges.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace magbrush::dem {

std::mt19937_64 charge_random_stream(const Case &c)
{
  // A fixed odd constant keeps this stream apart from the insertion's, seeded with dem.seed.
  return std::mt19937_64(c.dem.seed ^ 0x9E3779B97F4A7C15ULL);
}

std::vector<double> draw_charges(const Population &p, const std::vector<double> &diameters, double density,
                                 std::mt19937_64 &rng)
{
  std::vector<double> q(diameters.size(), 0.0);
  if (p.counter_charge)
    return q;
  ChargeToMassDraw charge_to_mass(p);
  for (std::size_t k = 0; k < diameters.size(); ++k)
  {
    const double d = diameters[k];
    q[k] = charge_to_mass(rng) * (density * M_PI / 6.0 * d * d * d); // q/m times the sphere's mass
  }
  return q;
}

ChargeToMassDraw::ChargeToMassDraw(const Population &p)
  : mean_(p.charge_to_mass), std_(p.charge_to_mass_std), wrong_(p.wrong_sign_fraction),
    spread_(p.charge_to_mass, std::max(0.0, p.charge_to_mass_std)),
    wrong_sign_(std::clamp(p.wrong_sign_fraction, 0.0, 1.0))
{
}

double ChargeToMassDraw::operator()(std::mt19937_64 &rng)
{
  double qm = mean_;
  if (std_ > 0.0 && mean_ != 0.0)
    do // truncated: the spread never reverses the sign (that is the wrong-sign fraction's job)
      qm = spread_(rng);
    while (qm * mean_ <= 0.0);
  if (wrong_ > 0.0 && wrong_sign_(rng))
    qm = -qm;
  return qm;
}

void assign_counter_charges(const Case &c, ParticleState &particles)
{
  std::vector<char> counter(c.populations.size(), 0);
  bool any = false;
  for (std::size_t s = 0; s < c.populations.size(); ++s)
    any |= (counter[s] = c.populations[s].counter_charge ? 1 : 0) != 0;
  if (!any)
    return;
  double others = 0.0, area = 0.0;
  for (std::size_t k = 0; k < particles.size(); ++k)
  {
    if (counter[static_cast<std::size_t>(particles.species[k])])
    {
      area += particles.radius[k] * particles.radius[k];
      others += particles.carried_charge[k]; // toner it carries (dem/carried_toner.h)
    }
    else
      others += particles.charge[k];
  }
  if (!(area > 0.0))
    return;
  const double per_area = -others / area;
  for (std::size_t k = 0; k < particles.size(); ++k)
    if (counter[static_cast<std::size_t>(particles.species[k])])
      particles.charge[k] = per_area * particles.radius[k] * particles.radius[k] + particles.carried_charge[k];
}

} // namespace magbrush::dem
