// The outflow (see particle_sink.h).
#include "dem/particle_sink.h"

#include "dem/carried_toner.h"
#include "dem/checkpoint_file.h"

#include <cmath>

namespace magbrush::dem {

ParticleSink::ParticleSink(const Case &c)
  : angle_(c.flow.outflow_angle), width_(c.flow.outflow_width),
    sense_(c.sleeve && c.sleeve->omega() < 0.0 ? -1.0 : 1.0), outer_radius_(c.flow.outflow_radius),
    count_(c.populations.size(), 0), mass_(c.populations.size(), 0.0)
{
  const int carried = carried_toner_population(c);
  carried_ = carried >= 0 ? static_cast<std::size_t>(carried) : 0;
}

bool ParticleSink::removes(const Vector3 &p) const
{
  if (outer_radius_ > 0.0 && std::hypot(p.x, p.y) > outer_radius_)
    return true;
  if (width_ <= 0.0)
    return false;
  // Angle from the sector's start in the sense of rotation, in [0, 2π).
  double a = sense_ * (std::atan2(p.y, p.x) - angle_);
  a -= 2.0 * M_PI * std::floor(a / (2.0 * M_PI));
  return a <= width_;
}

void ParticleSink::select(const ParticleState &s, std::vector<std::int32_t> &leave)
{
  for (std::size_t i = 0; i < s.size(); ++i)
    if (removes(s.position(i)))
    {
      leave.push_back(static_cast<std::int32_t>(i));
      const std::size_t sp = static_cast<std::size_t>(s.species[i]);
      count_[sp] += 1;
      mass_[sp] += s.mass[i] - s.carried_mass[i];
      if (s.carried_count[i] > 0) // the toner it carries leaves as toner (dem/carried_toner.h)
      {
        count_[carried_] += static_cast<long>(s.carried_count[i]);
        mass_[carried_] += s.carried_mass[i];
      }
    }
}

void ParticleSink::write_state(CheckpointWriter &out) const
{
  out.put_array(count_);
  out.put_array(mass_);
}

void ParticleSink::read_state(CheckpointReader &in)
{
  in.get_array(count_);
  in.get_array(mass_);
}

} // namespace magbrush::dem
