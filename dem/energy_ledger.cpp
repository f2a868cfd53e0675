// The energy balance of a run (see energy_ledger.h).
#include "dem/energy_ledger.h"

#include "dem/contact_law.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::dem {

namespace {
std::size_t U(std::int32_t v) { return static_cast<std::size_t>(v); }

// The dashpot's share f_d of the normal force (a = v_rel·n, > 0 approaching), as the contact
// law clamps it: f_n = max(0, F_H + c_n a). Whether a > 0 (f_d = c_n a > 0) or a < 0
// (f_d ∈ [c_n a, 0], the clamp may cut it), f_d a ≥ 0: it only ever dissipates.
struct NormalContact
{
  double hertz_energy, dashpot, force; // [J], f_d [N], f_n [N]
};
NormalContact normal_contact(const ContactCoefficients &c, double R_star, double m_star, double delta, double approach)
{
  const double k_n = HertzNormal::stiffness(c.effective_modulus, R_star);
  const double f_h = HertzNormal::force(k_n, delta);
  const double c_n = ViscoelasticDamping::normal(c.damping_normal, m_star, k_n, delta);
  const double f_n = std::max(0.0, f_h + c_n * approach);
  return {HertzNormal::energy(k_n, delta), f_n - f_h, f_n};
}
} // namespace

EnergyLedger::EnergyLedger(const DemSystem &system)
{
  const ContactTable &table = system.contact_table();
  if (table.adhesive())
    throw std::invalid_argument("energy ledger: the scene has adhesion, whose work it does not account for");
  for (std::size_t k = 0; k < table.species() * table.columns(); ++k)
    if (table.data()[k].friction != 0.0 || table.data()[k].rolling_friction != 0.0)
      throw std::invalid_argument("energy ledger: the scene has friction or rolling friction, whose tangential "
                                  "spring energy and slip losses it does not account for (frictionless contacts only)");
  for (const auto &term : system.force_terms())
    if (std::string(term->name()) != "gravity")
      throw std::invalid_argument(std::string("energy ledger: force term '") + term->name() +
                                  "' is on; only gravity's work is accounted for");
  const Vec3 &g = system.scene_case().dem.gravity;
  for (int a = 0; a < 3; ++a)
    if (g[static_cast<std::size_t>(a)] != 0.0 && system.box().length[static_cast<std::size_t>(a)] > 0.0)
      throw std::invalid_argument("energy ledger: gravity along a periodic axis has no potential energy");
  last_ = forces(system);
  last_time_ = system.time();
  initial_ = system.kinetic_energy() + system.rotational_energy() + last_.elastic + potential(system);
}

// Over the step from t to t + dt velocity Verlet gives each particle exactly
//   ½ m (v₁² − v₀²) = (dt/4) (F₀ + F₁)·(v₀ + v₁)
// for its total force, and so the work of each part of it in the same form: the dashpots'
// work is summed that way (the particle's id links its two ends: the particles are re-sorted
// between steps). The walls' input is the trapezoid of Σ F·v_s; the part of it the dashpot of
// a wall contact takes (F_d·v_s) is work the dashpot did on the wall's motion, not on the
// particle's, and is moved back out of the dissipation.
void EnergyLedger::record(const DemSystem &system)
{
  const Forces now = forces(system);
  const double dt = system.time() - last_time_;
  double dashpot_work = 0.0;
  for (std::size_t id = 0; id < now.present.size(); ++id)
    if (now.present[id] && id < last_.present.size() && last_.present[id])
      dashpot_work += 0.25 * dt * dot(last_.dashpot[id] + now.dashpot[id], last_.velocity[id] + now.velocity[id]);
  const double dashpot_wall = 0.5 * dt * (last_.dashpot_wall_power + now.dashpot_wall_power);
  dissipated_ += -(dashpot_work - dashpot_wall);
  wall_work_ += 0.5 * dt * (last_.wall_power + now.wall_power);
  last_ = now;
  last_time_ = system.time();
}

EnergyLedger::Balance EnergyLedger::balance(const DemSystem &system) const
{
  Balance b;
  b.kinetic = system.kinetic_energy() + system.rotational_energy();
  b.elastic = forces(system).elastic;
  b.gravitational = potential(system);
  b.dissipated = dissipated_;
  b.wall_work = wall_work_;
  b.initial = initial_;
  return b;
}

double EnergyLedger::potential(const DemSystem &system)
{
  const Vec3 &g = system.scene_case().dem.gravity;
  const ParticleState &s = system.particles();
  double e = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i)
    e -= s.mass[i] * (g[0] * s.x[i] + g[1] * s.y[i] + g[2] * s.z[i]);
  return e;
}

EnergyLedger::Forces EnergyLedger::forces(const DemSystem &system)
{
  const ParticleState &s = system.particles();
  const ForceBuffers &F = system.forces();
  const double h = 0.5 * system.time_step();
  Forces out;
  out.elastic = 0.0;
  out.wall_power = out.dashpot_wall_power = 0.0;
  const std::size_t ids = static_cast<std::size_t>(s.id_bound());
  out.dashpot.assign(ids, Vector3{});
  out.velocity.assign(ids, Vector3{});
  out.present.assign(ids, 0);
  // The velocities the contact law saw in this step's force evaluation: v(t + dt/2), the
  // velocity before the final half kick v += (dt/2) F/m (dem_system.h). So the dashpot forces
  // below are the ones the step applied, bit for bit up to rounding.
  std::vector<Vector3> half(s.size());
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    half[i] = {s.vx[i] - h * F.fx[i] * s.inv_mass[i], s.vy[i] - h * F.fy[i] * s.inv_mass[i],
               s.vz[i] - h * F.fz[i] * s.inv_mass[i]};
    out.velocity[U(s.id[i])] = s.velocity(i);
    out.present[U(s.id[i])] = 1;
  }
  const NeighbourList &list = system.neighbour_list();
  const ContactTable &table = system.contact_table();
  // Particle pairs: n from i to j, a = (v_i − v_j)·n (the spins add nothing along n); the
  // dashpot's force on i is −f_d n.
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::int32_t pp = list.row_start[i]; pp < list.row_start[i + 1]; ++pp)
    {
      const std::size_t p = U(pp), j = U(list.partner[p]);
      const Vector3 sh = list.shift(p);
      const Vector3 d{s.x[j] - s.x[i] + sh.x, s.y[j] - s.y[i] + sh.y, s.z[j] - s.z[i] + sh.z};
      const double dist = norm(d), delta = s.radius[i] + s.radius[j] - dist;
      if (delta <= 0.0)
        continue;
      const Vector3 n = (1.0 / dist) * d;
      const double approach = dot(half[i] - half[j], n);
      const double R = s.radius[i] * s.radius[j] / (s.radius[i] + s.radius[j]);
      const double m = s.mass[i] * s.mass[j] / (s.mass[i] + s.mass[j]);
      const NormalContact c = normal_contact(table.particle_pair(s.species[i], s.species[j]), R, m, delta, approach);
      out.elastic += c.hertz_energy;
      out.dashpot[U(s.id[i])] += (-c.dashpot) * n;
      out.dashpot[U(s.id[j])] += c.dashpot * n;
    }
  // Walls at their pose of the present step: the contact force on the particle is −f_n n; the
  // wall moves at v_s where it touches, and puts in (−f_n n)·v_s.
  const DemWalls &walls = system.walls();
  WallContactGeometry g;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t w = 0; w < walls.size(); ++w)
    {
      if (!walls.contact(w, s.position(i), s.radius[i], g) || g.overlap <= 0.0)
        continue;
      const double approach = dot(half[i] - g.surface_velocity, g.n);
      const NormalContact c =
          normal_contact(table.particle_wall(s.species[i], static_cast<int>(w)), s.radius[i], s.mass[i], g.overlap, approach);
      out.elastic += c.hertz_energy;
      out.dashpot[U(s.id[i])] += (-c.dashpot) * g.n;
      out.wall_power += -c.force * dot(g.n, g.surface_velocity);
      out.dashpot_wall_power += -c.dashpot * dot(g.n, g.surface_velocity);
    }
  return out;
}

} // namespace magbrush::dem
