// Population sampling and random sequential insertion (see insertion.h).
#include "dem/insertion.h"

#include "dem/carried_toner.h"
#include "dem/placement_grid.h"
#include "dem/particle_charges.h"

#include <algorithm>
#include <functional>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace magbrush::dem {

namespace {
double sphere_mass(double d, double rho) { return rho * M_PI / 6.0 * d * d * d; }

} // namespace

Vector3 touching_point(const Vector3 &centre, double rc, double rt, std::mt19937_64 &rng)
{
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double cz = 2.0 * u(rng) - 1.0, ph = 2.0 * M_PI * u(rng), s = std::sqrt(1.0 - cz * cz);
  const double reach = (rc + rt) * (1.0 + 1e-9);
  return {centre.x + reach * s * std::cos(ph), centre.y + reach * s * std::sin(ph), centre.z + reach * cz};
}

namespace {
// Adds the sphere (q, r) when it is clear of every particle placed so far and of the walls.
bool place_if_clear(const Vector3 &q, double r, double density, std::size_t species, double charge,
                    const DemWalls &walls, PlacementGrid &grid, ParticleState &particles)
{
  if (grid.overlaps(particles, q, r))
    return false;
  for (std::size_t w = 0; w < walls.size(); ++w)
    if (walls.distance(w, q, 0.0) < r)
      return false;
  grid.add(q, particles.size());
  particles.add(q, r, density, static_cast<int>(species), charge);
  return true;
}

// Toner as developer carries it: on the carriers. Carrier by carrier (in the order placed),
// each is owed the concentration times its own mass and gets toner touching its surface at
// random points, clear of every particle and wall; a toner that finds no room on its carrier
// is owed to the next one. The diameters were drawn to the concentration times the whole
// carrier mass, so the owed mass runs out with them; the last few that the running balance
// leaves over go to the carriers in turn.
void attach_to_carriers(const Case &c, const DemWalls &walls, const PeriodicBox &box, std::size_t species,
                        const std::vector<double> &d, const std::vector<double> &charge, PlacementGrid &grid,
                        std::mt19937_64 &rng, ParticleState &particles)
{
  const Population &p = c.populations[species];
  const double rho = c.material(p.material).density;
  std::vector<std::size_t> carriers;
  for (std::size_t k = 0; k < particles.size(); ++k)
    if (c.populations[static_cast<std::size_t>(particles.species[k])].kind == ParticleKind::carrier)
      carriers.push_back(k);
  if (carriers.empty())
    throw std::invalid_argument("population '" + p.name + "': attached toner needs carriers placed before it");
  // One try: toner `t` at a random point of carrier `k`'s surface, touching it.
  auto try_on = [&](std::size_t k, std::size_t t) {
    if (p.carried_until_gap > 0.0)
    {
      // Carried (dem/carried_toner.h): part of the carrier's mass and charge, no particle.
      load_carried_toner(particles, k, 1, sphere_mass(d[t], rho), charge[t]);
      return true;
    }
    const double rt = 0.5 * d[t];
    for (int attempt = 0; attempt < 50; ++attempt)
    {
      Vector3 q = touching_point(particles.position(k), particles.radius[k], rt, rng);
      double *coordinate[3] = {&q.x, &q.y, &q.z};
      for (int a = 0; a < 3; ++a)
        if (box.periodic(a))
        {
          const double L = box.length[static_cast<std::size_t>(a)];
          *coordinate[a] -= L * std::floor(*coordinate[a] / L);
        }
      if (place_if_clear(q, rt, rho, species, charge[t], walls, grid, particles))
        return true;
    }
    return false;
  };
  std::size_t t = 0;
  double owed = 0.0;
  for (std::size_t k : carriers)
  {
    owed += p.concentration * (particles.mass[k] - particles.carried_mass[k]); // its own mass
    while (t < d.size() && owed >= 0.5 * sphere_mass(d[t], rho) && try_on(k, t))
      owed -= sphere_mass(d[t++], rho);
  }
  for (std::size_t turn = 0; t < d.size() && turn < 4 * carriers.size(); ++turn)
    if (try_on(carriers[turn % carriers.size()], t))
      ++t;
  if (t < d.size())
    throw std::runtime_error("insertion of population '" + p.name + "': " + std::to_string(d.size() - t) + " of " +
                             std::to_string(d.size()) + " toner found no room on the carriers' surfaces (a lower "
                             "concentration, or carriers farther apart)");
}
} // namespace

std::vector<double> draw_diameters(const Case &c, const Population &p, double carrier_mass,
                                   std::mt19937_64 &rng)
{
  if (!(p.diameter_mean > 0.0))
    throw std::invalid_argument("population '" + p.name + "': diameter mean must be > 0");
  const double rho = c.material(p.material).density;
  if (!(rho > 0.0))
    throw std::invalid_argument("population '" + p.name + "': material '" + p.material +
                                "' needs a density > 0");
  // Truncated to positive sizes only, not at ±3σ as the particles made during a run are
  // (dem/size_distribution.h): a ±3σ cut redraws ~0.3 % of the draws and so gives every
  // inserted scene another realisation, and the reduced nip's regression guard holds for its
  // own realisation only (its slip at the gap centre over the relative speed scatters 0.76-1.05
  // over six realisations; docs/nip.md). Left so until that guard is made robust.
  std::normal_distribution<double> normal(p.diameter_mean, std::max(0.0, p.diameter_std));
  auto draw = [&]() {
    for (;;) // truncated to positive values: redraw the (rare) non-positive ones
    {
      const double d = p.diameter_std > 0.0 ? normal(rng) : p.diameter_mean;
      if (d > 0.0)
        return d;
    }
  };
  std::vector<double> d;
  if (p.count > 0)
  {
    d.reserve(static_cast<std::size_t>(p.count));
    for (long k = 0; k < p.count; ++k)
      d.push_back(draw());
    return d;
  }
  double target = p.mass;
  // A population the inflow feeds may start empty (checked by the case validation): its
  // particles, and the toner attached to them, all come with the sleeve.
  if (c.flow.inflow() && target <= 0.0 && (p.concentration <= 0.0 || carrier_mass <= 0.0))
    return d;
  if (target <= 0.0 && p.concentration > 0.0)
  {
    if (carrier_mass <= 0.0)
      throw std::invalid_argument("population '" + p.name +
                                  "': a toner concentration needs carrier populations listed before it");
    target = p.concentration * carrier_mass;
  }
  if (!(target > 0.0))
    throw std::invalid_argument("population '" + p.name + "': give one of count, mass or concentration");
  double m = 0.0;
  while (m < target)
  {
    d.push_back(draw());
    m += sphere_mass(d.back(), rho);
  }
  return d;
}

void insert_populations(const Case &c, const DemWalls &walls, const PeriodicBox &box,
                        ParticleState &particles)
{
  std::mt19937_64 rng(c.dem.seed);
  std::vector<std::vector<double>> diameters;
  double carrier_mass = 0.0, d_max = 0.0;
  for (const auto &p : c.populations)
  {
    diameters.push_back(draw_diameters(c, p, carrier_mass, rng));
    const double rho = c.material(p.material).density;
    for (double d : diameters.back())
    {
      if (p.kind == ParticleKind::carrier)
        carrier_mass += sphere_mass(d, rho);
      d_max = std::max(d_max, d);
    }
  }
  PlacementGrid grid(std::max(d_max, 1e-12), box);
  std::mt19937_64 charge_rng = charge_random_stream(c);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t s = 0; s < c.populations.size(); ++s)
  {
    const Population &p = c.populations[s];
    const Material &mat = c.material(p.material);
    auto &d = diameters[s];
    if (d.empty())
      continue; // fed by the inflow only
    std::sort(d.begin(), d.end(), std::greater<double>()); // largest first: jams last
    const std::vector<double> charge = draw_charges(p, d, mat.density, charge_rng);
    if (p.attached)
    {
      attach_to_carriers(c, walls, box, s, d, charge, grid, rng, particles);
      continue;
    }
    // The region's sampler, given the radius.
    std::function<Vector3(double)> sample;
    double region_volume = 0.0;
    if (p.layer_thickness > 0.0)
    {
      if (!c.sleeve)
        throw std::invalid_argument("population '" + p.name + "': a layer on the sleeve needs a sleeve");
      if (!box.periodic(2))
        throw std::invalid_argument("population '" + p.name +
                                    "': a layer on the sleeve needs dem.periodic_length (the slab along z)");
      const double R = c.sleeve->radius, Lz = box.length[2];
      region_volume = M_PI * (std::pow(R + p.layer_thickness, 2) - R * R) * Lz;
      sample = [&, R, Lz](double r) {
        const double a = R + r, b = R + p.layer_thickness - r;
        const double rr = std::sqrt(a * a + u(rng) * (b * b - a * a));
        const double th = 2.0 * M_PI * u(rng);
        return Vector3{rr * std::cos(th), rr * std::sin(th), Lz * u(rng)};
      };
    }
    else if (p.insert_box)
    {
      const auto lo = (*p.insert_box)[0], hi = (*p.insert_box)[1];
      region_volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
      sample = [&, lo, hi](double r) {
        Vector3 q;
        double *out[3] = {&q.x, &q.y, &q.z};
        for (int k = 0; k < 3; ++k)
        {
          const std::size_t ku = static_cast<std::size_t>(k);
          const double margin = box.periodic(k) ? 0.0 : r;
          *out[k] = lo[ku] + margin + u(rng) * (hi[ku] - lo[ku] - 2.0 * margin);
        }
        return q;
      };
    }
    else
      throw std::invalid_argument("population '" + p.name + "': no insertion region (give insert_box or layer_thickness)");

    double solid = 0.0;
    for (double di : d)
      solid += M_PI / 6.0 * di * di * di;
    for (std::size_t k = 0; k < d.size(); ++k)
    {
      const double r = 0.5 * d[k];
      bool placed = false;
      for (int attempt = 0; attempt < 5000 && !placed; ++attempt)
      {
        placed = place_if_clear(sample(r), r, mat.density, s, charge[k], walls, grid, particles);
      }
      if (!placed)
        throw std::runtime_error(
            "insertion of population '" + p.name + "': could not place particle " + std::to_string(k + 1) +
            " of " + std::to_string(d.size()) + " without overlap after 5000 attempts. The region's solid "
            "fraction would be " + std::to_string(100.0 * solid / region_volume) +
            " %; random insertion jams near 30-40 %: enlarge the insertion region (or layer) or insert fewer particles");
    }
  }
  assign_counter_charges(c, particles);
}

} // namespace magbrush::dem
