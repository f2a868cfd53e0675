// Separation at release (see developer_release.h).
#include "dem/measurements/developer_release.h"

#include "dem/dem_system.h"
#include "dem/measurements/measurement_registry.h"

#include "common/atomic_file.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace magbrush::dem {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();
double sense_of(const Case &c) { return c.sleeve && c.sleeve->omega() < 0.0 ? -1.0 : 1.0; }
} // namespace

bool DeveloperRelease::applies(const Case &c)
{
  return c.sleeve && c.dem.periodic_length > 0.0 && c.dma.release_from != c.dma.release_to;
}

DeveloperRelease::DeveloperRelease(const Case &c)
  : settings_(c.dma), statistics_(c.statistics), R_(c.sleeve ? c.sleeve->radius : 0.0), Lz_(c.dem.periodic_length),
    speed_(c.sleeve ? c.sleeve->surface_speed() : 0.0),
    before_line_(c.dma.release_from, sense_of(c), c.dma.window, R_, Lz_),
    after_line_(c.dma.release_to, sense_of(c), c.dma.window, R_, Lz_)
{
  if (!applies(c))
    throw std::invalid_argument("developer release: the scene needs a sleeve, a periodic slab "
                                "(dem.periodic_length) and a release sector (dma.release_from != dma.release_to)");
  // Only the layer on the sleeve crosses: what has fallen off is released.
  before_line_.set_max_radius(R_ + settings_.height);
  after_line_.set_max_radius(R_ + settings_.height);
}

void DeveloperRelease::sample(const DemSystem &system) { add_sample(system.time(), system.particles()); }

void DeveloperRelease::add_sample(double time, const ParticleState &s)
{
  // The lines see every sample (a crossing needs the previous position), the means only
  // those from average_from on.
  const LineFluxSample before = before_line_.sample(time, s), after = after_line_.sample(time, s);
  const double dt = previous_time_ >= 0.0 ? time - previous_time_ : 0.0;
  previous_time_ = time;
  rows_.push_back({time, before.crossed_mass, after.crossed_mass});
  if (time < settings_.average_from || dt <= 0.0 || speed_ <= 0.0)
    return;
  const double per_area = 1.0 / (dt * speed_ * Lz_);
  arriving_.add(before.crossed_mass * per_area);
  carried_back_.add(after.crossed_mass * per_area);
}

std::vector<SummaryValue> DeveloperRelease::summary() const
{
  const auto blocks = static_cast<std::size_t>(statistics_.blocks);
  // 1 − A/B from the mean fluxes; its error from both, treated as independent (the beads that
  // cross the second line crossed the first a few ms before: the correlation is weak over a
  // block longer than that).
  const double a = carried_back_.mean(), b = arriving_.mean();
  const double sa = carried_back_.standard_error(blocks), sb = arriving_.standard_error(blocks);
  SummaryValue fraction{"released_fraction", b > 0.0 ? 1.0 - a / b : nan,
                        b > 0.0 ? std::hypot(sa / b, a * sb / (b * b)) : nan, nan, "1",
                        "1 - (developer flux near the sleeve after the release sector) / (flux before it)"};
  return {fraction,
          summarise(arriving_, blocks, true, "developer_arriving_at_release_kg_per_m2", "kg/m^2",
                    "flux near the sleeve into the release sector / (sleeve speed x slab)"),
          summarise(carried_back_, blocks, false, "developer_carried_past_release_kg_per_m2", "kg/m^2",
                    "flux near the sleeve out of the release sector / (sleeve speed x slab): back to the pick-up")};
}

std::string DeveloperRelease::csv() const
{
  std::ostringstream o;
  char line[256];
  std::snprintf(line, sizeof line,
                "# developer release (magbrush): masses crossing the lines at %.4g deg and %.4g deg within %.4g mm of "
                "the sleeve since the previous sample\n",
                settings_.release_from * 180.0 / M_PI, settings_.release_to * 180.0 / M_PI, settings_.height * 1e3);
  o << line << "time_s,before_kg,after_kg\n";
  for (const Row &r : rows_)
  {
    std::snprintf(line, sizeof line, "%.9g,%.6g,%.6g\n", r.time, r.before, r.after);
    o << line;
  }
  return o.str();
}

void DeveloperRelease::write(const std::string &directory) const
{
  write_text_atomically((std::filesystem::path(directory) / "developer_release.csv").string(), csv());
}

namespace {
const bool registered =
  register_measurement({"developer release", [](const Case &c) -> std::unique_ptr<Measurement> {
                          if (!DeveloperRelease::applies(c))
                            return nullptr;
                          return std::make_unique<DeveloperRelease>(c);
                        }});
} // namespace


// The two lines' previous samples, the rows and the series (Measurement::write_state).
void DeveloperRelease::write_state(StateOut &out) const
{
  before_line_.write_state(out);
  after_line_.write_state(out);
  out.put(previous_time_);
  out.put_array(rows_);
  arriving_.write_state(out);
  carried_back_.write_state(out);
}

void DeveloperRelease::read_state(StateIn &in)
{
  before_line_.read_state(in);
  after_line_.read_state(in);
  previous_time_ = in.get<double>();
  in.get_array(rows_);
  arriving_.read_state(in);
  carried_back_.read_state(in);
}

} // namespace magbrush::dem
