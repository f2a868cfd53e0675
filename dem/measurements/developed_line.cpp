// The toner the drum carries past a line, per whole image period (see developed_line.h).
#include "dem/measurements/developed_line.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace magbrush::dem {

// Written as raw arrays into checkpoints: no padding byte may reach the file.
static_assert(sizeof(DevelopedLine::Period) == 8 * sizeof(double) + 2 * sizeof(long));
static_assert(sizeof(DevelopedLine::Bin) == 3 * sizeof(double) + sizeof(long));

DevelopedLine::DevelopedLine(const DrumImage &image, double slab_depth, int phase_bins, double block_length)
  : image_(image), depth_(slab_depth), bins_(phase_bins),
    block_(image.period() > 0.0 ? image.period() : block_length),
    phase_offset_(image.period() > 0.0 ? 0.5 * image.duty() : 0.0)
{
  if (!(block_ > 0.0))
    throw std::invalid_argument("developed line: a uniform latent image needs a block length to average over");
  if (bins_ < 1)
    throw std::invalid_argument("developed line: at least one phase bin");
  open_bins_.assign(static_cast<std::size_t>(bins_), Bin{});
  profile_ = open_bins_;
}

double DevelopedLine::bin_position(int k) const
{
  const double u = (k + 0.5) / bins_;
  return (u - phase_offset_) * block_;
}

double DevelopedLine::phase(double s) const
{
  const double u = s / block_ + phase_offset_;
  return u - std::floor(u);
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
      open_.s_start = s_previous_;
      open_started_ = true;
      align_to_grid();
    }
    // Cut the sweep where the open period completes (seldom more than once per sample).
    double from = 0.0;
    while (from < length)
    {
      const double to = std::min(length, from + (block_ - swept_));
      const bool last = to >= length;
      count_segment(from, to, last, candidates_);
      swept_ += to - from;
      if (block_ - swept_ <= 1e-12 * block_)
        close_period(t_previous_ + (time - t_previous_) * to / length, s_previous_ + direction_ * to);
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
  const double width = block_ / bins_;
  double s = lo;
  while (s < hi)
  {
    const double u = s / block_ + phase_offset_;
    const double j = std::floor(u * bins_ + 1e-12);
    const double edge = ((j + 1.0) / bins_ - phase_offset_) * block_;
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
    const auto k = std::min(static_cast<std::size_t>(phase(t.s) * bins_), static_cast<std::size_t>(bins_ - 1));
    open_bins_[k].mass += t.mass;
    open_bins_[k].charge += t.charge;
    ++open_bins_[k].toner;
    if (image_.exposed(t.s))
      open_.image_mass += t.mass, open_.image_charge += t.charge, ++open_.image_toner;
    else
      open_.dark_mass += t.mass, ++open_.dark_toner;
  }
}

// On a uniform image the blocks lie on a grid fixed to the drum (boundaries at s = n × block),
// whatever the line and whenever its counting starts: lines at two places then count the same
// drum elements in their blocks of the same index, and can be compared element by element. The
// stretch from where the counting starts to the first boundary is not a whole block: it is
// swept but not kept. (Strips need no grid: a whole period is the same whatever its start.)
void DevelopedLine::align_to_grid()
{
  if (image_.period() > 0.0)
    return;
  const double n = direction_ < 0.0 ? std::floor(s_previous_ / block_ + 1e-12) : std::ceil(s_previous_ / block_ - 1e-12);
  const double to_boundary = std::abs(s_previous_ - n * block_);
  if (to_boundary > 1e-12 * block_)
  {
    swept_ = block_ - to_boundary;
    open_partial_ = true;
  }
}

long DevelopedLine::grid_index(const Period &p) const
{
  return std::lround(p.s_start / block_);
}

void DevelopedLine::close_period(double time, double s_cut)
{
  open_.t_end = time;
  if (!open_partial_)
    periods_.push_back(open_);
  for (std::size_t k = 0; k < profile_.size(); ++k)
  {
    if (!open_partial_)
    {
      profile_[k].length += open_bins_[k].length;
      profile_[k].mass += open_bins_[k].mass;
      profile_[k].charge += open_bins_[k].charge;
      profile_[k].toner += open_bins_[k].toner;
    }
    open_bins_[k] = Bin{};
  }
  open_partial_ = false;
  open_ = Period{};
  open_.t_start = time;
  open_.s_start = s_cut;
  swept_ = 0.0;
}

std::string DevelopedLine::periods_csv() const
{
  std::ostringstream o;
  o << "# the toner the drum carried past the line, per whole latent-image period (magbrush toner development): "
       "each drum element counted once as it crossed; NaN: no toner\n";
  o << "period,t_start_s,t_end_s,tma_kg_per_m2,fog_kg_per_m2,developed_q_over_m_C_per_kg,image_area_m2,"
       "dark_area_m2,image_toner,dark_toner,s_start_m\n";
  char line[320];
  for (std::size_t k = 0; k < periods_.size(); ++k)
  {
    const Period &p = periods_[k];
    const double qm = p.image_mass > 0.0 ? p.image_charge / p.image_mass : std::nan("");
    std::snprintf(line, sizeof line, "%zu,%.9g,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%ld,%ld,%.9g\n", k + 1, p.t_start,
                  p.t_end, p.tma(), p.fog(), qm, p.image_area,
                  p.dark_area,
                  p.image_toner, p.dark_toner, p.s_start);
    o << line;
  }
  return o.str();
}

std::string DevelopedLine::profile_csv() const
{
  std::ostringstream o;
  char line[320];
  const char *order = direction_ < 0.0 ? "first (a strip's leading edge is at its larger position)"
                                       : "last (a strip's leading edge is at its smaller position)";
  if (image_.period() > 0.0)
    std::snprintf(line, sizeof line,
                  "# the developed profile across one latent-image period, summed over %zu whole periods "
                  "(magbrush toner development); position from the exposed strip's centre (exposed within "
                  "+-%.6g mm); the drum carries larger positions past the line %s\n",
                  periods_.size(), 0.5 * image_.duty() * image_.period() * 1e3, order);
  else
    std::snprintf(line, sizeof line,
                  "# the developed profile across one block of a uniform (%s) image, summed over %zu whole "
                  "blocks of %.6g mm (magbrush toner development): flat where the development is steady\n",
                  image_.solid() ? "solid" : "dark", periods_.size(), block_ * 1e3);
  o << line;
  o << "position_mm,exposed,area_m2,toner_mass_per_area_kg_per_m2,charge_per_area_C_per_m2,toner\n";
  for (int k = 0; k < bins_; ++k)
  {
    const Bin &b = profile_[static_cast<std::size_t>(k)];
    const double area = b.length * depth_;
    const double position = bin_position(k);
    const bool exposed = image_.period() > 0.0 ? std::abs(position) < 0.5 * image_.duty() * image_.period()
                                               : image_.solid();
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
  out.put<std::uint8_t>(open_partial_);
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
  open_partial_ = in.get<std::uint8_t>() != 0;
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
