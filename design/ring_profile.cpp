// The exact ring's profile for fixed pole shapes (see ring_profile.h).
#include "design/ring_profile.h"

#include "fields/multipole_ring.h"

namespace magbrush {

namespace {
// Enough harmonics that every coefficient beyond is below 1e-13 of the largest: the model is
// then exact to far below any tolerance a design states.
int harmonics_for(const Roller &roller)
{
  MultipoleRing::Options o;
  o.relative_tolerance = 1e-13;
  return std::max(8, MultipoleRing::choose_harmonics(roller.poles, o).harmonics);
}
} // namespace

RingProfile::RingProfile(const Roller &roller, double probe_radius)
    : model_(RingGeometry::from(roller), probe_radius, harmonics_for(roller))
{
  for (const Pole &p : roller.poles)
    spectra_.push_back(model_.spectrum(p.shape_factor));
}

void RingProfile::operator()(const std::vector<Pole> &poles, const std::vector<double> &angles,
                             std::vector<double> &Bn, std::vector<double> &Bt) const
{
  Bn.assign(angles.size(), 0.0);
  Bt.assign(angles.size(), 0.0);
  for (size_t i = 0; i < poles.size(); ++i)
  {
    const auto t = model_.terms(spectra_[i], poles[i].angle, angles, false);
    for (size_t k = 0; k < angles.size(); ++k)
    {
      Bn[k] += poles[i].strength * t.C[k];
      Bt[k] += poles[i].strength * t.S[k];
    }
  }
}

ProfileFunction RingProfile::of(const std::vector<Pole> &poles) const
{
  return [this, poles](const std::vector<double> &a, std::vector<double> &Bn, std::vector<double> &Bt) {
    (*this)(poles, a, Bn, Bt);
  };
}

} // namespace magbrush
