// The brush's height and mass along the sleeve (see brush_height.h).
#include "dem/measurements/brush_height.h"

#include "dem/dem_system.h"
#include "dem/measurements/measurement_registry.h"
#include "dem/snapshot_writer.h" // write_file_atomically

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

namespace magbrush::dem {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double to_deg = 180.0 / M_PI;
constexpr double no_bead = -std::numeric_limits<double>::infinity();
} // namespace

BrushHeight::BrushHeight(const Case &c) : settings_(c.nip), frame_(NipFrame::from_case(c)), bins_(c.nip)
{
  const std::size_t n = bins_.size();
  tip_sum_.assign(n, 0.0);
  tip_samples_.assign(n, 0.0);
  mass_sum_.assign(n, 0.0);
  count_sum_.assign(n, 0.0);
  tip_now_.assign(n, no_bead);
  for (const auto &p : c.populations)
    species_is_carrier_.push_back(p.kind == ParticleKind::carrier);
}

void BrushHeight::sample(const DemSystem &system)
{
  if (system.time() < settings_.average_from)
    return;
  if (t_first_ < 0.0)
    t_first_ = system.time();
  t_last_ = system.time();
  ++samples_;
  const ParticleState &p = system.particles();
  std::fill(tip_now_.begin(), tip_now_.end(), no_bead);
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    const auto s = static_cast<std::size_t>(p.species[i]);
    if (s < species_is_carrier_.size() && !species_is_carrier_[s])
      continue;
    const int b = bins_.of(frame_.sleeve_angle(p.x[i], p.y[i]));
    if (b < 0)
      continue;
    const auto k = static_cast<std::size_t>(b);
    const double top = std::hypot(p.x[i] - frame_.sx, p.y[i] - frame_.sy) - frame_.sleeve_radius + p.radius[i];
    tip_now_[k] = std::max(tip_now_[k], top);
    mass_sum_[k] += p.mass[i];
    count_sum_[k] += 1.0;
  }
  for (std::size_t k = 0; k < tip_now_.size(); ++k)
    if (tip_now_[k] != no_bead)
    {
      tip_sum_[k] += tip_now_[k];
      tip_samples_[k] += 1.0;
    }
}

std::vector<BrushHeightBin> BrushHeight::bins() const
{
  std::vector<BrushHeightBin> out;
  const double per_sample = samples_ > 0 ? 1.0 / static_cast<double>(samples_) : nan;
  const double bin_area = frame_.sleeve_radius * bins_.width * frame_.slab_depth;
  for (std::size_t i = 0; i < bins_.size(); ++i)
  {
    BrushHeightBin b;
    b.theta = bins_.centre(i);
    b.gap = frame_.radial_gap(b.theta);
    b.tip_height = tip_samples_[i] > 0.0 ? tip_sum_[i] / tip_samples_[i] : nan;
    b.mass_per_area = mass_sum_[i] * per_sample / bin_area;
    b.carriers = count_sum_[i] * per_sample;
    out.push_back(b);
  }
  return out;
}

std::string BrushHeight::csv() const
{
  std::ostringstream o;
  char line[256];
  std::snprintf(line, sizeof line,
                "# Brush height along the sleeve (magbrush brush height): %ld samples over t = %.6g .. %.6g s\n",
                samples_, t_first_, t_last_);
  o << line;
  o << "# theta: sleeve angle of the bead centres from the line of centres, positive downstream; x = R_sleeve * "
       "sin(theta). gap: sleeve surface to drum surface along the radius at theta.\n"
       "# tip_height: the top of the highest carrier in the bin above the sleeve surface, averaged over the "
       "samples (tip_height = gap: the brush touches the drum). mass_per_area: the carriers' mass per sleeve area "
       "of the bin.\n";
  o << "theta_deg,sleeve_arc_mm,x_mm,gap_mm,tip_height_mm,mass_per_area_kg_m2,carriers_per_sample\n";
  for (const auto &b : bins())
  {
    std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", b.theta * to_deg,
                  frame_.sleeve_radius * b.theta * 1e3, frame_.sleeve_radius * std::sin(b.theta) * 1e3, b.gap * 1e3,
                  b.tip_height * 1e3, b.mass_per_area, b.carriers);
    o << line;
  }
  return o.str();
}

void BrushHeight::write(const std::string &directory) const
{
  write_file_atomically((std::filesystem::path(directory) / "brush_height.csv").string(), csv());
}

namespace {
const bool registered = register_measurement({"brush height", [](const Case &c) -> std::unique_ptr<Measurement> {
                                                if (!NipFrame::applies(c))
                                                  return nullptr;
                                                return std::make_unique<BrushHeight>(c);
                                              }});
} // namespace

// The per-bin sums (Measurement::write_state).
void BrushHeight::write_state(StateOut &out) const
{
  for (const auto *a : {&tip_sum_, &tip_samples_, &mass_sum_, &count_sum_})
    out.put_array(*a);
  out.put(samples_);
  out.put(t_first_);
  out.put(t_last_);
}

void BrushHeight::read_state(StateIn &in)
{
  const std::size_t bins = tip_sum_.size();
  for (auto *a : {&tip_sum_, &tip_samples_, &mass_sum_, &count_sum_})
  {
    in.get_array(*a);
    if (a->size() != bins)
      in.fail("holds a brush-height profile of " + std::to_string(a->size()) + " bins, this case's has " +
              std::to_string(bins));
  }
  samples_ = in.get<long>();
  t_first_ = in.get<double>();
  t_last_ = in.get<double>();
}

} // namespace magbrush::dem
