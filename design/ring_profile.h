// The sleeve profile of a pole layout whose shapes are fixed: the exact ring of the pole fit
// (calibration/pole_fit.h, PoleProfileModel) with each pole's Fourier spectrum computed once,
// so that a design can evaluate thousands of layouts that differ only in angles and strengths.
#pragma once

#include "calibration/pole_fit.h"

#include <functional>
#include <vector>

namespace magbrush {

// A profile source: Bn, Bt [T] at the given angles [rad] (the ring model, or an FEM profile).
using ProfileFunction =
    std::function<void(const std::vector<double> &angles, std::vector<double> &Bn, std::vector<double> &Bt)>;

class RingProfile
{
public:
  // The geometry of `roller`, its poles' shape factors, at `probe_radius` (outside the magnet).
  RingProfile(const Roller &roller, double probe_radius);
  // Bn, Bt at `angles` for poles with the roller's shapes, in the roller's pole order.
  void operator()(const std::vector<Pole> &poles, const std::vector<double> &angles,
                  std::vector<double> &Bn, std::vector<double> &Bt) const;
  // The same as a ProfileFunction of one layout.
  ProfileFunction of(const std::vector<Pole> &poles) const;
  int harmonics() const { return model_.harmonics(); }

private:
  PoleProfileModel model_;
  std::vector<GaussianPoleSpectrum> spectra_;
};

} // namespace magbrush
