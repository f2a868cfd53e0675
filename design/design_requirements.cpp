// Judging a profile against a design target (see design_requirements.h).
#include "design/design_requirements.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace magbrush {

namespace {

constexpr double deg = M_PI / 180.0;
// A one-sided requirement (|B| below a level, a spacing, a release) aims this fraction of its
// residual scale inside its limit: the least squares balances a hinge against the pull towards
// the case's layout a hair outside the limit, and the aim keeps that hair inside.
constexpr double inside = 0.02;

std::string f1(double v)
{
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", v);
  return b;
}

std::string f3(double v)
{
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

// The sector of pole i in a layout: from halfway to its predecessor to halfway to its successor
// (counter-clockwise), as [from, to] unwrapped around the pole's angle.
std::pair<double, double> sector(const std::vector<Pole> &poles, size_t i)
{
  if (poles.size() < 2)
    return {poles[i].angle - M_PI, poles[i].angle + M_PI};
  double before = 2 * M_PI, after = 2 * M_PI;
  for (size_t j = 0; j < poles.size(); ++j)
  {
    if (j == i)
      continue;
    const double d = wrap_0_2pi(poles[j].angle - poles[i].angle); // ccw distance to j
    after = std::min(after, d > 0 ? d : 2 * M_PI);
    before = std::min(before, d > 0 ? 2 * M_PI - d : 2 * M_PI);
  }
  return {poles[i].angle - 0.5 * before, poles[i].angle + 0.5 * after};
}

// s·Bn at three points around θ.
void three(const ProfileFunction &profile, double s, double theta, double h, double f[3])
{
  std::vector<double> Bn, Bt;
  profile({theta - h, theta, theta + h}, Bn, Bt);
  for (int k = 0; k < 3; ++k)
    f[k] = s * Bn[k];
}

struct Peak
{
  double angle = 0, value = 0; // value: s·Bn at the extremum [T]
  bool found = false;
};

// The extremum of s·Bn in [from, to]: the best of a 1° grid, then parabolas through three
// points, each step narrowing its spacing to twice the last move (never below 1e-4 rad, where
// the differences are still far above rounding), until the vertex moves by < 1e-10 rad.
Peak extremum(const ProfileFunction &profile, double s, double from, double to)
{
  const int n = std::max(3, int(std::ceil((to - from) / deg)) + 1);
  std::vector<double> grid(n), Bn, Bt;
  for (int k = 0; k < n; ++k)
    grid[k] = from + (to - from) * k / (n - 1);
  profile(grid, Bn, Bt);
  int best = 0;
  for (int k = 1; k < n; ++k)
    if (s * Bn[k] > s * Bn[best])
      best = k;
  Peak p;
  p.angle = grid[best];
  p.value = s * Bn[best];
  p.found = best > 0 && best < n - 1 && p.value > 0.0;
  double theta = p.angle, h = deg;
  for (int it = 0; it < 30; ++it)
  {
    double f[3];
    three(profile, s, theta, h, f);
    const double curvature = f[0] - 2 * f[1] + f[2];
    if (!(curvature < 0.0))
      break;
    const double d = std::clamp(0.5 * h * (f[0] - f[2]) / curvature, -h, h);
    if (theta + d < from - deg || theta + d > to + deg)
      break;
    theta += d;
    if (std::abs(d) < 1e-10)
      break;
    h = std::max(std::min(h, 2 * std::abs(d)), 1e-4);
  }
  std::vector<double> at = {theta};
  profile(at, Bn, Bt);
  p.angle = theta;
  p.value = s * Bn[0];
  return p;
}

double miss_of(const RequirementResult &r)
{
  switch (r.kind)
  {
  case RequirementResult::Kind::equal: return std::abs(r.value - r.target) - r.tolerance;
  case RequirementResult::Kind::at_most: return r.value - (r.target + r.tolerance);
  case RequirementResult::Kind::at_least: return (r.target - r.tolerance) - r.value;
  }
  return 0.0;
}

} // namespace

double wrap_pm_pi(double a)
{
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

double wrap_0_2pi(double a)
{
  a = std::fmod(a, 2.0 * M_PI);
  return a < 0 ? a + 2.0 * M_PI : a;
}

RequirementSet::RequirementSet(const DesignTarget &target, const Roller &roller)
    : target_(target), nominal_(roller.poles)
{
  if (target_.release)
  {
    if (!target_.release_inputs)
      throw std::invalid_argument("a release requirement needs the carrier bead, sleeve and gravity of the case");
    const ReleaseInputs &in = *target_.release_inputs;
    const double r = in.sleeve_radius + in.bead_radius, h = 1e-3 * in.bead_radius;
    release_rings_.emplace_back(roller, r - h);
    release_rings_.emplace_back(roller, r + h);
    double span = wrap_0_2pi(target_.release->to - target_.release->from);
    const int n = int(std::ceil(span / (0.25 * deg))) + 1;
    for (int k = 0; k < n; ++k)
      release_angles_.push_back(target_.release->from + span * k / (n - 1));
  }
  if (target_.profile)
  {
    arc_samples_.assign(nominal_.size(), {});
    const auto &a = target_.profile->angle;
    for (size_t k = 0; k < a.size(); ++k)
    {
      size_t nearest = 0;
      for (size_t i = 1; i < nominal_.size(); ++i)
        if (std::abs(wrap_pm_pi(a[k] - nominal_[i].angle)) < std::abs(wrap_pm_pi(a[k] - nominal_[nearest].angle)))
          nearest = i;
      arc_samples_[nearest].push_back(k);
    }
  }
  for (const auto &c : target_.ceilings)
  {
    ceiling_start_.push_back(ceiling_angles_.size());
    double span = wrap_0_2pi(c.to - c.from);
    if (span == 0.0)
      span = 2 * M_PI;
    const int n = int(std::ceil(span / (0.5 * deg))) + 1;
    for (int k = 0; k < n; ++k)
      ceiling_angles_.push_back(c.from + span * k / (n - 1));
  }
  ceiling_start_.push_back(ceiling_angles_.size());
  for (const auto &p : target_.peaks)
    if (std::none_of(nominal_.begin(), nominal_.end(), [&](const Pole &q) { return q.name == p.pole; }))
      throw std::invalid_argument("the target names the pole '" + p.pole + "', which the case does not have");
}

void RequirementSet::profile_arcs(const ProfileFunction &profile, std::vector<RequirementResult> &out) const
{
  const ProfileTarget &t = *target_.profile;
  std::vector<double> Bn, Bt;
  profile(t.angle, Bn, Bt);
  const bool with_bt = !t.Bt.empty();
  for (size_t i = 0; i < arc_samples_.size(); ++i)
  {
    const auto &ks = arc_samples_[i];
    if (ks.empty())
      continue;
    RequirementResult r;
    const auto [from, to] = sector(nominal_, i);
    r.name = "profile near " + nominal_[i].name + " (" + f1(wrap_0_2pi(from) / deg) + "–" +
             f1(wrap_0_2pi(to) / deg) + "°)";
    r.unit = "mT";
    r.kind = RequirementResult::Kind::at_most;
    double worst_ratio = -1, sum2 = 0, worst_angle = 0;
    for (size_t k : ks)
    {
      const double dn = Bn[k] - t.Bn[k], dt = with_bt ? Bt[k] - t.Bt[k] : 0.0;
      const double w = std::sqrt(t.weight[k]) / t.tolerance[k];
      r.residuals.push_back(w * dn);
      if (with_bt)
        r.residuals.push_back(w * dt);
      const double d = std::max(std::abs(dn), std::abs(dt));
      sum2 += dn * dn + dt * dt;
      if (t.weight[k] > 0 && d / t.tolerance[k] > worst_ratio)
      {
        worst_ratio = d / t.tolerance[k];
        r.value = d * 1e3;
        r.target = t.tolerance[k] * 1e3; // the limit at the worst sample
        worst_angle = t.angle[k];
      }
    }
    r.tolerance = 0.0;
    r.miss = miss_of(r);
    r.detail = "largest |ΔBn|, |ΔBt| at " + f1(wrap_0_2pi(worst_angle) / deg) + "°, RMS " +
               f3(std::sqrt(sum2 / (ks.size() * (with_bt ? 2 : 1))) * 1e3) + " mT over " +
               std::to_string(ks.size()) + " samples";
    out.push_back(r);
  }
}

void RequirementSet::pole_peaks(const std::vector<Pole> &poles, const ProfileFunction &profile,
                                std::vector<RequirementResult> &out) const
{
  for (const auto &req : target_.peaks)
  {
    const size_t i = std::find_if(poles.begin(), poles.end(), [&](const Pole &p) { return p.name == req.pole; }) - poles.begin();
    const double s = poles[i].strength >= 0 ? 1.0 : -1.0;
    const auto [from, to] = sector(poles, i);
    const Peak peak = extremum(profile, s, from, to);
    const std::string where = "at " + f1(wrap_0_2pi(peak.angle) / deg) + "°, " +
                              (s > 0 ? "N" : "S") + (peak.found ? "" : " (no interior extremum of its sign: sector edge)");
    if (req.peak)
    {
      RequirementResult r;
      r.name = req.pole + " peak |Bn|";
      r.unit = "mT";
      r.target = *req.peak * 1e3;
      r.tolerance = req.peak_tolerance * 1e3;
      r.value = peak.value * 1e3;
      r.residuals = {(peak.value - *req.peak) / req.peak_tolerance};
      r.miss = miss_of(r);
      r.detail = where;
      out.push_back(r);
    }
    if (req.angle)
    {
      RequirementResult r;
      r.name = req.pole + " peak angle";
      r.unit = "deg";
      const double d = wrap_pm_pi(peak.angle - *req.angle);
      r.target = wrap_0_2pi(*req.angle) / deg;
      r.tolerance = req.angle_tolerance / deg;
      r.value = r.target + d / deg; // continuous across 0°
      r.residuals = {d / req.angle_tolerance};
      r.miss = miss_of(r);
      r.detail = where;
      out.push_back(r);
    }
  }
}

void RequirementSet::field_below(const ProfileFunction &profile, std::vector<RequirementResult> &out) const
{
  if (target_.ceilings.empty())
    return;
  std::vector<double> Bn, Bt;
  profile(ceiling_angles_, Bn, Bt);
  for (size_t c = 0; c < target_.ceilings.size(); ++c)
  {
    const FieldCeiling &fc = target_.ceilings[c];
    RequirementResult r;
    r.name = "|B| ≤ " + f1(fc.level * 1e3) + " mT over " + f1(wrap_0_2pi(fc.from) / deg) + "–" +
             f1(wrap_0_2pi(fc.to) / deg) + "°";
    r.unit = "mT";
    r.kind = RequirementResult::Kind::at_most;
    r.target = fc.level * 1e3;
    r.tolerance = fc.tolerance * 1e3;
    const double scale = fc.tolerance > 0 ? fc.tolerance : 0.05 * fc.level;
    double worst = -1, worst_angle = 0;
    for (size_t k = ceiling_start_[c]; k < ceiling_start_[c + 1]; ++k)
    {
      const double B = std::hypot(Bn[k], Bt[k]);
      r.residuals.push_back(std::max(0.0, B - (fc.level - inside * scale)) / scale);
      if (B > worst)
      {
        worst = B;
        worst_angle = ceiling_angles_[k];
      }
    }
    r.value = worst * 1e3;
    r.miss = miss_of(r);
    r.detail = "largest |B| at " + f1(wrap_0_2pi(worst_angle) / deg) + "°";
    out.push_back(r);
  }
}

void RequirementSet::release(const std::vector<Pole> &poles, std::vector<RequirementResult> &out) const
{
  if (!target_.release)
    return;
  const ReleaseInputs &in = *target_.release_inputs;
  const double r = in.sleeve_radius + in.bead_radius, h = 1e-3 * in.bead_radius;
  const double beta = (in.bead_mu_r - 1.0) / (in.bead_mu_r + 2.0), mu0 = 4e-7 * M_PI;
  const double g = 9.81; // the margin's unit, whatever the case's own gravity (which may be zero)
  std::vector<double> n0, t0, n1, t1;
  release_rings_[0](poles, release_angles_, n0, t0);
  release_rings_[1](poles, release_angles_, n1, t1);
  RequirementResult res;
  res.name = "release somewhere on " + f1(wrap_0_2pi(target_.release->from) / deg) + "–" +
             f1(wrap_0_2pi(target_.release->to) / deg) + "°";
  res.unit = "g";
  res.kind = RequirementResult::Kind::at_least;
  res.target = target_.release->margin;
  res.value = -1e300;
  for (size_t k = 0; k < release_angles_.size(); ++k)
  {
    const double t = release_angles_[k];
    const double dB2 = (n1[k] * n1[k] + t1[k] * t1[k] - n0[k] * n0[k] - t0[k] * t0[k]) / (2 * h);
    const double net = 3.0 * beta / (2.0 * mu0 * in.bead_density) * dB2 + in.omega * in.omega * r +
                       in.gx * std::cos(t) + in.gy * std::sin(t);
    if (net / g > res.value)
    {
      res.value = net / g;
      res.detail = "largest net outward acceleration of a carrier bead at " + f1(wrap_0_2pi(t) / deg) + "° (exact ring)";
    }
  }
  res.residuals = {std::max(0.0, res.target + inside * 0.1 - res.value) / 0.1};
  res.miss = miss_of(res);
  out.push_back(res);
}

void RequirementSet::spacing(const std::vector<Pole> &poles, std::vector<RequirementResult> &out) const
{
  if (target_.min_spacing <= 0.0 || poles.size() < 2)
    return;
  std::vector<size_t> order(poles.size());
  std::iota(order.begin(), order.end(), 0);
  // Sorted by the nominal order around the roller, so that the residual count never changes.
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return wrap_0_2pi(nominal_[a].angle) < wrap_0_2pi(nominal_[b].angle);
  });
  RequirementResult r;
  r.name = "spacing ≥ " + f1(target_.min_spacing / deg) + "°";
  r.unit = "deg";
  r.kind = RequirementResult::Kind::at_least;
  r.target = target_.min_spacing / deg;
  r.value = 360.0;
  for (size_t j = 0; j < order.size(); ++j)
  {
    const Pole &a = poles[order[j]], &b = poles[order[(j + 1) % order.size()]];
    const double gap = wrap_0_2pi(b.angle - a.angle);
    r.residuals.push_back(std::max(0.0, target_.min_spacing + inside * 0.5 * deg - gap) / (0.5 * deg));
    if (gap / deg < r.value)
    {
      r.value = gap / deg;
      r.detail = "closest pair " + a.name + "–" + b.name;
    }
  }
  r.miss = miss_of(r);
  out.push_back(r);
}

std::vector<RequirementResult> RequirementSet::evaluate(const std::vector<Pole> &poles,
                                                        const ProfileFunction &profile) const
{
  std::vector<RequirementResult> out;
  if (target_.profile)
    profile_arcs(profile, out);
  pole_peaks(poles, profile, out);
  field_below(profile, out);
  spacing(poles, out);
  release(poles, out);
  return out;
}

std::vector<double> RequirementSet::stacked_residuals(const std::vector<RequirementResult> &results)
{
  std::vector<double> all;
  for (const auto &r : results)
    all.insert(all.end(), r.residuals.begin(), r.residuals.end());
  return all;
}

} // namespace magbrush
