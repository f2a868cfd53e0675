// The toner the drum carries past a line, per whole image period (see developed_line.h).
#include "dem/measurements/developed_line.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace magbrush::dem {

// Written as raw arrays into checkpoints: no padding byte may reach the file.
static_assert(sizeof(DevelopedLine::Period) == 7 * sizeof(double) + 2 * sizeof(long));
static_assert(sizeof(DevelopedLine::Bin) == 3 * sizeof(double) + sizeof(long));

DevelopedLine::DevelopedLine(const DrumImage &image, double slab_depth, int phase_bins)
  : image_(image), depth_(slab_depth), bins_(phase_bins)
{
  if (!(image.period() > 0.0))
    throw std::invalid_argument("developed line: the latent image has no period to average over");
  if (bins_ < 1)
    throw std::invalid_argument("developed line: at least one phase bin");
  open_bins_.assign(static_cast<std::size_t>(bins_), Bin{});
  profile_ = open_bins_;
}

double DevelopedLine::bin_position(int k) const
{
  const double u = (k + 0.5) / bins_;
  return (u - 0.5 * image_.duty()) * image_.period();
}

void DevelopedLine::add_sample(double time, double s_line, const std::vector<LineToner> &on_drum, bool counting)
{
  if (has_previous_ && previous_counting_ && counting && s_line != s_previous_)
  {
    direction_ = s_line > s_previous_ ? 1.0 : -1.0;
    const double length = std::abs(s_line - s_previous_);
    const double lo = std::min(s_line, s_previous_), hi = std::max(s_line, s_previous_);
    // The toner in the swept interval that was not counted before (both lists sorted by id).
    candidates_.clear();
    std::size_t c = 0;
    for (const LineToner &t : on_drum)
    {
      while (c < counted_.size() && counted_[c] < t.id)
        ++c;
      const bool seen = c < counted_.size() && counted_[c] == t.id;
      if (!seen && t.s >= lo && t.s <= hi)
        candidates_.push_back(t);
    }
    if (!open_started_)
    {
      open_ = Period{};
      open_.t_start = t_previous_;
      open_started_ = true;
    }
    // Cut the sweep where the open period completes (seldom more than once per sample).
    double from = 0.0;
    while (from < length)
    {
      const double to = std::min(length, from + (image_.period() - swept_));
      const bool last = to >= length;
      count_segment(from, to, last, candidates_);
      swept_ += to - from;
      if (image_.period() - swept_ <= 1e-12 * image_.period())
        close_period(t_previous_ + (time - t_previous_) * to / length);
      from = to;
    }
    // Remember what was counted, as long as it stays on the drum.
    std::size_t a = 0;
    still_counted_.clear();
    for (const LineToner &t : on_drum)
    {
      while (a < counted_.size() && counted_[a] < t.id)
        ++a;
      if (a < counted_.size() && counted_[a] == t.id)
        still_counted_.push_back(t.id);
    }
    for (const LineToner &t : candidates_)
      still_counted_.push_back(t.id);
    std::sort(still_counted_.begin(), still_counted_.end());
    counted_.swap(still_counted_);
  }
  has_previous_ = true;
  previous_counting_ = counting;
  s_previous_ = s_line;
  t_previous_ = time;
}

void DevelopedLine::count_segment(double from, double to, bool last, const std::vector<LineToner> &candidates)
{
  // The drum-frame arcs of the segment's ends.
  const double sa = s_previous_ + direction_ * from, sb = s_previous_ + direction_ * to;
  const double lo = std::min(sa, sb), hi = std::max(sa, sb);
  const double exposed = image_.exposed_length(lo, hi);
  open_.image_area += exposed * depth_;
  open_.dark_area += (hi - lo - exposed) * depth_;
  // Its length per phase bin: walk across the bin edges (a segment is much shorter than a bin).
  const double period = image_.period(), width = period / bins_;
  double s = lo;
  while (s < hi)
  {
    const double u = s / period + 0.5 * image_.duty();
    const double j = std::floor(u * bins_ + 1e-12);
    const double edge = ((j + 1.0) / bins_ - 0.5 * image_.duty()) * period;
    const double end = std::min(hi, std::max(edge, s + 1e-15 * width));
    const auto k = static_cast<std::size_t>(static_cast<long>(j) % bins_ + bins_) % static_cast<std::size_t>(bins_);
    open_bins_[k].length += end - s;
    s = end;
  }
  // The toner lying in it: [from, to), the first segment from its near end and the last to its
  // far end inclusive (a candidate's position is rounded like the interval's ends).
  for (const LineToner &t : candidates)
  {
    const double d = direction_ * (t.s - s_previous_);
    if ((from > 0.0 && d < from) || (!last && d >= to))
      continue;
    const auto k = std::min(static_cast<std::size_t>(image_.phase(t.s) * bins_), static_cast<std::size_t>(bins_ - 1));
    open_bins_[k].mass += t.mass;
    open_bins_[k].charge += t.charge;
    ++open_bins_[k].toner;
    if (image_.exposed(t.s))
      open_.image_mass += t.mass, open_.image_charge += t.charge, ++open_.image_toner;
    else
      open_.dark_mass += t.mass, ++open_.dark_toner;
  }
}

void DevelopedLine::close_period(double time)
{
  open_.t_end = time;
  periods_.push_back(open_);
  for (std::size_t k = 0; k < profile_.size(); ++k)
  {
    profile_[k].length += open_bins_[k].length;
    profile_[k].mass += open_bins_[k].mass;
    profile_[k].charge += open_bins_[k].charge;
    profile_[k].toner += open_bins_[k].toner;
    open_bins_[k] = Bin{};
  }
  open_ = Period{};
  open_.t_start = time;
  swept_ = 0.0;
}

std::string DevelopedLine::periods_csv() const
{
  std::ostringstream o;
  o << "# the toner the drum carried past the line, per whole latent-image period (magbrush toner development): "
       "each drum element counted once as it crossed; NaN: no toner\n";
  o << "period,t_start_s,t_end_s,tma_kg_per_m2,fog_kg_per_m2,developed_q_over_m_C_per_kg,image_area_m2,"
       "dark_area_m2,image_toner,dark_toner\n";
  char line[320];
  for (std::size_t k = 0; k < periods_.size(); ++k)
  {
    const Period &p = periods_[k];
    const double qm = p.image_mass > 0.0 ? p.image_charge / p.image_mass : std::nan("");
    std::snprintf(line, sizeof line, "%zu,%.9g,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%ld,%ld\n", k + 1, p.t_start, p.t_end,
                  p.image_mass / p.image_area, p.dark_mass / p.dark_area, qm, p.image_area, p.dark_area,
                  p.image_toner, p.dark_toner);
    o << line;
  }
  return o.str();
}

std::string DevelopedLine::profile_csv() const
{
  std::ostringstream o;
  char line[320];
  std::snprintf(line, sizeof line,
                "# the developed profile across one latent-image period, summed over %zu whole periods "
                "(magbrush toner development); position from the exposed strip's centre (exposed within "
                "+-%.6g mm); the drum carries larger positions past the line %s\n",
                periods_.size(), 0.5 * image_.duty() * image_.period() * 1e3,
                direction_ < 0.0 ? "first (a strip's leading edge is at its larger position)"
                                 : "last (a strip's leading edge is at its smaller position)");
  o << line;
  o << "position_mm,exposed,area_m2,toner_mass_per_area_kg_per_m2,charge_per_area_C_per_m2,toner\n";
  for (int k = 0; k < bins_; ++k)
  {
    const Bin &b = profile_[static_cast<std::size_t>(k)];
    const double area = b.length * depth_;
    const double position = bin_position(k);
    const bool exposed = std::abs(position) < 0.5 * image_.duty() * image_.period();
    std::snprintf(line, sizeof line, "%.6g,%d,%.6g,%.6g,%.6g,%ld\n", position * 1e3, exposed ? 1 : 0, area,
                  area > 0.0 ? b.mass / area : std::nan(""), area > 0.0 ? b.charge / area : std::nan(""), b.toner);
    o << line;
  }
  return o.str();
}

void DevelopedLine::write_state(StateOut &out) const
{
  out.put<std::uint8_t>(has_previous_);
  out.put<std::uint8_t>(previous_counting_);
  out.put<std::uint8_t>(open_started_);
  for (double v : {s_previous_, t_previous_, direction_, swept_})
    out.put(v);
  out.put_array(counted_);
  out.put_array(std::vector<Period>{open_});
  out.put_array(open_bins_);
  out.put_array(profile_);
  out.put_array(periods_);
}

void DevelopedLine::read_state(StateIn &in)
{
  has_previous_ = in.get<std::uint8_t>() != 0;
  previous_counting_ = in.get<std::uint8_t>() != 0;
  open_started_ = in.get<std::uint8_t>() != 0;
  for (double *v : {&s_previous_, &t_previous_, &direction_, &swept_})
    *v = in.get<double>();
  in.get_array(counted_);
  std::vector<Period> open;
  in.get_array(open);
  if (open.size() != 1)
    in.fail("is corrupt (the developed line's open period)");
  open_ = open[0];
  const std::size_t bins = profile_.size();
  in.get_array(open_bins_);
  in.get_array(profile_);
  if (open_bins_.size() != bins || profile_.size() != bins)
    in.fail("holds a developed profile of " + std::to_string(profile_.size()) + " phase bins, this case's has " +
            std::to_string(bins));
  in.get_array(periods_);
}

} // namespace magbrush::dem
