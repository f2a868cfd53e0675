// How symmetric the nip is about the gap centre (see nip_asymmetry.h).
#include "dem/measurements/nip_asymmetry.h"

#include "common/state_stream.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace magbrush::dem {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

enum Sum : std::size_t { F, Fx, Fxx, F_up, F_down, N, Nx, Nxx, N_up, N_down };

// The three ratios of one set of sums (forces from `first`, or counts from N).
struct Ratios
{
  double centroid = nan, spread = nan, up_over_down = nan;
};

Ratios ratios_of(const double *s, std::size_t first)
{
  Ratios r;
  const double w = s[first], wx = s[first + 1], wxx = s[first + 2], up = s[first + 3], down = s[first + 4];
  if (w > 0.0)
  {
    r.centroid = wx / w;
    r.spread = std::sqrt(std::max(0.0, wxx / w - r.centroid * r.centroid));
  }
  if (down > 0.0)
    r.up_over_down = up / down;
  return r;
}

SummaryValue value_with_error(const char *key, const char *unit, const char *meaning, double value,
                              const std::vector<double> &per_block)
{
  SummaryValue v;
  v.key = key;
  v.unit = unit;
  v.meaning = meaning;
  v.value = value;
  std::vector<double> finite;
  for (double b : per_block)
    if (std::isfinite(b))
      finite.push_back(b);
  const std::size_t n = finite.size();
  if (n >= 2)
  {
    double mean = 0.0;
    for (double b : finite)
      mean += b;
    mean /= static_cast<double>(n);
    double ss = 0.0;
    for (double b : finite)
      ss += (b - mean) * (b - mean);
    v.standard_error = std::sqrt(ss / static_cast<double>(n - 1) / static_cast<double>(n));
  }
  return v;
}

} // namespace

void NipAsymmetry::start_sample() { std::fill(std::begin(current_), std::end(current_), 0.0); }

void NipAsymmetry::add_contact(double x, double f)
{
  double *s = current_;
  s[F] += f, s[Fx] += f * x, s[Fxx] += f * x * x;
  s[N] += 1.0, s[Nx] += x, s[Nxx] += x * x;
  // A contact exactly at the centre belongs to neither side.
  if (x < 0.0)
    s[F_up] += f, s[N_up] += 1.0;
  else if (x > 0.0)
    s[F_down] += f, s[N_down] += 1.0;
}

void NipAsymmetry::end_sample()
{
  for (std::size_t k = 0; k < sums; ++k)
    series_[k].add(current_[k]);
}

std::vector<SummaryValue> NipAsymmetry::summary(std::size_t blocks) const
{
  const std::size_t n = series_[F].size();
  // The window's sums, and the same over each of `blocks` contiguous blocks (the oldest samples
  // that do not fill a block are left out, as for the other block errors).
  double whole[sums] = {};
  for (std::size_t k = 0; k < sums; ++k)
    for (double v : series_[k].values())
      whole[k] += v;
  std::vector<Ratios> force_blocks, count_blocks;
  const std::size_t length = blocks > 0 ? n / blocks : 0;
  if (length >= 1)
    for (std::size_t b = 0; b < blocks; ++b)
    {
      double part[sums] = {};
      const std::size_t from = n - (blocks - b) * length;
      for (std::size_t k = 0; k < sums; ++k)
        for (std::size_t i = from; i < from + length; ++i)
          part[k] += series_[k].values()[i];
      force_blocks.push_back(ratios_of(part, F));
      count_blocks.push_back(ratios_of(part, N));
    }
  const Ratios force = ratios_of(whole, F), count = ratios_of(whole, N);
  auto per_block = [](const std::vector<Ratios> &b, double Ratios::*member) {
    std::vector<double> out;
    for (const Ratios &r : b)
      out.push_back(r.*member);
    return out;
  };
  // key, unit, meaning, which ratio, of the forces (true) or of the touching beads.
  struct Entry
  {
    const char *key, *unit, *meaning;
    double Ratios::*ratio;
    bool force;
  };
  static const Entry entries[] = {
      {"pressure_centroid_m", "m", "sum F_n x / sum F_n over the beads touching the drum (0: centred)",
       &Ratios::centroid, true},
      {"pressure_spread_m", "m", "RMS width of the normal force about its centroid along the nip", &Ratios::spread,
       true},
      {"pressure_upstream_over_downstream", "1",
       "normal force on the drum before the gap centre (x < 0) over after it (1: symmetric)",
       &Ratios::up_over_down, true},
      {"touching_centroid_m", "m", "mean x of the beads touching the drum (0: centred)", &Ratios::centroid, false},
      {"touching_spread_m", "m", "RMS width of the touching beads about their centroid", &Ratios::spread, false},
      {"touching_upstream_over_downstream", "1",
       "beads touching the drum before the gap centre over after it (1: symmetric)", &Ratios::up_over_down, false},
  };
  std::vector<SummaryValue> out;
  for (const Entry &e : entries)
    out.push_back(value_with_error(e.key, e.unit, e.meaning, (e.force ? force : count).*e.ratio,
                                   per_block(e.force ? force_blocks : count_blocks, e.ratio)));
  return out;
}

void NipAsymmetry::write_state(StateOut &out) const
{
  for (const SampleSeries &s : series_)
    s.write_state(out);
}

void NipAsymmetry::read_state(StateIn &in)
{
  for (SampleSeries &s : series_)
    s.read_state(in);
  for (const SampleSeries &s : series_)
    if (s.size() != series_[F].size())
      in.fail("is corrupt (the nip asymmetry's series have different lengths)");
}

} // namespace magbrush::dem
