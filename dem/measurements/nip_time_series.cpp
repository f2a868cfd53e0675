// Bead budget and drum load of the nip over time (see nip_time_series.h).
#include "dem/measurements/nip_time_series.h"

#include "dem/measurements/measurement_registry.h"
#include "dem/measurements/nip_profile.h" // resolve_drum_contact
#include "dem/measurements/sample_series.h"
#include "dem/snapshot_writer.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

namespace magbrush::dem {

namespace {
constexpr std::int8_t unseen = 2;
}

NipTimeSeries::NipTimeSeries(const Case &c)
    : settings_(c.nip), statistics_(c.statistics), frame_(NipFrame::from_case(c))
{
  // The magnetic grid ends at field.grid_outer_radius (0 = sleeve + 3 mm): beyond it no field
  // holds a bead to the brush.
  lost_radius_ = c.field.grid_outer_radius > 0.0 ? c.field.grid_outer_radius : frame_.sleeve_radius + 3e-3;
}

std::int8_t NipTimeSeries::region_of(const Vector3 &p) const
{
  const double theta = frame_.sleeve_angle(p.x, p.y);
  if (theta < -settings_.chain_half_angle)
    return -1;
  if (theta > settings_.chain_half_angle)
    return 1;
  return 0;
}

void NipTimeSeries::add_beads(double time, const std::vector<std::int32_t> &ids, const std::vector<Vector3> &x,
                              const std::vector<double> &radii)
{
  NipBudgetRow row;
  row.time = time;
  row.beads = static_cast<long>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    const Vector3 &p = x[i];
    const double r = std::hypot(p.x - frame_.sx, p.y - frame_.sy);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || r > lost_radius_ ||
        r < frame_.sleeve_radius - radii[i])
    {
      ++row.lost;
      continue;
    }
    const auto id = static_cast<std::size_t>(ids[i]);
    if (id >= region_.size())
      region_.resize(id + 1, unseen);
    const std::int8_t now = region_of(p), before = region_[id];
    // Crossings of the window's edges, net: entering over the upstream edge counts +1, going
    // back over it −1; leaving over the downstream edge +1, coming back −1. A bead carried
    // all the way round (downstream → upstream, outside the window) crosses neither edge.
    if (before != unseen && before != now)
    {
      if (before == -1 && now != -1)
        ++entered_;
      if (now == -1 && before != -1)
        --entered_;
      if (now == 1 && before != 1)
        ++left_;
      if (before == 1 && now != 1)
        --left_;
    }
    region_[id] = now;
    if (now == 0)
      ++row.in_window;
  }
  row.entered = entered_;
  row.left = left_;
  rows_.push_back(row);
}

void NipTimeSeries::sample(const DemSystem &system)
{
  const ParticleState &p = system.particles();
  ids_.assign(p.id.begin(), p.id.end());
  positions_.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    positions_[i] = p.position(i);
  add_beads(system.time(), ids_, positions_, p.radius);
  NipBudgetRow &row = rows_.back();
  // Drum load and the slip near the gap centre.
  std::size_t drum = system.walls().size();
  for (std::size_t w = 0; w < system.walls().size(); ++w)
    if (system.walls().name(w) == "drum")
      drum = w;
  row.centre_slip = std::numeric_limits<double>::quiet_NaN();
  if (drum == system.walls().size())
    return;
  system.wall_contacts(drum, records_);
  double slip = 0.0;
  long at_centre = 0;
  for (const auto &r : records_)
  {
    DrumContact c;
    c.position = p.position(r.particle);
    c.velocity = p.velocity(r.particle);
    c.angular_velocity = p.angular_velocity(r.particle);
    c.radius = p.radius[r.particle];
    c.force_on_wall = r.force_on_wall;
    const DrumContactInFrame f = resolve_drum_contact(frame_, c);
    ++row.drum_touching;
    row.drum_normal_force += f.normal;
    row.drum_tangential_force += f.tangential;
    if (std::abs(f.x) <= 0.5 * settings_.bin_width)
    {
      slip += f.slip;
      ++at_centre;
    }
  }
  if (at_centre > 0)
    row.centre_slip = slip / static_cast<double>(at_centre);
}

std::vector<SummaryValue> NipTimeSeries::summary() const
{
  // The same samples as the nip profile's means (t >= nip.average_from).
  SampleSeries in_window;
  for (const NipBudgetRow &r : rows_)
    if (r.time >= settings_.average_from)
      in_window.add(static_cast<double>(r.in_window));
  SummaryValue v = summarise(in_window, static_cast<std::size_t>(statistics_.blocks), true, "beads_in_nip_window",
                             "1", "beads in the nip window (|sleeve angle| <= nip.chain_half_angle): the nip's state");
  v.state = true;
  return {v};
}

std::string NipTimeSeries::csv() const
{
  std::ostringstream o;
  char line[320];
  std::snprintf(line, sizeof line,
                "# Nip time series (magbrush nip time series): window |sleeve angle| <= %.4g deg; lost = non-finite, "
                "inside the sleeve or beyond r = %.4g mm\n",
                settings_.chain_half_angle * 180.0 / M_PI, lost_radius_ * 1e3);
  o << line;
  o << "# conservation: beads constant; in_window(t) = in_window(0) + entered(t) - left(t)\n";
  o << "time_s,beads,lost,in_window,entered,left,drum_touching,drum_normal_force_N,drum_tangential_force_N,"
       "centre_slip_m_s\n";
  for (const auto &r : rows_)
  {
    std::snprintf(line, sizeof line, "%.9g,%ld,%ld,%ld,%ld,%ld,%ld,%.6g,%.6g,%.6g\n", r.time, r.beads, r.lost,
                  r.in_window, r.entered, r.left, r.drum_touching, r.drum_normal_force, r.drum_tangential_force,
                  r.centre_slip);
    o << line;
  }
  return o.str();
}

void NipTimeSeries::write(const std::string &directory) const
{
  write_file_atomically((std::filesystem::path(directory) / "nip_time_series.csv").string(), csv());
}

namespace {
const bool registered = register_measurement({"nip time series", [](const Case &c) -> std::unique_ptr<Measurement> {
                                                if (!NipFrame::applies(c))
                                                  return nullptr;
                                                return std::make_unique<NipTimeSeries>(c);
                                              }});
} // namespace


// Each bead's region at the last sample (the next crossings are counted against it), the net
// counts and the rows (Measurement::write_state).
void NipTimeSeries::write_state(StateOut &out) const
{
  out.put_array(region_);
  out.put(entered_);
  out.put(left_);
  out.put_array(rows_);
}

void NipTimeSeries::read_state(StateIn &in)
{
  in.get_array(region_);
  entered_ = in.get<long>();
  left_ = in.get<long>();
  in.get_array(rows_);
}

} // namespace magbrush::dem
