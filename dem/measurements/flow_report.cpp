// Particles and mass in, out and present; flux through a line (see flow_report.h).
#include "dem/measurements/flow_report.h"

#include "dem/dem_system.h"
#include "dem/measurements/measurement_registry.h"
#include "dem/particle_flow.h"

#include "common/atomic_file.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

namespace magbrush::dem {

namespace {
template <typename T>
T sum(const std::vector<T> &v)
{
  T s{};
  for (const T &x : v)
    s += x;
  return s;
}
} // namespace

FlowReport::FlowReport(const Case &c)
  : settings_(c.flow), statistics_(c.statistics), sleeve_speed_(c.sleeve ? c.sleeve->surface_speed() : 0.0),
    slab_(c.dem.periodic_length),
    flux_(c.flow.flux_angle, c.sleeve && c.sleeve->omega() < 0.0 ? -1.0 : 1.0, c.flow.density_window,
          c.sleeve ? c.sleeve->radius : 1.0, c.dem.periodic_length > 0.0 ? c.dem.periodic_length : 1.0),
    sump_(c.flow.inflow() && c.flow.inflow_supply == "sump")
{
}

void FlowReport::sample(const DemSystem &system)
{
  FlowReportRow row;
  row.time = system.time();
  if (const auto *flow = dynamic_cast<const ParticleFlow *>(system.particle_exchange()))
  {
    if (const ParticleSource *in = flow->source())
    {
      row.in = sum(in->created_count());
      row.in_mass = sum(in->created_mass());
      row.due_mass = in->mass_due(system.time());
      row.declined_mass = in->declined_mass();
      row.sump_mass = in->finite_sump() ? in->sump_stock() : std::nan("");
    }
    if (const ParticleSink *out = flow->sink())
    {
      row.out = sum(out->removed_count());
      row.out_mass = sum(out->removed_mass());
    }
  }
  const ParticleState &s = system.particles();
  row.present = static_cast<long>(s.size());
  for (double m : s.mass)
    row.present_mass += m;
  const LineFluxSample f = flux_.sample(system.time(), s);
  row.crossed = f.crossed;
  row.crossed_mass = f.crossed_mass;
  row.areal_mass = f.areal_mass;
  if (!rows_.empty() && row.time > rows_.back().time)
    row.flux = row.crossed_mass / (row.time - rows_.back().time);
  rows_.push_back(row);
  if (row.time < settings_.average_from)
    return;
  if (window_first_row_ < 0)
    window_first_row_ = static_cast<long>(rows_.size()) - 1;
  else if (sleeve_speed_ > 0.0) // the first row's flux counts crossings before the window
    supplied_flux_.add(row.flux / (sleeve_speed_ * slab_));
  supplied_areal_.add(row.areal_mass);
}

std::vector<SummaryValue> FlowReport::summary() const
{
  const double nan = std::nan("");
  const auto blocks = static_cast<std::size_t>(statistics_.blocks);
  std::vector<SummaryValue> out;
  if (supplied_areal_.size() == 0)
    return out;
  // Neither mean enters the steady-state verdict: a flux counted over 2-deg windows and 20-us
  // intervals scatters by tens of percent from sample to sample (the nip's own means decide).
  out.push_back(summarise(supplied_flux_, blocks, false, "supplied_flux_kg_per_m2", "kg/m^2",
                          "mass flux through the flux line / (sleeve speed x slab): the developer per sleeve area "
                          "carried past it"));
  out.push_back(summarise(supplied_areal_, blocks, false, "supplied_areal_mass_kg_per_m2", "kg/m^2",
                          "developer mass per sleeve area around the flux line"));
  if (sump_ && window_first_row_ >= 0)
  {
    const FlowReportRow &a = rows_[static_cast<std::size_t>(window_first_row_)], &b = rows_.back();
    const double offered = b.due_mass - a.due_mass;
    out.push_back({"inflow_declined_fraction", offered > 0.0 ? (b.declined_mass - a.declined_mass) / offered : nan,
                   nan, nan, "1", "part of the sump's offer left in the sump for want of room in the entry arc"});
  }
  return out;
}

std::string FlowReport::csv() const
{
  std::ostringstream o;
  char line[400];
  std::snprintf(line, sizeof line,
                "# Flow report (magbrush flow report): flux line at %.4g deg, areal mass over +-%.4g deg around it; "
                "sleeve speed %.6g m/s, slab %.6g m\n",
                settings_.flux_angle * 180.0 / M_PI, 0.5 * settings_.density_window * 180.0 / M_PI, sleeve_speed_, slab_);
  o << line;
  o << "# budget: in - out = present - present(first row); due_mass = areal_mass(inflow) x R x sleeve rotation x slab; "
       "with a finite sump (inflow.sump_mass) present_mass + sump_mass is constant\n";
  o << "time_s,in,in_mass_kg,due_mass_kg,out,out_mass_kg,present,present_mass_kg,crossed,crossed_mass_kg,flux_kg_s,"
       "areal_mass_kg_m2,declined_mass_kg,sump_mass_kg\n";
  for (const auto &r : rows_)
  {
    std::snprintf(line, sizeof line, "%.9g,%ld,%.9g,%.9g,%ld,%.9g,%ld,%.9g,%ld,%.9g,%.9g,%.9g,%.9g,%.9g\n", r.time, r.in,
                  r.in_mass, r.due_mass, r.out, r.out_mass, r.present, r.present_mass, r.crossed, r.crossed_mass,
                  r.flux, r.areal_mass, r.declined_mass, r.sump_mass);
    o << line;
  }
  return o.str();
}

void FlowReport::write(const std::string &directory) const
{
  write_text_atomically((std::filesystem::path(directory) / "flow_report.csv").string(), csv());
}

namespace {
const bool registered = register_measurement({"flow report", [](const Case &c) -> std::unique_ptr<Measurement> {
                                                if (!c.flow.inflow() && !c.flow.outflow())
                                                  return nullptr;
                                                return std::make_unique<FlowReport>(c);
                                              }});
} // namespace


// The flux line's previous sample, the rows and the averaging window (Measurement::write_state).
void FlowReport::write_state(StateOut &out) const
{
  flux_.write_state(out);
  out.put_array(rows_);
  supplied_flux_.write_state(out);
  supplied_areal_.write_state(out);
  out.put(window_first_row_);
}

void FlowReport::read_state(StateIn &in)
{
  flux_.read_state(in);
  in.get_array(rows_);
  supplied_flux_.read_state(in);
  supplied_areal_.read_state(in);
  window_first_row_ = in.get<long>();
  if (window_first_row_ >= static_cast<long>(rows_.size()))
    in.fail("is corrupt (the flow report's window starts after its last row)");
}

} // namespace magbrush::dem
