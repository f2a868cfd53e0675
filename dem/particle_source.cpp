// The inflow on the sleeve (see particle_source.h).
#include "dem/particle_source.h"

#include "common/random_engine_state.h"
#include "dem/carried_toner.h"
#include "dem/checkpoint_file.h"
#include "dem/insertion.h"
#include "dem/particle_charges.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::dem {

namespace {
double sphere_mass(double d, double rho) { return rho * M_PI / 6.0 * d * d * d; }
constexpr int carrier_attempts = 200, toner_attempts = 50;
} // namespace

ParticleSource::ParticleSource(const Case &c, const DemWalls &walls, const PeriodicBox &box)
  : walls_(walls), box_(box), rng_(c.dem.seed * 0x9E3779B97F4A7C15ull + 0x5eed)
{
  const FlowSettings &f = c.flow;
  if (!c.sleeve)
    throw std::invalid_argument("inflow.areal_mass: the inflow feeds the sleeve, and the case has none");
  if (!box.periodic(2))
    throw std::invalid_argument("inflow.areal_mass: the inflow needs dem.periodic_length (the slab along the roller axis)");
  auto feed_of = [&c](std::size_t s) {
    const Population &p = c.populations[s];
    Feed fd;
    fd.species = static_cast<int>(s);
    fd.density = c.material(p.material).density;
    fd.size = SizeDistribution(p.diameter_mean, p.diameter_std);
    fd.population = p;
    fd.concentration = p.concentration;
    fd.carried = p.carried_until_gap > 0.0;
    return fd;
  };
  int carrier = -1;
  for (std::size_t s = 0; s < c.populations.size(); ++s)
  {
    const Population &p = c.populations[s];
    if (p.kind == ParticleKind::carrier && carrier < 0 &&
        (f.inflow_population.empty() || f.inflow_population == p.name))
      carrier = static_cast<int>(s);
    if (p.kind == ParticleKind::toner && p.concentration > 0.0)
      toner_.push_back(feed_of(s));
  }
  if (carrier < 0)
    throw std::invalid_argument(f.inflow_population.empty()
                                    ? "inflow.population: the case has no carrier population to feed"
                                    : "inflow.population: no carrier population named '" + f.inflow_population + "'");
  carrier_ = feed_of(static_cast<std::size_t>(carrier));
  double tc = 0.0;
  for (const Feed &t : toner_)
    tc += t.concentration;
  R_ = c.sleeve->radius;
  Lz_ = box.length[2];
  height_ = f.inflow_layer_height;
  theta_in_ = f.inflow_angle;
  omega_ = c.sleeve->omega();
  spin_up_ = c.sleeve->spin_up_time;
  areal_mass_ = f.inflow_areal_mass;
  sump_ = f.inflow_supply == "sump";
  prefill_arc_ = f.inflow_prefill_arc;
  prefill_thins_ = f.inflow_prefill_no_room == "thin";
  prefill_at_rest_ = c.dem.settle_time > 0.0;
  carrier_share_ = 1.0 / (1.0 + tc);
  // Random insertion jams near 30-40 % solid; refuse a layer that would need more.
  const double free_height = height_ - carrier_.size.mean();
  const double solid = free_height > 0.0 ? carrier_share_ * areal_mass_ / (carrier_.density * free_height) : 1.0;
  if (solid > 0.3)
    throw std::invalid_argument("inflow.layer_height: a layer of " + std::to_string(height_ * 1e3) +
                                " mm cannot hold inflow.areal_mass = " + std::to_string(areal_mass_) +
                                " kg/m^2 of carriers by random placement (" + std::to_string(100.0 * solid) +
                                " % solid; at most 30 %): raise inflow.layer_height to at least " +
                                std::to_string(1e3 * (carrier_share_ * areal_mass_ / (0.3 * carrier_.density) + carrier_.size.mean())) + " mm");
  owed_toner_.assign(toner_.size(), 0.0);
  count_.assign(c.populations.size(), 0);
  mass_.assign(c.populations.size(), 0.0);
  finite_sump_ = sump_ && f.inflow_sump_mass > 0.0;
  if (finite_sump_)
  {
    // The sump's developer in the feed's proportions: carriers 1/(1 + ΣTC), each toner TC/(1 + ΣTC).
    const double total = f.inflow_sump_mass * Lz_;
    stock_.assign(c.populations.size(), 0.0);
    stock_[static_cast<std::size_t>(carrier_.species)] = carrier_share_ * total;
    for (const Feed &t : toner_)
      stock_[static_cast<std::size_t>(t.species)] = carrier_share_ * t.concentration * total;
  }
}

double ParticleSource::sump_stock() const
{
  double s = 0.0;
  for (double m : stock_)
    s += m;
  return s;
}

void ParticleSource::return_to_sump(int species, double m)
{
  if (finite_sump_ && species >= 0 && static_cast<std::size_t>(species) < stock_.size())
    stock_[static_cast<std::size_t>(species)] += m;
}

// Whether a finite sump still holds a particle of mass m of this feed (always, without one).
bool ParticleSource::in_stock(const Feed &f, double m) const
{
  return !finite_sump_ || !drawing_ || stock_[static_cast<std::size_t>(f.species)] >= m;
}

double ParticleSource::sleeve_rotation(double t) const
{
  if (t <= 0.0)
    return 0.0;
  if (spin_up_ > 0.0 && t < spin_up_)
    return omega_ * t * t / (2.0 * spin_up_);
  return omega_ * (t - 0.5 * spin_up_);
}

void ParticleSource::smallest_particles(ParticleState &out) const
{
  out.add({0, 0, 0}, 0.5 * carrier_.size.min(), carrier_.density, carrier_.species, 0.0);
  for (const Feed &t : toner_)
    out.add({0, 0, 0}, 0.5 * t.size.min(), t.density, t.species, 0.0);
}

double ParticleSource::draw_diameter(const Feed &f) { return f.size.draw(rng_); }

// The particles present within reach of the arc θ0 … θ0 + Δφ (and of the layer).
void ParticleSource::gather_near(const ParticleState &s, double theta0, double dphi)
{
  near_x_.clear();
  near_r_.clear();
  add_near(s, theta0, dphi);
}

// Adds the particles of `s` within reach of the arc to those gathered.
void ParticleSource::add_near(const ParticleState &s, double theta0, double dphi)
{
  double d_big = carrier_.size.max();
  for (const Feed &t : toner_)
    d_big = std::max(d_big, carrier_.size.max() + 2.0 * t.size.max());
  const double mid = theta0 + 0.5 * dphi, half = 0.5 * std::abs(dphi) + (height_ + 2.0 * d_big) / R_;
  const double r_out = R_ + height_ + 2.0 * d_big;
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    const double r = std::hypot(s.x[i], s.y[i]);
    if (r > r_out)
      continue;
    const double a = std::remainder(std::atan2(s.y[i], s.x[i]) - mid, 2.0 * M_PI);
    if (std::abs(a) > half)
      continue;
    near_x_.push_back(s.position(i));
    near_r_.push_back(s.radius[i]);
  }
}

bool ParticleSource::clear_of_everything(const Vector3 &p, double r) const
{
  for (std::size_t k = 0; k < near_x_.size(); ++k)
  {
    double dz = near_x_[k].z - p.z;
    dz -= Lz_ * std::round(dz / Lz_);
    const double dx = near_x_[k].x - p.x, dy = near_x_[k].y - p.y, reach = r + near_r_[k];
    if (dx * dx + dy * dy + dz * dz < reach * reach)
      return false;
  }
  for (std::size_t w = 0; w < walls_.size(); ++w)
    if (walls_.distance(w, p, t_last_) < r)
      return false;
  return true;
}

void ParticleSource::append(const Feed &f, const Vector3 &p, double d, double t, double charge, ParticleState &enter)
{
  enter.add(p, 0.5 * d, f.density, f.species, charge);
  // Rigidly with the sleeve: v = ω ẑ × x, spin ω ẑ.
  const double w = spin_up_ > 0.0 && t < spin_up_ ? omega_ * t / spin_up_ : omega_;
  enter.vx.back() = -w * p.y;
  enter.vy.back() = w * p.x;
  enter.wz.back() = w;
  near_x_.push_back(p);
  near_r_.push_back(0.5 * d);
  count_created(f, enter.mass.back());
}

// A particle of feed f and mass m created: drawn from a finite sump, counted.
void ParticleSource::count_created(const Feed &f, double m)
{
  if (finite_sump_ && drawing_)
    stock_[static_cast<std::size_t>(f.species)] -= m;
  count_[static_cast<std::size_t>(f.species)] += 1;
  mass_[static_cast<std::size_t>(f.species)] += m;
}

bool ParticleSource::place_carrier(double d, double theta0, double dphi, double t, ParticleState &enter)
{
  const double r = 0.5 * d, a = R_ + r, b = R_ + height_ - r;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int attempt = 0; attempt < carrier_attempts; ++attempt)
  {
    const double rr = std::sqrt(a * a + u(rng_) * (b * b - a * a));
    const double th = theta0 + dphi * u(rng_);
    const Vector3 p{rr * std::cos(th), rr * std::sin(th), Lz_ * u(rng_)};
    if (!clear_of_everything(p, r))
      continue;
    const std::size_t carrier = enter.size();
    append(carrier_, p, d, t, ChargeToMassDraw(carrier_.population)(rng_) * sphere_mass(d, carrier_.density), enter);
    attach_toner(p, r, t, enter);
    if (carrier_.population.counter_charge)
    {
      // "The carrier has the opposite charge of the toner on its surface": its own charge is
      // minus that of all the toner it brings, so that with the toner it carries (already in
      // its charge) it holds minus the charge of the toner attached to it as particles.
      double toner = 0.0;
      for (std::size_t k = carrier + 1; k < enter.size(); ++k)
        toner += enter.charge[k];
      enter.charge[carrier] = -toner;
    }
    return true;
  }
  return false;
}

void ParticleSource::attach_toner(const Vector3 &c, double rc, double t, ParticleState &enter)
{
  const double mc = sphere_mass(2.0 * rc, carrier_.density);
  const std::size_t carrier = enter.size() - 1; // just appended
  for (std::size_t k = 0; k < toner_.size(); ++k)
  {
    const Feed &f = toner_[k];
    ChargeToMassDraw charge_to_mass(f.population); // the population's q/m, spread and wrong sign
    owed_toner_[k] += f.concentration * mc;
    for (;;)
    {
      const double d = draw_diameter(f), m = sphere_mass(d, f.density);
      if (owed_toner_[k] < 0.5 * m || !in_stock(f, m))
        break;
      const double q = charge_to_mass(rng_) * m;
      if (f.carried)
      {
        // Carried (dem/carried_toner.h): part of the carrier's mass and charge, no particle.
        load_carried_toner(enter, carrier, 1, m, q);
        count_created(f, m);
        owed_toner_[k] -= m;
        continue;
      }
      bool placed = false;
      for (int attempt = 0; attempt < toner_attempts && !placed; ++attempt)
      {
        // A random point of the carrier's surface; the toner touches it without overlap.
        Vector3 p = touching_point(c, rc, 0.5 * d, rng_);
        p.z -= Lz_ * std::floor(p.z / Lz_);
        if (!clear_of_everything(p, 0.5 * d))
          continue;
        append(f, p, d, t, q, enter);
        owed_toner_[k] -= m;
        placed = true;
      }
      if (!placed)
        break; // owed to the next carrier
    }
  }
}

void ParticleSource::create(const ParticleState &state, double t, ParticleState &enter)
{
  const double dphi = sleeve_rotation(t) - sleeve_rotation(t_last_);
  t_last_ = t;
  if (dphi == 0.0)
    return;
  owed_carrier_ += carrier_share_ * areal_mass_ * R_ * std::abs(dphi) * Lz_;
  // The arc the new carriers' centres go into: the one swept, but at least two diameters long
  // (an exchange every few steps sweeps far less than a bead; what does not fit waits).
  const double span = std::copysign(std::max(std::abs(dphi), 2.0 * carrier_.size.max() / R_), dphi);
  gather_near(state, theta_in_, span);
  drawing_ = true;
  fill_owed(t, theta_in_, span, sump_, enter);
  drawing_ = false;
  check_owed();
}

// Places the carriers owed (with their toner) into the arc θ0 … θ0 + span; with `may_decline`
// (a sump) what finds no room stays in the sump. False when a carrier found no room and may
// not be declined.
bool ParticleSource::fill_owed(double t, double theta0, double span, bool may_decline, ParticleState &enter)
{
  for (;;)
  {
    const double d = pending_d_ > 0.0 ? pending_d_ : draw_diameter(carrier_);
    pending_d_ = d;
    // Whole particles; what is owed below half a particle waits for the next exchange.
    if (owed_carrier_ < 0.5 * sphere_mass(d, carrier_.density))
      break;
    if (!in_stock(carrier_, sphere_mass(d, carrier_.density)))
    {
      owed_carrier_ = 0.0; // an empty sump offers nothing: not declined, not owed
      break;
    }
    if (!place_carrier(d, theta0, span, t, enter))
    {
      if (!may_decline)
        return false;
      declined_mass_ += owed_carrier_; // no room: the rest stays in the sump
      owed_carrier_ = 0.0;
      break;
    }
    owed_carrier_ -= sphere_mass(d, carrier_.density);
    pending_d_ = 0.0;
  }
  return true;
}

// The layer over the prefill arc, walked downstream in pieces two diameters long, each given
// the mass the layer holds over it. What a piece has no room for moves on to the next (as in
// the run's inflow). A backlog of a whole piece's mass (at least ten carriers) means the layer
// does not fit there: a wall in the way leaves most of a piece unplaced at once, while random
// placement near its packing limit only falls behind by a fraction of a carrier per piece,
// which the pieces downstream take up.
//
// Where it does not fit, the layer is refused (inflow.prefill_where_no_room: refuse) or thinned
// (thin): a piece's shortfall beyond two carriers is dropped (counted in prefill_thinned_mass;
// a smaller one, the random placement's lag, moves on as before), and from there on every
// piece is given only the fraction of the layer's mass that the narrowest piece so far took,
// since a layer that passes a gap carries on downstream what the gap let through, not what the
// sleeve brought to it.
void ParticleSource::prefill(const ParticleState &present, ParticleState &add)
{
  if (prefill_arc_ <= 0.0)
    return;
  const auto created_count = count_;
  const auto created_mass = mass_;
  const std::size_t first = add.size();
  const double sense = omega_ < 0.0 ? -1.0 : 1.0;
  const double piece = 2.0 * carrier_.size.max() / R_;
  const int pieces = std::max(1, static_cast<int>(std::ceil(prefill_arc_ / piece)));
  const double span = sense * prefill_arc_ / pieces;
  const double per_piece = carrier_share_ * areal_mass_ * R_ * std::abs(span) * Lz_;
  const double backlog = std::max(per_piece, 10.0 * sphere_mass(carrier_.size.mean(), carrier_.density));
  // Thin: a piece that leaves more than two carriers unplaced has no room for the layer (random
  // placement near its packing limit falls behind by a fraction of one).
  const double shortfall = 2.0 * sphere_mass(carrier_.size.mean(), carrier_.density);
  double passed = 1.0; // the fraction of the layer the narrowest piece so far took (thin)
  for (int k = 0; k < pieces; ++k)
  {
    const double theta0 = theta_in_ + k * span;
    const double given = passed * per_piece;
    prefill_withheld_mass_ += per_piece - given;
    const double owed_before = owed_carrier_ + given;
    owed_carrier_ += given;
    gather_near(present, theta0, span);
    add_near(add, theta0, span);
    fill_owed(0.0, theta0, span, /*may_decline=*/false, add); // the layer is given, not offered
    if (owed_carrier_ > shortfall && prefill_thins_)
    {
      // What this piece took is what passes on (pending_d_: a drawn carrier that did not fit
      // is drawn anew downstream).
      const double took = (owed_before - owed_carrier_) / per_piece;
      if (took < passed)
      {
        passed = took;
        prefill_narrowest_ = theta0 + 0.5 * span;
      }
      prefill_thinned_mass_ += owed_carrier_;
      owed_carrier_ = 0.0;
      pending_d_ = 0.0;
    }
    if (owed_carrier_ > backlog)
    {
      throw std::invalid_argument(
          "inflow.prefill_arc: the layer of inflow.areal_mass does not fit between the sleeve and the walls at " +
          std::to_string((theta0 + 0.5 * span) * 180.0 / M_PI) + " deg (within inflow.layer_height of the sleeve): "
          "end the prefill arc before it, or lower inflow.layer_height or inflow.areal_mass");
    }
  }
  // What is left (below half a particle) is not carried over into the run's inflow.
  prefill_passed_ = passed;
  owed_carrier_ = 0.0;
  pending_d_ = 0.0;
  std::fill(owed_toner_.begin(), owed_toner_.end(), 0.0);
  count_ = created_count;
  mass_ = created_mass;
  for (std::size_t i = first; i < add.size(); ++i)
  {
    ++prefilled_count_;
    prefilled_mass_ += add.mass[i];
    if (prefill_at_rest_) // the scene settles with the walls at rest first
      add.vx[i] = add.vy[i] = add.vz[i] = add.wx[i] = add.wy[i] = add.wz[i] = 0.0;
  }
}

// After create()'s placement: a fixed supply that has fallen far behind what it owes stops.
void ParticleSource::check_owed() const
{
  const double mean_mass = sphere_mass(carrier_.size.mean(), carrier_.density);
  if (owed_carrier_ > 50.0 * mean_mass)
    throw std::runtime_error("inflow: the developer owed (" + std::to_string(owed_carrier_ / mean_mass) +
                             " carriers) does not fit into the entry arc: the particles there do not move on "
                             "with the sleeve, or inflow.layer_height is too thin for inflow.areal_mass");
}

void ParticleSource::write_state(CheckpointWriter &out) const
{
  put_random_engine(out, rng_);
  out.put(t_last_);
  out.put(owed_carrier_);
  out.put(pending_d_);
  out.put(declined_mass_);
  out.put_array(owed_toner_);
  out.put_array(count_);
  out.put_array(mass_);
  if (finite_sump_) // only then: checkpoints of cases without one read as before
    out.put_array(stock_);
}

void ParticleSource::read_state(CheckpointReader &in)
{
  get_random_engine(in, rng_);
  t_last_ = in.get<double>();
  owed_carrier_ = in.get<double>();
  pending_d_ = in.get<double>();
  declined_mass_ = in.get<double>();
  in.get_array(owed_toner_);
  in.get_array(count_);
  in.get_array(mass_);
  if (finite_sump_)
    in.get_array(stock_);
}

} // namespace magbrush::dem
