// The developer the doctor blade lets through (see developer_mass_per_area.h).
#include "dem/measurements/developer_mass_per_area.h"

#include "dem/dem_system.h"
#include "dem/measurements/measurement_registry.h"

#include "common/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace magbrush::dem {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();
// Random close packing: the densest a poured, unvibrated layer of spheres gets.
constexpr double random_close_packing = 0.64;

const BladeOrGuide *doctor_blade(const Case &c)
{
  for (const auto &b : c.blades)
    if (b.is_doctor_blade)
      return &b;
  return nullptr;
}

// The point of the polygon's boundary nearest the roller axis: the blade's tip.
Vec2 nearest_to_axis(const std::vector<Vec2> &polygon)
{
  Vec2 best{0, 0};
  double best_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < polygon.size(); ++k)
  {
    const Vec2 &a = polygon[k], &b = polygon[(k + 1) % polygon.size()];
    const double ex = b[0] - a[0], ey = b[1] - a[1], e2 = ex * ex + ey * ey;
    const double t = e2 > 0.0 ? std::clamp(-(a[0] * ex + a[1] * ey) / e2, 0.0, 1.0) : 0.0;
    const Vec2 p{a[0] + t * ex, a[1] + t * ey};
    if (p[0] * p[0] + p[1] * p[1] < best_d2)
      best = p, best_d2 = p[0] * p[0] + p[1] * p[1];
  }
  return best;
}
} // namespace

bool DeveloperMassPerArea::applies(const Case &c)
{
  return c.sleeve && c.dem.periodic_length > 0.0 && doctor_blade(c) != nullptr;
}

DeveloperMassPerArea::DeveloperMassPerArea(const Case &c)
  : settings_(c.dma), statistics_(c.statistics), R_(c.sleeve ? c.sleeve->radius : 0.0), Lz_(c.dem.periodic_length),
    sense_(c.sleeve && c.sleeve->omega() < 0.0 ? -1.0 : 1.0), speed_(c.sleeve ? c.sleeve->surface_speed() : 0.0),
    centre_line_(0, 1, 1, 1, 1)
{
  const BladeOrGuide *blade = doctor_blade(c);
  if (!applies(c) || !blade)
    throw std::invalid_argument("developer mass per area: the scene needs a sleeve, a periodic slab "
                                "(dem.periodic_length) and a doctor blade");
  const Vec2 tip = nearest_to_axis(blade->polygon);
  blade_angle_ = std::atan2(tip[1], tip[0]);
  gap_ = std::hypot(tip[0], tip[1]) - R_;
  blade_name_ = blade->name;
  double carrier_density = 0.0, concentration = 0.0;
  for (const auto &p : c.populations)
  {
    is_toner_.push_back(p.kind == ParticleKind::toner);
    if (p.kind == ParticleKind::carrier && carrier_density == 0.0)
      carrier_density = c.material(p.material).density;
    if (p.kind == ParticleKind::toner)
      concentration += p.concentration;
  }
  bulk_density_ = random_close_packing * carrier_density * (1.0 + concentration);
  const double within = R_ + settings_.height;
  centre_line_ = LineFlux(blade_angle_ + sense_ * settings_.after_blade, sense_, settings_.window, R_, Lz_);
  centre_line_.set_max_radius(within);
}

double DeveloperMassPerArea::angle_from(double px, double py, double angle) const
{
  return sense_ * std::remainder(std::atan2(py, px) - angle, 2.0 * M_PI);
}

void DeveloperMassPerArea::sample(const DemSystem &system)
{
  Vector3 force;
  const auto loads = system.wall_loads();
  bool found = false;
  for (std::size_t w = 0; w < system.walls().size(); ++w)
    if (system.walls().name(w) == blade_name_)
    {
      force = {loads[w].force[0], loads[w].force[1], loads[w].force[2]};
      found = true;
    }
  if (!found)
    throw std::runtime_error("developer mass per area: the run has no wall named '" + blade_name_ + "'");
  add_sample(system.time(), system.particles(), force);
}

void DeveloperMassPerArea::add_sample(double time, const ParticleState &s, const Vector3 &force_on_blade)
{
  // The line counters see every sample (a crossing needs the previous position), the means
  // only those from average_from on.
  const LineFluxSample centre = centre_line_.sample(time, s);
  const double dt = previous_time_ >= 0.0 ? time - previous_time_ : 0.0;
  previous_time_ = time;

  Row row;
  row.time = time;
  const double window_centre = blade_angle_ + sense_ * settings_.after_blade;
  double mass = 0.0, toner = 0.0, front = 0.0, gap_mass = 0.0, gap_momentum = 0.0;
  const double gap_half_angle = gap_ / R_;
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    const double a = angle_from(s.x[i], s.y[i], window_centre);
    const double r = std::hypot(s.x[i], s.y[i]), height = r - R_;
    if (std::abs(a) <= 0.5 * settings_.window && height <= settings_.height)
    {
      mass += s.mass[i];
      const auto sp = static_cast<std::size_t>(s.species[i]);
      if (sp < is_toner_.size() && is_toner_[sp])
        toner += s.mass[i];
      toner += s.carried_mass[i]; // carried by a carrier as its own mass (dem/carried_toner.h)
    }
    const double b = angle_from(s.x[i], s.y[i], blade_angle_);
    if (b < 0.0 && b >= -settings_.front_window)
      front += s.mass[i];
    if (std::abs(b) <= gap_half_angle && height <= gap_)
    {
      // angular speed about the axis, in the sense the sleeve turns
      gap_mass += s.mass[i];
      gap_momentum += s.mass[i] * sense_ * (s.x[i] * s.vy[i] - s.y[i] * s.vx[i]) / (r * r);
    }
  }
  row.dma = mass / (R_ * settings_.window * Lz_);
  row.toner_concentration = mass > toner ? toner / (mass - toner) : nan;
  row.dma_flux = dt > 0.0 && speed_ > 0.0 ? centre.crossed_mass / dt / (speed_ * Lz_) : nan;
  // The blade's load along the outward radius through its tip and along the sleeve's motion.
  const double c = std::cos(blade_angle_), sn = std::sin(blade_angle_);
  row.blade_radial = (force_on_blade.x * c + force_on_blade.y * sn) / Lz_;
  row.blade_along = sense_ * (-force_on_blade.x * sn + force_on_blade.y * c) / Lz_;
  row.held_in_front = front / Lz_;
  row.gap_speed_ratio = gap_mass > 0.0 && speed_ > 0.0 ? gap_momentum / gap_mass / (speed_ / R_) : nan;
  rows_.push_back(row);

  if (time < settings_.average_from)
    return;
  dma_.add(row.dma);
  if (!std::isnan(row.dma_flux))
    dma_flux_.add(row.dma_flux);
  if (!std::isnan(row.toner_concentration) && toner > 0.0)
    concentration_.add(row.toner_concentration);
  blade_radial_.add(row.blade_radial);
  blade_along_.add(row.blade_along);
  held_.add(row.held_in_front);
  if (!std::isnan(row.gap_speed_ratio))
    gap_speed_.add(row.gap_speed_ratio);
}

std::vector<SummaryValue> DeveloperMassPerArea::summary() const
{
  const auto blocks = static_cast<std::size_t>(statistics_.blocks);
  auto sampled = [&](const char *key, const SampleSeries &s, bool steady_test, const char *unit, const char *meaning) {
    return summarise(s, blocks, steady_test, key, unit, meaning);
  };
  SummaryValue bound{"dma_kg_per_m2_bound", dma_bound(), nan, nan, "kg/m^2",
                     "bulk density x blade gap: 0.64 rho_carrier (1 + TC) x gap"};
  std::vector<SummaryValue> out = {
      sampled("dma_kg_per_m2", dma_, true, "kg/m^2", "developer mass per sleeve area past the doctor blade"),
      bound,
      sampled("dma_flux_kg_per_m2", dma_flux_, false, "kg/m^2",
              "the same from the mass flux past the window's centre line / (sleeve speed x slab)"),
      sampled("blade_force_N_per_m", blade_radial_, true, "N/m",
              "force of the developer on the doctor blade per slab length, outward along its radius"),
      sampled("blade_drag_N_per_m", blade_along_, false, "N/m",
              "the same along the sleeve's motion at the blade tip"),
      sampled("developer_held_in_front_of_blade_kg_per_m", held_, true, "kg/m",
              "developer mass in the sector just before the blade tip per slab length"),
      sampled("blade_gap_speed_ratio", gap_speed_, false, "1",
              "speed of the developer in the blade's gap / the sleeve's (below 1: the sleeve slides under it)"),
  };
  if (concentration_.size() > 0)
    out.push_back(sampled("toner_concentration_after_blade", concentration_, false, "1",
                          "toner mass / carrier mass in the DMA window"));
  return out;
}

std::string DeveloperMassPerArea::csv() const
{
  std::ostringstream o;
  char line[512];
  std::snprintf(line, sizeof line,
                "# developer on the sleeve (magbrush developer mass per area): doctor blade '%s' at %.4g deg, gap "
                "%.4g mm; window %.4g deg wide centred %.4g deg past it, within %.4g mm of the sleeve; bound %.6g kg/m^2\n",
                blade_name_.c_str(), blade_angle_ * 180.0 / M_PI, gap_ * 1e3, settings_.window * 180.0 / M_PI,
                settings_.after_blade * 180.0 / M_PI, settings_.height * 1e3, dma_bound());
  o << line;
  o << "time_s,dma_kg_per_m2,dma_flux_kg_per_m2,toner_concentration,blade_force_N_per_m,blade_drag_N_per_m,"
       "held_in_front_kg_per_m,gap_speed_ratio\n";
  for (const Row &r : rows_)
  {
    std::snprintf(line, sizeof line, "%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.4g\n", r.time, r.dma, r.dma_flux,
                  r.toner_concentration, r.blade_radial, r.blade_along, r.held_in_front, r.gap_speed_ratio);
    o << line;
  }
  return o.str();
}

void DeveloperMassPerArea::write(const std::string &directory) const
{
  write_text_atomically((std::filesystem::path(directory) / "developer_mass_per_area.csv").string(), csv());
}

namespace {
const bool registered =
  register_measurement({"developer mass per area", [](const Case &c) -> std::unique_ptr<Measurement> {
                          if (!DeveloperMassPerArea::applies(c))
                            return nullptr;
                          return std::make_unique<DeveloperMassPerArea>(c);
                        }});
} // namespace


// The line the flux is counted through, the rows and the series (Measurement::write_state).
void DeveloperMassPerArea::write_state(StateOut &out) const
{
  centre_line_.write_state(out);
  out.put(previous_time_);
  out.put_array(rows_);
  for (const auto *s : {&dma_, &dma_flux_, &concentration_, &blade_radial_, &blade_along_, &held_, &gap_speed_})
    s->write_state(out);
}

void DeveloperMassPerArea::read_state(StateIn &in)
{
  centre_line_.read_state(in);
  previous_time_ = in.get<double>();
  in.get_array(rows_);
  for (auto *s : {&dma_, &dma_flux_, &concentration_, &blade_radial_, &blade_along_, &held_, &gap_speed_})
    s->read_state(in);
}

} // namespace magbrush::dem
