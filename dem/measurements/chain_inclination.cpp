// Chain inclination from the contact fabric along the sleeve (see chain_inclination.h).
#include "dem/measurements/chain_inclination.h"

#include "dem/dem_system.h"
#include "dem/measurements/measurement_registry.h"
#include "dem/snapshot_writer.h" // write_file_atomically

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numeric>
#include <sstream>

namespace magbrush::dem {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double to_deg = 180.0 / M_PI;
} // namespace

ChainInclination::ChainInclination(const Case &c) : settings_(c.nip), frame_(NipFrame::from_case(c)), bins_(c.nip)
{
  const std::size_t n = bins_.size();
  ftt_.assign(n, 0.0);
  fnn_.assign(n, 0.0);
  ftn_.assign(n, 0.0);
  count_.assign(n, 0.0);
  for (const auto &p : c.populations)
    species_is_carrier_.push_back(p.kind == ParticleKind::carrier);
}

void ChainInclination::sample(const DemSystem &system)
{
  if (system.time() < settings_.average_from)
    return;
  if (t_first_ < 0.0)
    t_first_ = system.time();
  t_last_ = system.time();
  // The touching pairs are the engine's: its contact list marks each pair with
  // |x_j − x_i| < r_i + r_j at the positions of this step's contacts, so no search of our own
  // (a cell list of its own cost ~9 ms a sample on the placed quick scene's 4,300 beads).
  ++samples_;
  const ParticleState &p = system.particles();
  const NeighbourList &list = system.neighbour_list();
  auto carrier = [&](std::size_t i) {
    const auto s = static_cast<std::size_t>(p.species[i]);
    return s >= species_is_carrier_.size() || species_is_carrier_[s];
  };
  for (std::size_t q = 0; q < list.pairs(); ++q)
  {
    if (!list.touching[q])
      continue;
    const auto i = static_cast<std::size_t>(list.owner[q]), j = static_cast<std::size_t>(list.partner[q]);
    if (!carrier(i) || !carrier(j))
      continue;
    const Vector3 a = p.position(i);
    add_contact(a, p.position(j) - a + list.shift(q));
  }
}

void ChainInclination::add_contact(const Vector3 &a, const Vector3 &d)
{
  const Vector3 m = a + 0.5 * d;
  const int b = bins_.of(frame_.sleeve_angle(m.x, m.y));
  if (b < 0)
    return;
  const double rx = m.x - frame_.sx, ry = m.y - frame_.sy, r = std::hypot(rx, ry);
  const double enx = rx / r, eny = ry / r;
  const double sense = (frame_.nx * frame_.ty - frame_.ny * frame_.tx) >= 0.0 ? 1.0 : -1.0;
  const double etx = -sense * eny, ety = sense * enx; // downstream tangent at m
  const double len = norm(d);
  const double ut = (d.x * etx + d.y * ety) / len, un = (d.x * enx + d.y * eny) / len;
  const auto k = static_cast<std::size_t>(b);
  ftt_[k] += ut * ut;
  fnn_[k] += un * un;
  ftn_[k] += ut * un;
  count_[k] += 1.0;
}

std::vector<ChainBin> ChainInclination::bins() const
{
  std::vector<ChainBin> out;
  const double per_sample = samples_ > 0 ? 1.0 / static_cast<double>(samples_) : nan;
  for (std::size_t i = 0; i < bins_.size(); ++i)
  {
    ChainBin b;
    b.theta = bins_.centre(i);
    b.contacts = count_[i] * per_sample;
    const double trace = ftt_[i] + fnn_[i];
    if (count_[i] > 0.0 && trace > 0.0)
    {
      const double diff = fnn_[i] - ftt_[i], off = 2.0 * ftn_[i];
      b.inclination = 0.5 * std::atan2(off, diff);
      b.anisotropy = std::sqrt(diff * diff + off * off) / trace;
    }
    else
      b.inclination = b.anisotropy = nan;
    out.push_back(b);
  }
  return out;
}

std::string ChainInclination::csv() const
{
  std::ostringstream o;
  char line[256];
  std::snprintf(line, sizeof line,
                "# Chain inclination along the sleeve (magbrush chain inclination): %ld samples over t = %.6g .. %.6g s\n",
                samples_, t_first_, t_last_);
  o << line;
  o << "# theta: sleeve angle of the contact midpoints from the line of centres, positive downstream; sleeve_arc = "
       "R_sleeve * theta; x = R_sleeve * sin(theta) (the nip coordinate of the sleeve surface point).\n"
       "# inclination: principal direction of the in-plane contact fabric from the local sleeve normal, positive "
       "leaning downstream (tips ahead); anisotropy 1 = all contacts on one line, 0 = isotropic.\n";
  o << "theta_deg,sleeve_arc_mm,x_mm,contacts_per_sample,inclination_deg,anisotropy\n";
  for (const auto &b : bins())
  {
    std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", b.theta * to_deg,
                  frame_.sleeve_radius * b.theta * 1e3, frame_.sleeve_radius * std::sin(b.theta) * 1e3, b.contacts,
                  b.inclination * to_deg, b.anisotropy);
    o << line;
  }
  return o.str();
}

void ChainInclination::write(const std::string &directory) const
{
  write_file_atomically((std::filesystem::path(directory) / "chain_inclination.csv").string(), csv());
}

namespace {
const bool registered = register_measurement({"chain inclination", [](const Case &c) -> std::unique_ptr<Measurement> {
                                                if (!NipFrame::applies(c))
                                                  return nullptr;
                                                return std::make_unique<ChainInclination>(c);
                                              }});
} // namespace


// The fabric sums per bin (Measurement::write_state).
void ChainInclination::write_state(StateOut &out) const
{
  for (const auto *a : {&ftt_, &fnn_, &ftn_, &count_})
    out.put_array(*a);
  out.put(samples_);
  out.put(t_first_);
  out.put(t_last_);
}

void ChainInclination::read_state(StateIn &in)
{
  const std::size_t bins = ftt_.size();
  for (auto *a : {&ftt_, &fnn_, &ftn_, &count_})
  {
    in.get_array(*a);
    if (a->size() != bins)
      in.fail("holds a chain profile of " + std::to_string(a->size()) + " bins, this case's has " +
              std::to_string(bins));
  }
  samples_ = in.get<long>();
  t_first_ = in.get<double>();
  t_last_ = in.get<double>();
}

} // namespace magbrush::dem
