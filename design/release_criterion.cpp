// The field criterion for release (see release_criterion.h).
#include "design/release_criterion.h"

#include <cmath>
#include <stdexcept>

namespace magbrush {

namespace {
constexpr double mu0 = 4e-7 * M_PI;

double wrap(double a)
{
  a = std::fmod(a, 2 * M_PI);
  return a < 0 ? a + 2 * M_PI : a;
}

// B² at (r, θ) from the ring.
double B2(const MultipoleRing &ring, double r, double theta)
{
  const RingField f = ring.field_polar(r, theta);
  return f.Br * f.Br + f.Btheta * f.Btheta;
}
} // namespace

ReleaseInputs ReleaseInputs::from(const Case &c)
{
  if (!c.sleeve)
    throw std::invalid_argument("the release criterion needs the case's sleeve (radius, rpm)");
  const Population *carrier = nullptr;
  for (const auto &p : c.populations)
    if (p.kind == ParticleKind::carrier)
    {
      carrier = &p;
      break;
    }
  if (!carrier)
    throw std::invalid_argument("the release criterion needs a carrier population (its diameter and material)");
  ReleaseInputs in;
  const Material &m = c.material(carrier->material);
  in.bead_radius = 0.5 * carrier->diameter_mean;
  in.bead_density = m.density;
  in.bead_mu_r = m.mu_r;
  in.sleeve_radius = c.sleeve->radius;
  in.omega = c.sleeve->omega();
  in.gx = c.dem.gravity[0];
  in.gy = c.dem.gravity[1];
  return in;
}

ReleaseProfile release_profile(const MultipoleRing &ring, const ReleaseInputs &in, double step)
{
  const double beta = (in.bead_mu_r - 1.0) / (in.bead_mu_r + 2.0);
  const double r = in.sleeve_radius + in.bead_radius;
  const double h = 1e-3 * in.bead_radius; // central difference in r, well resolved
  const int n = int(std::round(2 * M_PI / step));
  ReleaseProfile p;
  for (int k = 0; k < n; ++k)
  {
    const double t = k * 2 * M_PI / n;
    const double dB2_dr = (B2(ring, r + h, t) - B2(ring, r - h, t)) / (2 * h);
    p.angle.push_back(t);
    p.B.push_back(std::sqrt(B2(ring, r, t)));
    p.magnetic.push_back(3.0 * beta / (2.0 * mu0 * in.bead_density) * dB2_dr);
    p.centrifugal.push_back(in.omega * in.omega * r);
    p.gravity.push_back(in.gx * std::cos(t) + in.gy * std::sin(t));
    p.net.push_back(p.magnetic.back() + p.centrifugal.back() + p.gravity.back());
  }
  // The arcs where a_net > 0, joined across 0°.
  int start = 0;
  while (start < n && p.net[start] > 0)
    ++start;
  if (start == n) // released all round
  {
    p.arcs.push_back({0.0, 2 * M_PI, 0, 0});
    return p;
  }
  for (int j = 1; j <= n; ++j)
  {
    const int k = (start + j) % n;
    if (p.net[k] <= 0)
      continue;
    ReleaseProfile::Arc a;
    a.from = p.angle[k];
    a.peak = p.net[k];
    a.at = p.angle[k];
    int len = 0;
    while (p.net[(start + j) % n] > 0 && j <= n)
    {
      const int i = (start + j) % n;
      if (p.net[i] > a.peak)
      {
        a.peak = p.net[i];
        a.at = p.angle[i];
      }
      ++j;
      ++len;
    }
    a.to = a.from + len * 2 * M_PI / n;
    p.arcs.push_back(a);
  }
  return p;
}

ReleaseVerdict release_in_window(const ReleaseProfile &p, double from, double to)
{
  double span = wrap(to - from);
  if (span == 0)
    span = 2 * M_PI;
  const size_t n = p.angle.size();
  const double step = 2 * M_PI / n;
  // Walk the window counter-clockwise on the profile's own samples.
  const size_t first = size_t(std::ceil(wrap(from) / step - 1e-9)) % n;
  const size_t count = size_t(std::floor(span / step + 1e-9)) + 1;
  ReleaseVerdict v;
  v.peak = -1e300;
  bool open = false;
  for (size_t j = 0; j < std::min(count, n); ++j)
  {
    const size_t k = (first + j) % n;
    const double angle = from + (wrap(p.angle[k] - from));
    if (p.net[k] > v.peak)
    {
      v.peak = p.net[k];
      v.at = p.angle[k];
    }
    if (p.net[k] > 0 && !open)
    {
      v.arcs.push_back({angle, angle, p.net[k], p.angle[k]});
      open = true;
    }
    else if (p.net[k] <= 0)
      open = false;
    if (open)
    {
      v.arcs.back().to = angle;
      if (p.net[k] > v.arcs.back().peak)
      {
        v.arcs.back().peak = p.net[k];
        v.arcs.back().at = p.angle[k];
      }
    }
  }
  v.releases = v.peak > 0;
  return v;
}

} // namespace magbrush
