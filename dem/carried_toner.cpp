// Toner carried by its carrier, and its release near the drum (see carried_toner.h).
#include "dem/carried_toner.h"

#include "common/random_engine_state.h"
#include "dem/checkpoint_file.h"
#include "dem/insertion.h"
#include "dem/particle_charges.h"
#include "dem/placement_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::dem {

namespace {
double sphere_mass(double d, double rho) { return rho * M_PI / 6.0 * d * d * d; }
constexpr int attempts_per_toner = 50;
} // namespace

int carried_toner_population(const Case &c)
{
  for (std::size_t s = 0; s < c.populations.size(); ++s)
    if (c.populations[s].carried_until_gap > 0.0)
      return static_cast<int>(s);
  return -1;
}

// The carrier's own mass is what it has without its toner; its moment of inertia is that of
// the solid sphere plus the toner as a thin shell on its surface.
static void set_carrier_inertia(ParticleState &s, std::size_t k)
{
  const double r = s.radius[k], own = s.mass[k] - s.carried_mass[k];
  s.inv_mass[k] = 1.0 / s.mass[k];
  s.inv_inertia[k] = 1.0 / ((0.4 * own + 2.0 / 3.0 * s.carried_mass[k]) * r * r);
}

void load_carried_toner(ParticleState &s, std::size_t k, int count, double m, double q)
{
  s.carried_count[k] += count;
  s.carried_mass[k] += m;
  s.carried_charge[k] += q;
  s.mass[k] += m;
  s.charge[k] += q;
  set_carrier_inertia(s, k);
}

CarriedTonerRelease::CarriedTonerRelease(const Case &c, const DemWalls &walls, const PeriodicBox &box)
  : walls_(walls), box_(box), rng_(c.dem.seed * 0xD1B54A32D192ED03ull + 0xca221ed)
{
  species_ = carried_toner_population(c);
  if (species_ < 0)
    throw std::invalid_argument("populations[].carried_until_gap: no toner population is carried");
  if (!c.drum.present || !c.sleeve)
    throw std::invalid_argument("populations[].carried_until_gap: carried toner is released near the drum, "
                                "and the case has no drum (or no sleeve to place it from)");
  const Population &p = c.populations[static_cast<std::size_t>(species_)];
  population_ = p;
  density_ = c.material(p.material).density;
  size_ = SizeDistribution(p.diameter_mean, p.diameter_std);
  gap_ = p.carried_until_gap;
  const Vec2 centre = c.drum.center(c.sleeve->radius);
  drum_x_ = centre[0];
  drum_y_ = centre[1];
  drum_radius_ = c.drum.radius;
  for (const Population &q : c.populations)
    is_carrier_.push_back(q.kind == ParticleKind::carrier ? 1 : 0);
}

void CarriedTonerRelease::smallest_particles(ParticleState &out) const
{
  out.add({0, 0, 0}, 0.5 * size_.min(), density_, species_, 0.0);
}

// Surface-to-surface distance of particle k to the drum (negative when overlapping it).
double CarriedTonerRelease::drum_gap(const ParticleState &s, std::size_t k) const
{
  return std::hypot(s.x[k] - drum_x_, s.y[k] - drum_y_) - drum_radius_ - s.radius[k];
}

void CarriedTonerRelease::release(ParticleState &state, double t, const std::vector<char> &leaving,
                                  ParticleState &enter)
{
  for (std::size_t k = 0; k < state.size(); ++k)
    if (state.carried_count[k] > 0 && !leaving[k] && drum_gap(state, k) < gap_)
      release_carrier(state, k, t, enter);
}

// Every particle (present or placed this exchange) that a toner touching carrier k could
// overlap, with positions shifted to their periodic image nearest the carrier.
void CarriedTonerRelease::gather_near(const ParticleState &state, const ParticleState &enter, std::size_t k)
{
  near_x_.clear();
  near_r_.clear();
  const Vector3 c = state.position(k);
  const double reach = state.radius[k] + size_.max();
  auto consider = [&](const ParticleState &s, std::size_t j) {
    double d[3] = {s.x[j] - c.x, s.y[j] - c.y, s.z[j] - c.z};
    for (int a = 0; a < 3; ++a)
      if (box_.periodic(a))
      {
        const double L = box_.length[static_cast<std::size_t>(a)];
        d[a] -= L * std::round(d[a] / L);
      }
    const double r = reach + s.radius[j];
    if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < r * r)
    {
      near_x_.push_back({c.x + d[0], c.y + d[1], c.z + d[2]});
      near_r_.push_back(s.radius[j]);
    }
  };
  for (std::size_t j = 0; j < state.size(); ++j)
    if (j != k)
      consider(state, j);
  for (std::size_t j = 0; j < enter.size(); ++j)
    consider(enter, j);
}

bool CarriedTonerRelease::clear(const Vector3 &p, double r, double t) const
{
  for (std::size_t j = 0; j < near_x_.size(); ++j)
  {
    const double dx = near_x_[j].x - p.x, dy = near_x_[j].y - p.y, dz = near_x_[j].z - p.z;
    const double reach = r + near_r_[j];
    if (dx * dx + dy * dy + dz * dz < reach * reach)
      return false;
  }
  for (std::size_t w = 0; w < walls_.size(); ++w)
    if (walls_.distance(w, p, t) < r)
      return false;
  return true;
}

// Carrier k's toner as particles: the diameters drawn and scaled to the carried mass, the
// charges drawn from the population's q/m, each placed touching the carrier where it fits.
void CarriedTonerRelease::release_carrier(ParticleState &state, std::size_t k, double t, ParticleState &enter)
{
  const std::size_t n = static_cast<std::size_t>(state.carried_count[k]);
  d_.resize(n);
  double drawn = 0.0;
  for (double &d : d_)
  {
    d = size_.draw(rng_);
    drawn += sphere_mass(d, density_);
  }
  const double scale = std::cbrt(state.carried_mass[k] / drawn);
  for (double &d : d_)
    d *= scale;
  q_ = draw_charges(population_, d_, density_, rng_);

  const double own_mass = state.mass[k] - state.carried_mass[k];
  gather_near(state, enter, k);
  const Vector3 c = state.position(k), v = state.velocity(k), w = state.angular_velocity(k);
  const double rc = state.radius[k];
  for (std::size_t i = 0; i < n; ++i)
  {
    const double rt = 0.5 * d_[i];
    for (int attempt = 0; attempt < attempts_per_toner; ++attempt)
    {
      const Vector3 p = touching_point(c, rc, rt, rng_);
      if (!clear(p, rt, t))
        continue;
      // Moving with the carrier's surface where it sits.
      const Vector3 u = v + cross(w, p - c);
      Vector3 wrapped = p;
      double *coordinate[3] = {&wrapped.x, &wrapped.y, &wrapped.z};
      for (int a = 0; a < 3; ++a)
        if (box_.periodic(a))
        {
          const double L = box_.length[static_cast<std::size_t>(a)];
          *coordinate[a] -= L * std::floor(*coordinate[a] / L);
        }
      enter.add(wrapped, rt, density_, species_, q_[i]);
      enter.vx.back() = u.x;
      enter.vy.back() = u.y;
      enter.vz.back() = u.z;
      near_x_.push_back(p);
      near_r_.push_back(rt);
      const double m = enter.mass.back();
      if (state.carried_count[k] == 1)
      {
        // The last one: the carrier keeps exactly its own mass (the scaled diameters give the
        // carried mass to rounding), and the charge the draws differ by from what it carried.
        state.mass[k] = own_mass;
        state.carried_mass[k] = 0.0;
        state.carried_charge[k] = 0.0;
        state.carried_count[k] = 0;
        state.charge[k] -= q_[i];
        set_carrier_inertia(state, k);
      }
      else
        load_carried_toner(state, k, -1, -m, -q_[i]);
      ++released_;
      break;
    }
  }
}

void CarriedTonerRelease::recapture(ParticleState &state, std::vector<char> &leaving,
                                    std::vector<std::int32_t> &leave)
{
  // The carriers in a grid of cells one largest carrier diameter wide.
  double d_max = 0.0;
  for (std::size_t k = 0; k < state.size(); ++k)
    if (is_carrier_[static_cast<std::size_t>(state.species[k])])
      d_max = std::max(d_max, 2.0 * state.radius[k]);
  if (d_max <= 0.0)
    return;
  PlacementGrid carriers(d_max, box_);
  for (std::size_t k = 0; k < state.size(); ++k)
    if (is_carrier_[static_cast<std::size_t>(state.species[k])] && !leaving[k])
      carriers.add(state.position(k), k);
  for (std::size_t t = 0; t < state.size(); ++t)
  {
    if (state.species[t] != species_ || leaving[t] || drum_gap(state, t) < gap_)
      continue;
    // The carrier it touches (the nearest surface; ties to the lower index).
    std::size_t on = state.size();
    double nearest = 0.02 * state.radius[t];
    carriers.for_each_near(state, state.position(t), [&](std::size_t k, const double *d) {
      const double g = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - state.radius[k] - state.radius[t];
      if (g < nearest || (g == nearest && k < on))
      {
        nearest = g;
        on = k;
      }
    });
    if (on == state.size() || drum_gap(state, on) <= 2.0 * gap_)
      continue;
    // Momentum kept: the carrier takes the toner's.
    const double mc = state.mass[on], mt = state.mass[t], m = mc + mt;
    state.vx[on] = (mc * state.vx[on] + mt * state.vx[t]) / m;
    state.vy[on] = (mc * state.vy[on] + mt * state.vy[t]) / m;
    state.vz[on] = (mc * state.vz[on] + mt * state.vz[t]) / m;
    load_carried_toner(state, on, 1, mt, state.charge[t]);
    leaving[t] = 1;
    leave.push_back(static_cast<std::int32_t>(t));
    ++recaptured_;
  }
}

void CarriedTonerRelease::write_state(CheckpointWriter &out) const
{
  put_random_engine(out, rng_);
  out.put(released_);
  out.put(recaptured_);
}

void CarriedTonerRelease::read_state(CheckpointReader &in)
{
  get_random_engine(in, rng_);
  released_ = in.get<long>();
  recaptured_ = in.get<long>();
}

} // namespace magbrush::dem
