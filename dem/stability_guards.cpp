#include "dem/stability_guards.h"

#include <cmath>
#include <cstdio>

namespace magbrush::dem {

void StepAlarms::merge(const StepAlarms &other)
{
  overlap_alarm |= other.overlap_alarm;
  if (other.wall_overlap.particle > wall_overlap.particle)
    wall_overlap = other.wall_overlap;
  if (other.wall_crowded.particle > wall_crowded.particle)
    wall_crowded = other.wall_crowded;
  if (other.not_finite.particle >= 0 && (not_finite.particle < 0 || other.not_finite.particle < not_finite.particle))
    not_finite = other.not_finite;
}

std::string StabilityGuards::describe_particle(const ParticleState &s, std::size_t i, const Vector3 &at)
{
  char buf[256];
  std::snprintf(buf, sizeof buf, "particle id %d (species %d, r = %.3g m, at (%.4g, %.4g, %.4g) m)", s.id[i],
                s.species[i], s.radius[i], at.x, at.y, at.z);
  return buf;
}

void StabilityGuards::pair_overlap(const StepClock &clock, const std::string &particle, int partner_id,
                                   double overlap_fraction) const
{
  char msg[768];
  std::snprintf(msg, sizeof msg,
                "stability guard: at step %ld (t = %.6g s) %s overlaps particle id %d by %.1f %% of the smaller "
                "radius (limit dem.max_overlap_fraction = %.1f %%). Contacts are too soft for the loads, "
                "the time step (%.3g s) is too large, or a wall on a prescribed path presses particles that "
                "cannot get out of its way: increase Young's modulus, reduce dem.time_step, slow or stop the "
                "wall earlier, or check the insertion and the force terms",
                clock.step, clock.time, particle.c_str(), partner_id, 100.0 * overlap_fraction,
                100.0 * max_overlap_, clock.dt);
  throw StabilityError(msg);
}

void StabilityGuards::wall_crowded(const StepClock &clock, const std::string &particle, int slots) const
{
  throw StabilityError("wall contacts: " + particle + " touches more than " + std::to_string(slots) +
                       " walls at once at step " + std::to_string(clock.step) +
                       "; the walls overlap or leave a gap smaller than a particle: check the geometry");
}

void StabilityGuards::wall_overlap(const StepClock &clock, const std::string &particle) const
{
  char msg[768];
  std::snprintf(msg, sizeof msg,
                "stability guard: at step %ld (t = %.6g s) %s overlaps a wall by more than %.1f %% of its "
                "radius (dem.max_overlap_fraction). The wall pushes too hard for the contact stiffness or "
                "the time step (%.3g s) is too large: reduce dem.time_step, slow the wall, or increase the "
                "stiffness",
                clock.step, clock.time, particle.c_str(), 100.0 * max_overlap_, clock.dt);
  throw StabilityError(msg);
}

void StabilityGuards::not_finite(const StepClock &clock, const std::string &particle) const
{
  char msg[512];
  std::snprintf(msg, sizeof msg,
                "stability guard: NaN/Inf at step %ld (t = %.6g s) in the state of %s. The time step "
                "(%.3g s) is probably too large for the stiffest contact or force term: reduce "
                "dem.time_step (or time_step_safety), or check the material stiffness and the force terms",
                clock.step, clock.time, particle.c_str(), clock.dt);
  throw StabilityError(msg);
}

void StabilityGuards::check_energy(const StepClock &clock, const ParticleState &s, double ke, double floor)
{
  if (!std::isfinite(ke))
    throw StabilityError("stability guard: kinetic energy is not finite at step " + std::to_string(clock.step) +
                         ": reduce dem.time_step");
  if (last_energy_ >= 0.0 && ke > max_growth_ * std::max(last_energy_, floor))
  {
    // Name the fastest particle: the likely origin of the runaway.
    std::size_t worst = 0;
    double v2max = -1;
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      const double v2 = s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i] + s.vz[i] * s.vz[i];
      if (v2 > v2max)
      {
        v2max = v2;
        worst = i;
      }
    }
    char msg[768];
    std::snprintf(msg, sizeof msg,
                  "stability guard: kinetic energy grew from %.4g J to %.4g J (more than x%.3g, "
                  "dem.max_kinetic_energy_growth) within 100 steps at step %ld (t = %.6g s); fastest: %s at "
                  "%.4g m/s. Energy is being created numerically: reduce dem.time_step (now %.3g s) or the "
                  "contact stiffness, or check the force terms",
                  last_energy_, ke, max_growth_, clock.step, clock.time,
                  describe_particle(s, worst, s.position(worst)).c_str(), std::sqrt(v2max), clock.dt);
    throw StabilityError(msg);
  }
  last_energy_ = ke;
}

} // namespace magbrush::dem
