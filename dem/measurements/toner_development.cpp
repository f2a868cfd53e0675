// Toner development onto the drum (see toner_development.h).
#include "dem/measurements/toner_development.h"

#include "dem/dem_system.h"
#include "dem/measurements/measurement_registry.h"
#include "dem/snapshot_writer.h" // write_file_atomically

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
constexpr double epsilon0 = 8.8541878128e-12; // [F/m]

// The development contrast ΔV = |V_bias − V_exposed| of the case's latent image.
double contrast_of(const Case &c)
{
  const LatentImage &im = c.electric.image;
  double exposed = 0.0;
  if (im.kind == LatentImage::Kind::surface_potential)
    exposed = im.light_value;
  else if (im.kind == LatentImage::Kind::surface_charge && c.drum.pc_eps_r > 0.0)
    exposed = im.light_value * c.drum.pc_thickness / (epsilon0 * c.drum.pc_eps_r);
  return std::abs(c.electric.bias - exposed);
}
} // namespace

// ---------------------------------------------------------------------------------------
bool TonerDevelopment::applies(const Case &c)
{
  if (!NipFrame::applies(c) || !c.electric.enabled)
    return false;
  return std::any_of(c.populations.begin(), c.populations.end(),
                     [](const Population &p) { return p.kind == ParticleKind::toner; });
}

TonerDevelopment::TonerDevelopment(const Case &c)
  : settings_(c.development), statistics_(c.statistics), frame_(NipFrame::from_case(c)),
    image_(c.electric.image, frame_)
{
  if (!(settings_.measure_to > settings_.measure_from))
    throw std::invalid_argument("toner development: development.measure_to must lie downstream of "
                                "development.measure_from");
  if (c.drum.pc_thickness > 0.0)
    eps_layer_over_l_ = epsilon0 * c.drum.pc_eps_r / c.drum.pc_thickness;
  contrast_ = contrast_of(c);
  for (const auto &p : c.populations)
  {
    is_toner_.push_back(p.kind == ParticleKind::toner);
    is_carrier_.push_back(p.kind == ParticleKind::carrier);
    if (p.kind == ParticleKind::toner && toner_q_over_m_ == 0.0)
      toner_q_over_m_ = p.charge_to_mass;
  }
  if (settings_.average_over == "image_periods")
  {
    line_.emplace(image_, frame_.slab_depth, settings_.phase_bins, settings_.block_length);
    near_line_.emplace(image_, frame_.slab_depth, settings_.phase_bins, settings_.block_length);
  }
  bin_width_ = c.nip.bin_width;
  bins_half_ = static_cast<int>(std::lround(c.nip.half_width / c.nip.bin_width));
  arrived_.assign(static_cast<std::size_t>(2 * bins_half_ + 1), 0.0);
  left_ = arrived_;
}

double TonerDevelopment::tma_bound() const
{
  return toner_q_over_m_ != 0.0 ? eps_layer_over_l_ * contrast_ / std::abs(toner_q_over_m_) : nan;
}

void TonerDevelopment::sample(const DemSystem &system)
{
  // Sampled from the start, so that the file shows the approach to the steady state; the means
  // and the transfer profile take only the samples from average_from on (add_sample).
  std::size_t drum = system.walls().size();
  for (std::size_t w = 0; w < system.walls().size(); ++w)
    if (system.walls().name(w) == "drum")
      drum = w;
  if (drum == system.walls().size())
    throw std::runtime_error("toner development: the run has no wall named 'drum'");
  system.wall_contacts(drum, records_);
  const ParticleState &p = system.particles();
  layer_.assign(p.size(), 0);
  for (const auto &r : records_)
  {
    const auto s = static_cast<std::size_t>(p.species[r.particle]);
    if (s < is_toner_.size() && is_toner_[s])
      layer_[r.particle] = 1;
  }
  // Which toner a carrier holds: once per sample, for both the stack and the share on carriers.
  mark_on_carriers(system, is_toner_, is_carrier_, on_carrier_);
  stack_on_drum(system, is_toner_, on_carrier_, layer_);
  toner_.clear();
  for (std::size_t k = 0; k < p.size(); ++k)
    if (layer_[k] > 0)
      toner_.push_back({p.id[k], p.x[k], p.y[k], p.mass[k], p.charge[k], layer_[k]});
  add_sample(system.time(), toner_, toner_share_on_carriers(system, is_toner_, on_carrier_));
}

namespace {
bool species_is(const ParticleState &p, const std::vector<std::uint8_t> &flags, std::size_t k)
{
  const auto s = static_cast<std::size_t>(p.species[k]);
  return s < flags.size() && flags[s];
}

// Whether the pair q of the neighbour list holds together: touching (adhesion holds a contact),
// or within the adhesion range of one another.
bool held_pair(const DemSystem &system, std::size_t q)
{
  const NeighbourList &list = system.neighbour_list();
  if (list.touching[q] != 0)
    return true;
  const double range = system.contact_table().adhesion_range();
  if (range <= 0.0)
    return false;
  const ParticleState &p = system.particles();
  const auto i = static_cast<std::size_t>(list.owner[q]), j = static_cast<std::size_t>(list.partner[q]);
  const Vector3 s = list.shift(q);
  const double dx = p.x[j] - p.x[i] + s.x, dy = p.y[j] - p.y[i] + s.y, dz = p.z[j] - p.z[i] + s.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz) - p.radius[i] - p.radius[j] <= range;
}

} // namespace

void TonerDevelopment::mark_on_carriers(const DemSystem &system, const std::vector<std::uint8_t> &is_toner,
                                        const std::vector<std::uint8_t> &is_carrier, std::vector<std::uint8_t> &on)
{
  const ParticleState &p = system.particles();
  const NeighbourList &list = system.neighbour_list();
  on.assign(p.size(), 0);
  for (std::size_t q = 0; q < list.pairs(); ++q)
  {
    const auto i = static_cast<std::size_t>(list.owner[q]), j = static_cast<std::size_t>(list.partner[q]);
    const bool toner_carrier = species_is(p, is_toner, i) && species_is(p, is_carrier, j);
    const bool carrier_toner = species_is(p, is_carrier, i) && species_is(p, is_toner, j);
    if ((toner_carrier || carrier_toner) && held_pair(system, q))
      on[toner_carrier ? i : j] = 1;
  }
}

void TonerDevelopment::stack_on_drum(const DemSystem &system, const std::vector<std::uint8_t> &is_toner,
                                     const std::vector<std::uint8_t> &on_carrier, std::vector<std::uint8_t> &layer)
{
  const ParticleState &p = system.particles();
  const NeighbourList &list = system.neighbour_list();
  // Layer by layer: a pass over the pairs extends only from the layer below, so that the layers
  // do not depend on the pairs' order.
  for (int below = 1; below < max_layers; ++below)
  {
    bool grew = false;
    for (std::size_t q = 0; q < list.pairs(); ++q)
    {
      const auto i = static_cast<std::size_t>(list.owner[q]), j = static_cast<std::size_t>(list.partner[q]);
      const bool up_j = layer[i] == below && layer[j] == 0, up_i = layer[j] == below && layer[i] == 0;
      if (!up_i && !up_j)
        continue;
      const std::size_t upper = up_j ? j : i;
      if (!species_is(p, is_toner, upper) || !species_is(p, is_toner, up_j ? i : j) || on_carrier[upper] ||
          !held_pair(system, q))
        continue;
      layer[upper] = static_cast<std::uint8_t>(below + 1);
      grew = true;
    }
    if (!grew)
      break;
  }
}

double TonerDevelopment::toner_share_on_carriers(const DemSystem &system, const std::vector<std::uint8_t> &is_toner,
                                                 const std::vector<std::uint8_t> &on)
{
  const ParticleState &p = system.particles();
  double all = 0.0, carried = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k)
  {
    if (species_is(p, is_toner, k))
    {
      all += p.mass[k];
      carried += on[k] ? p.mass[k] : 0.0;
    }
    // Toner a carrier carries as its own mass (dem/carried_toner.h) is on it by definition.
    all += p.carried_mass[k];
    carried += p.carried_mass[k];
  }
  return all > 0.0 ? carried / all : std::numeric_limits<double>::quiet_NaN();
}

void TonerDevelopment::add_sample(double time, const std::vector<DrumToner> &on_drum_now, double on_carriers)
{
  std::vector<DrumToner> now = on_drum_now;
  std::sort(now.begin(), now.end(), [](const DrumToner &a, const DrumToner &b) { return a.id < b.id; });
  // Every sample is a row of the file; the means take those from average_from on, and the
  // transfer between two samples counts when both are.
  const bool averaged = time >= settings_.average_from;
  const bool interval_averaged = averaged && previous_time_ >= settings_.average_from;
  if (averaged)
  {
    if (first_time_ < 0.0)
      first_time_ = time;
    last_time_ = time;
  }

  // Transfer: merge the id-sorted lists of this and the previous sample.
  double arrived_mass = 0.0;
  if (previous_time_ >= 0.0)
  {
    auto bin = [&](const DrumToner &t) {
      const long k = std::lround(frame_.x_along(t.x, t.y) / bin_width_);
      return std::abs(k) <= bins_half_ ? static_cast<int>(k) + bins_half_ : -1;
    };
    std::size_t i = 0, j = 0;
    while (i < now.size() || j < before_.size())
    {
      if (j == before_.size() || (i < now.size() && now[i].id < before_[j].id))
      {
        arrived_mass += now[i].mass;
        if (const int b = bin(now[i]); b >= 0 && interval_averaged)
          arrived_[static_cast<std::size_t>(b)] += now[i].mass;
        ++i;
      }
      else if (i == now.size() || before_[j].id < now[i].id)
      {
        if (const int b = bin(before_[j]); b >= 0 && interval_averaged)
          left_[static_cast<std::size_t>(b)] += before_[j].mass;
        ++j;
      }
      else
        ++i, ++j;
    }
  }

  // The measuring window in the drum's frame at this time.
  const double s1 = image_.drum_arc_at_x(settings_.measure_from, time);
  const double s2 = image_.drum_arc_at_x(settings_.measure_to, time);
  const double a = std::min(s1, s2), b = std::max(s1, s2);
  const double depth = frame_.slab_depth;
  const double image_area = image_.exposed_length(a, b) * depth, dark_area = (b - a) * depth - image_area;
  double m_image = 0, q_image = 0, m_dark = 0;
  long n_image = 0, n_dark = 0, n_stacked = 0;
  for (const auto &t : now)
  {
    const double x = frame_.x_along(t.x, t.y);
    if (x < settings_.measure_from || x > settings_.measure_to)
      continue;
    if (image_.exposed(image_.drum_arc(t.x, t.y, time)))
      m_image += t.mass, q_image += t.charge, ++n_image;
    else
      m_dark += t.mass, ++n_dark;
    n_stacked += t.layer > 1;
  }
  Row row{time, nan, nan, nan, nan, nan, on_carriers, n_image, n_dark, n_stacked};
  if (image_area > 0.0)
  {
    row.tma = m_image / image_area;
    if (eps_layer_over_l_ > 0.0 && contrast_ > 0.0)
      row.ratio = std::abs(q_image / image_area) / (eps_layer_over_l_ * contrast_);
  }
  if (dark_area > 0.0)
    row.fog = m_dark / dark_area;
  if (m_image > 0.0)
    row.q_over_m = q_image / m_image;
  if (previous_time_ >= 0.0 && time > previous_time_)
    row.transfer = arrived_mass / ((time - previous_time_) * depth);
  if (averaged)
    add_to_means(row, interval_averaged);
  rows_.push_back(row);
  // The developed line: every drum element once, as it crosses measure_to.
  if (line_)
  {
    line_toner_.clear();
    for (const auto &t : now)
      line_toner_.push_back({t.id, image_.drum_arc(t.x, t.y, time), t.mass, t.charge});
    line_->add_sample(time, image_.drum_arc_at_x(settings_.measure_to, time), line_toner_, averaged);
    near_line_->add_sample(time, image_.drum_arc_at_x(settings_.measure_from, time), line_toner_, averaged);
  }
  previous_time_ = time;
  before_ = std::move(now);
}

void TonerDevelopment::add_to_means(const Row &row, bool with_transfer)
{
  if (!std::isnan(row.on_carriers))
    on_carriers_.add(row.on_carriers);
  if (!std::isnan(row.tma))
    tma_.add(row.tma);
  if (!std::isnan(row.ratio))
    ratio_.add(row.ratio);
  if (!std::isnan(row.fog))
    fog_.add(row.fog);
  if (!std::isnan(row.q_over_m))
    q_over_m_.add(row.q_over_m);
  if (with_transfer && !std::isnan(row.transfer))
    transfer_.add(row.transfer);
}

std::vector<SummaryValue> TonerDevelopment::summary() const
{
  const auto blocks = static_cast<std::size_t>(statistics_.blocks);
  auto sampled = [&](const char *key, const SampleSeries &s, bool steady_test, const char *unit, const char *meaning) {
    return summarise(s, blocks, steady_test, key, unit, meaning);
  };
  SummaryValue bound;
  bound.key = "tma_kg_per_m2_bound";
  bound.value = tma_bound();
  bound.unit = "kg/m^2";
  bound.meaning = "complete neutralisation of the contrast: eps0 epsr dV / (L |q/m|)";
  SummaryValue contrast;
  contrast.key = "contrast_potential_V";
  contrast.value = contrast_;
  contrast.unit = "V";
  contrast.meaning = "|bias - exposed potential|";
  std::vector<SummaryValue> out;
  if (line_)
  {
    out = period_summary();
    const auto near = near_line_summary();
    out.insert(out.end(), near.begin(), near.end());
  }
  else
    out = {
        sampled("tma_kg_per_m2", tma_, true, "kg/m^2", "toner mass per exposed drum area after the nip"),
        sampled("fog_kg_per_m2", fog_, false, "kg/m^2", "toner mass per dark (background) drum area after the nip"),
        sampled("developed_q_over_m_C_per_kg", q_over_m_, false, "C/kg", "charge per mass of the toner on the image"),
        sampled("neutralisation_ratio", ratio_, false, "1", "developed charge per area / (eps0 epsr dV / L)"),
        sampled("toner_transfer_rate_kg_per_s_m", transfer_, true, "kg/(s m)",
                "toner mass arriving on the drum per time and slab depth"),
    };
  out.insert(out.begin() + 1, bound);
  out.push_back(sampled("toner_on_carriers_fraction", on_carriers_, false, "1",
                        "toner mass within the adhesion range of a carrier / all toner mass (the whole scene)"));
  out.push_back(contrast);
  return out;
}

// Over whole image periods: each period's image TMA, fog, q/m and neutralisation ratio are
// ratios of its own sums (every phase of the image counted once), and its transfer rate the
// mean of the samples' over the same span of time (the arrivals at the nip are periodic too).
std::vector<SummaryValue> TonerDevelopment::period_summary() const
{
  std::vector<double> tma, fog, q_over_m, ratio, transfer;
  for (const DevelopedLine::Period &p : line_->periods())
  {
    tma.push_back(p.tma());
    fog.push_back(p.fog());
    if (p.image_mass > 0.0)
      q_over_m.push_back(p.image_charge / p.image_mass);
    if (eps_layer_over_l_ > 0.0 && contrast_ > 0.0)
      ratio.push_back(p.image_area > 0.0 ? std::abs(p.image_charge / p.image_area) / (eps_layer_over_l_ * contrast_) : nan);
    double sum = 0.0;
    long n = 0;
    for (std::size_t k = 1; k < rows_.size(); ++k)
      if (rows_[k].time > p.t_start && rows_[k].time <= p.t_end && !std::isnan(rows_[k].transfer))
        sum += rows_[k].transfer, ++n;
    transfer.push_back(n > 0 ? sum / static_cast<double>(n) : nan);
  }
  SummaryValue periods;
  periods.key = "image_periods_averaged";
  periods.value = static_cast<double>(line_->periods().size());
  periods.unit = "1";
  periods.meaning = "whole latent-image periods (on a uniform image: blocks of development.block_length) past "
                    "the line measure_to that the means average (their blocks)";
  // A dark drum (a fog point) has no image: its steady state is that of the fog.
  const bool dark_drum = image_.period() <= 0.0 && !image_.solid();
  return {
      summarise_blocks(tma, !dark_drum, "tma_kg_per_m2", "kg/m^2",
                       "toner mass per exposed drum area carried past measure_to, over whole image periods"),
      summarise_blocks(fog, dark_drum, "fog_kg_per_m2", "kg/m^2",
                       "toner mass per dark (background) drum area carried past measure_to, over whole periods"),
      summarise_blocks(q_over_m, false, "developed_q_over_m_C_per_kg", "C/kg",
                       "charge per mass of the toner on the image, over whole periods"),
      summarise_blocks(ratio, false, "neutralisation_ratio", "1",
                       "developed charge per area / (eps0 epsr dV / L), over whole periods"),
      summarise_blocks(transfer, true, "toner_transfer_rate_kg_per_s_m", "kg/(s m)",
                       "toner mass arriving on the drum per time and slab depth, over whole periods"),
      periods,
  };
}

// The same count at measure_from: the TMA and fog there, over its own whole blocks. Where the
// brush has ended before measure_from, the developed layer only rides the drum from there to
// measure_to, and the two agree within their errors: the line can then sit at measure_from and
// the drum's transit between the two is saved.
std::vector<SummaryValue> TonerDevelopment::near_line_summary() const
{
  std::vector<double> tma, fog;
  for (const DevelopedLine::Period &p : near_line_->periods())
  {
    tma.push_back(p.tma());
    fog.push_back(p.fog());
  }
  // Element by element (a uniform image's blocks lie on a grid fixed to the drum): what the
  // drum's layer gained (lost: negative) between the two lines, per block of the same elements.
  std::vector<double> change;
  if (image_.period() <= 0.0)
  {
    const auto &a = near_line_->periods();
    for (const DevelopedLine::Period &p : line_->periods())
      for (const DevelopedLine::Period &q : a)
        if (line_->grid_index(p) == near_line_->grid_index(q))
        {
          change.push_back(image_.solid() ? p.tma() - q.tma() : p.fog() - q.fog());
          break;
        }
  }
  SummaryValue blocks;
  blocks.key = "image_periods_averaged_at_measure_from";
  blocks.value = static_cast<double>(near_line_->periods().size());
  blocks.unit = "1";
  blocks.meaning = "whole periods (or blocks) past the line measure_from";
  return {summarise_blocks(tma, false, "tma_at_measure_from_kg_per_m2", "kg/m^2",
                           "toner mass per exposed drum area carried past measure_from, over whole periods"),
          summarise_blocks(fog, false, "fog_at_measure_from_kg_per_m2", "kg/m^2",
                           "toner mass per dark drum area carried past measure_from, over whole periods"),
          summarise_blocks(change, false, "layer_change_past_measure_from_kg_per_m2", "kg/m^2",
                           "toner per drum area at measure_to minus at measure_from, the same drum elements "
                           "(blocks paired on the drum; uniform images): 0 where the layer only rides the drum"),
          blocks};
}

std::string TonerDevelopment::csv() const
{
  std::ostringstream o;
  o << "# toner on the drum between x = " << settings_.measure_from * 1e3 << " and " << settings_.measure_to * 1e3
    << " mm after the nip (magbrush toner development); NaN: no area or no toner; the means average the rows "
       "from t = "
    << settings_.average_from << " s\n";
  o << "time_s,tma_kg_per_m2,fog_kg_per_m2,developed_q_over_m_C_per_kg,neutralisation_ratio,"
       "transfer_rate_kg_per_s_m,toner_on_carriers_fraction,image_toner,dark_toner,stacked_toner\n";
  char line[256];
  for (const Row &r : rows_)
  {
    std::snprintf(line, sizeof line, "%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%ld,%ld,%ld\n", r.time, r.tma, r.fog,
                  r.q_over_m, r.ratio, r.transfer, r.on_carriers, r.image_toner, r.dark_toner, r.stacked_toner);
    o << line;
  }
  return o.str();
}

std::string TonerDevelopment::transfer_profile_csv() const
{
  std::ostringstream o;
  const double span = (last_time_ - first_time_) * frame_.slab_depth;
  o << "# where toner arrives on and leaves the drum along the nip, per time, slab depth and bin width "
       "(magbrush toner development)\n";
  o << "x_mm,arriving_kg_per_s_m2,leaving_kg_per_s_m2\n";
  char line[128];
  for (int k = -bins_half_; k <= bins_half_; ++k)
  {
    const auto i = static_cast<std::size_t>(k + bins_half_);
    const double per = span > 0.0 ? 1.0 / (span * bin_width_) : nan;
    std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g\n", k * bin_width_ * 1e3, arrived_[i] * per, left_[i] * per);
    o << line;
  }
  return o.str();
}

void TonerDevelopment::write(const std::string &directory) const
{
  write_file_atomically((std::filesystem::path(directory) / "toner_development.csv").string(), csv());
  write_file_atomically((std::filesystem::path(directory) / "toner_transfer_profile.csv").string(),
                        transfer_profile_csv());
  if (line_)
  {
    write_file_atomically((std::filesystem::path(directory) / "toner_developed_periods.csv").string(),
                          line_->periods_csv());
    write_file_atomically((std::filesystem::path(directory) / "toner_developed_profile.csv").string(),
                          line_->profile_csv());
    write_file_atomically((std::filesystem::path(directory) / "toner_developed_periods_at_measure_from.csv").string(),
                          near_line_->periods_csv());
  }
}

namespace {
const bool registered =
  register_measurement({"toner development", [](const Case &c) -> std::unique_ptr<Measurement> {
                          if (!TonerDevelopment::applies(c))
                            return nullptr;
                          return std::make_unique<TonerDevelopment>(c);
                        }});
} // namespace


// The toner on the drum at the last sample (arrivals and departures are counted against it),
// the transfer profile, the series and the rows (Measurement::write_state). The toner and the
// rows are written field by field, so that no padding byte reaches the file.
void TonerDevelopment::write_state(StateOut &out) const
{
  std::vector<std::int32_t> ids;
  std::vector<double> x, y, mass, charge;
  for (const DrumToner &t : before_)
  {
    ids.push_back(t.id);
    x.push_back(t.x);
    y.push_back(t.y);
    mass.push_back(t.mass);
    charge.push_back(t.charge);
  }
  out.put_array(ids);
  for (const auto *a : {&x, &y, &mass, &charge})
    out.put_array(*a);
  out.put_array(arrived_);
  out.put_array(left_);
  out.put(previous_time_);
  out.put(first_time_);
  out.put(last_time_);
  for (const auto *s : {&tma_, &fog_, &q_over_m_, &ratio_, &transfer_, &on_carriers_})
    s->write_state(out);
  std::vector<double> values;
  std::vector<long> counts;
  for (const Row &r : rows_)
  {
    values.insert(values.end(), {r.time, r.tma, r.fog, r.q_over_m, r.ratio, r.transfer, r.on_carriers});
    counts.insert(counts.end(), {r.image_toner, r.dark_toner, r.stacked_toner});
  }
  out.put_array(values);
  out.put_array(counts);
  out.put<std::uint8_t>(line_.has_value());
  if (line_)
  {
    line_->write_state(out);
    near_line_->write_state(out);
  }
}

void TonerDevelopment::read_state(StateIn &in)
{
  std::vector<std::int32_t> ids;
  std::vector<double> x, y, mass, charge;
  in.get_array(ids);
  for (auto *a : {&x, &y, &mass, &charge})
  {
    in.get_array(*a);
    if (a->size() != ids.size())
      in.fail("is corrupt (the toner on the drum has arrays of different lengths)");
  }
  before_.clear();
  for (std::size_t k = 0; k < ids.size(); ++k)
    before_.push_back({ids[k], x[k], y[k], mass[k], charge[k]});
  const std::size_t bins = arrived_.size();
  in.get_array(arrived_);
  in.get_array(left_);
  if (arrived_.size() != bins || left_.size() != bins)
    in.fail("holds a transfer profile of " + std::to_string(arrived_.size()) + " bins, this case's has " +
            std::to_string(bins));
  previous_time_ = in.get<double>();
  first_time_ = in.get<double>();
  last_time_ = in.get<double>();
  for (auto *s : {&tma_, &fog_, &q_over_m_, &ratio_, &transfer_, &on_carriers_})
    s->read_state(in);
  std::vector<double> values;
  std::vector<long> counts;
  in.get_array(values);
  in.get_array(counts);
  if (values.size() % 7 != 0 || counts.size() != 3 * (values.size() / 7))
    in.fail("is corrupt (the development rows)");
  rows_.clear();
  for (std::size_t k = 0; k < counts.size() / 3; ++k)
  {
    const double *v = &values[7 * k];
    rows_.push_back({v[0], v[1], v[2], v[3], v[4], v[5], v[6], counts[3 * k], counts[3 * k + 1], counts[3 * k + 2]});
  }
  const bool with_line = in.get<std::uint8_t>() != 0;
  if (with_line != line_.has_value())
    in.fail(with_line ? "averages over image periods, this case over samples (development.average_over)"
                      : "averages over samples, this case over image periods (development.average_over)");
  if (line_)
  {
    line_->read_state(in);
    near_line_->read_state(in);
  }
}

} // namespace magbrush::dem
