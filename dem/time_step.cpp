// Rayleigh/Hertz time-step criterion (see time_step.h).
#include "dem/time_step.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace magbrush::dem {

namespace {
double hertz_duration(double m_star, double R_star, double E_star, double v)
{
  return 2.868 * std::pow(m_star * m_star / (R_star * E_star * E_star * v), 0.2);
}
} // namespace

StableTimeStep stable_time_step(const ParticleState &particles,
                                const std::vector<Material> &species_materials,
                                const std::vector<std::string> &species_names,
                                const ContactTable &table, std::size_t n_walls, double impact_speed,
                                const std::vector<char> *excluded)
{
  const std::size_t S = species_materials.size();
  std::vector<double> r_min(S, std::numeric_limits<double>::max()), m_min(S, std::numeric_limits<double>::max());
  for (std::size_t i = 0; i < particles.size(); ++i)
  {
    const std::size_t s = static_cast<std::size_t>(particles.species[i]);
    if (excluded && (*excluded)[s])
      continue;
    r_min[s] = std::min(r_min[s], particles.radius[i]);
    m_min[s] = std::min(m_min[s], particles.mass[i]);
  }
  StableTimeStep out;
  out.impact_speed = impact_speed;
  out.rayleigh = out.hertz = std::numeric_limits<double>::max();
  std::string rayleigh_who, hertz_who;
  for (std::size_t s = 0; s < S; ++s)
  {
    if (r_min[s] == std::numeric_limits<double>::max())
      continue; // no particle of this species
    const Material &m = species_materials[s];
    const double G = m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
    const double tr = M_PI * r_min[s] * std::sqrt(m.density / G) / (0.1631 * m.poisson_ratio + 0.8766);
    if (tr < out.rayleigh)
    {
      out.rayleigh = tr;
      rayleigh_who = "Rayleigh time of the smallest '" + species_names[s] + "' particle";
    }
    for (std::size_t t = 0; t < S + n_walls; ++t)
    {
      const bool wall = t >= S;
      if (!wall && r_min[t] == std::numeric_limits<double>::max())
        continue;
      const auto &c = wall ? table.particle_wall(static_cast<int>(s), static_cast<int>(t - S))
                           : table.particle_pair(static_cast<int>(s), static_cast<int>(t));
      const double R_star = wall ? r_min[s] : r_min[s] * r_min[t] / (r_min[s] + r_min[t]);
      const double m_star = wall ? m_min[s] : m_min[s] * m_min[t] / (m_min[s] + m_min[t]);
      const double tc = hertz_duration(m_star, R_star, c.effective_modulus, impact_speed) / 10.0;
      if (tc < out.hertz)
      {
        out.hertz = tc;
        hertz_who = "Hertz contact time / 10 of the lightest '" + species_names[s] + "' against " +
                    (wall ? "wall " + std::to_string(t - S) : "'" + species_names[t] + "'");
      }
    }
  }
  if (out.rayleigh == std::numeric_limits<double>::max())
    throw std::invalid_argument("time step: no particles to derive a stable time step from");
  out.limit = std::min(out.rayleigh, out.hertz);
  out.limiting = out.rayleigh <= out.hertz ? rayleigh_who : hertz_who;
  return out;
}

double choose_time_step(const DemSettings &settings, const StableTimeStep &limit)
{
  if (settings.time_step <= 0.0)
  {
    if (!(settings.time_step_safety > 0.0 && settings.time_step_safety <= 1.0))
      throw std::invalid_argument("dem.time_step_safety must lie in (0, 1], got " +
                                  std::to_string(settings.time_step_safety));
    return settings.time_step_safety * limit.limit;
  }
  if (settings.time_step > limit.limit)
  {
    char msg[512];
    std::snprintf(msg, sizeof msg,
                  "dem.time_step = %.4g s is above the stable limit %.4g s (%s; Rayleigh %.4g s, Hertz "
                  "t_c/10 %.4g s at %.3g m/s). Use a step <= %.4g s, or leave time_step at 0 for the "
                  "automatic step (%.2g x limit)",
                  settings.time_step, limit.limit, limit.limiting.c_str(), limit.rayleigh, limit.hertz,
                  limit.impact_speed, limit.limit, settings.time_step_safety);
    throw std::invalid_argument(msg);
  }
  return settings.time_step;
}

} // namespace magbrush::dem
