// Flux through a radial line and areal mass around it (see line_flux.h).
#include "dem/measurements/line_flux.h"

#include <algorithm>
#include <cmath>

namespace magbrush::dem {

LineFlux::LineFlux(double angle, double sense, double window, double sleeve_radius, double slab_length)
  : angle_(angle), sense_(sense), window_(window), R_(sleeve_radius), Lz_(slab_length)
{
}

LineFluxSample LineFlux::sample(double time, const ParticleState &s)
{
  LineFluxSample out;
  out.time = time;
  now_.clear();
  double window_mass = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    if (std::hypot(s.x[i], s.y[i]) > max_radius_)
      continue;
    // Angle from the line in the sense of rotation, in (−π, π].
    const double a = sense_ * std::remainder(std::atan2(s.y[i], s.x[i]) - angle_, 2.0 * M_PI);
    now_.push_back({s.id[i], a, s.mass[i]});
    if (std::abs(a) <= 0.5 * window_)
      window_mass += s.mass[i];
  }
  out.areal_mass = window_mass / (R_ * window_ * Lz_);
  std::sort(now_.begin(), now_.end());
  if (!first_)
  {
    std::size_t p = 0; // merge by id
    for (std::size_t k = 0; k < now_.size(); ++k)
    {
      while (p < before_.size() && before_[p].id < now_[k].id)
        ++p;
      if (p == before_.size() || before_[p].id != now_[k].id)
        continue;
      const double a0 = before_[p].angle, a1 = now_[k].angle;
      if (std::abs(a1 - a0) > 0.5 * M_PI) // the wrap at ±π, opposite the line: no crossing
        continue;
      const int dir = (a0 < 0.0 && a1 >= 0.0) ? 1 : (a0 >= 0.0 && a1 < 0.0) ? -1 : 0;
      out.crossed += dir;
      if (dir != 0)
        out.crossed_mass += dir * now_[k].mass;
    }
  }
  first_ = false;
  before_.swap(now_);
  return out;
}

// Written as three arrays rather than the structs, so that no padding byte reaches the file.
void LineFlux::write_state(StateOut &out) const
{
  out.put<std::uint8_t>(first_);
  std::vector<std::int32_t> ids;
  std::vector<double> angles, masses;
  for (const Seen &s : before_)
  {
    ids.push_back(s.id);
    angles.push_back(s.angle);
    masses.push_back(s.mass);
  }
  out.put_array(ids);
  out.put_array(angles);
  out.put_array(masses);
}

void LineFlux::read_state(StateIn &in)
{
  first_ = in.get<std::uint8_t>() != 0;
  std::vector<std::int32_t> ids;
  std::vector<double> angles, masses;
  in.get_array(ids);
  in.get_array(angles);
  in.get_array(masses);
  if (angles.size() != ids.size() || masses.size() != ids.size())
    in.fail("is corrupt (a line flux's previous sample has arrays of different lengths)");
  before_.clear();
  for (std::size_t k = 0; k < ids.size(); ++k)
    before_.push_back({ids[k], angles[k], masses[k]});
}

} // namespace magbrush::dem
