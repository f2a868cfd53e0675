// The latent image in the drum's frame (see drum_image.h).
#include "dem/measurements/drum_image.h"

#include <algorithm>
#include <cmath>

namespace magbrush::dem {

namespace {
double wrapped(double a) { return std::remainder(a, 2.0 * M_PI); } // into [−π, π]

// Cumulative exposed share of the strip pattern at u = s/period + duty/2 (per period).
double exposed_cumulative(double u, double duty)
{
  const double whole = std::floor(u);
  return whole * duty + std::min(u - whole, duty);
}
} // namespace

DrumImage::DrumImage(const LatentImage &image, const NipFrame &frame)
  : period_(image.striped() ? image.period : 0.0), duty_(image.duty), solid_(image.solid()), frame_(frame),
    nip_angle_(std::atan2(frame.sy - frame.cy, frame.sx - frame.cx))
{
}

double DrumImage::drum_arc(double px, double py, double t) const
{
  const double s_lab = frame_.drum_radius * wrapped(std::atan2(py - frame_.cy, px - frame_.cx) - nip_angle_);
  return s_lab - frame_.drum_omega * frame_.drum_radius * t;
}

double DrumImage::drum_arc_at_x(double x, double t) const
{
  const NipFrame &f = frame_;
  const double psi = f.drum_angle_of_x(x);
  const double px = f.cx + f.drum_radius * (-f.nx * std::cos(psi) + f.tx * std::sin(psi));
  const double py = f.cy + f.drum_radius * (-f.ny * std::cos(psi) + f.ty * std::sin(psi));
  return drum_arc(px, py, t);
}

bool DrumImage::exposed(double s) const
{
  if (period_ <= 0.0)
    return solid_; // uniform, as in the field stage: a solid area or dark
  return phase(s) < duty_;
}

double DrumImage::phase(double s) const
{
  if (period_ <= 0.0)
    return 0.0;
  const double u = s / period_ + 0.5 * duty_;
  return u - std::floor(u);
}

double DrumImage::exposed_length(double a, double b) const
{
  if (period_ <= 0.0)
    return solid_ ? b - a : 0.0;
  return period_ * (exposed_cumulative(b / period_ + 0.5 * duty_, duty_) -
                    exposed_cumulative(a / period_ + 0.5 * duty_, duty_));
}

} // namespace magbrush::dem
