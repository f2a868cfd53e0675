// The five-pole Gaussian roller of cases/data/sleeve_profile_example.csv (iron shaft, μr = 1000,
// magnet μr = 1), used by the magnetostatics tests and the field benchmark against its exact
// Fourier-ring solution: one definition, so the test and the benchmark measure the same roller.
#pragma once

#include "case/case_model.h"

namespace magbrush::field::testing {

inline Roller five_pole_roller()
{
  Roller roller;
  roller.shaft_radius = 3e-3;
  roller.shaft_mu_r = 1000.0;
  roller.magnet_radius = 9.3e-3;
  roller.magnet_mu_r = 1.0;
  const double deg = 3.14159265358979323846 / 180.0;
  roller.poles = {{"S1", 0 * deg, -330e3, 10.0},
                  {"N1", 72 * deg, 172e3, 10.0},
                  {"S2", 144 * deg, -200e3, 10.0},
                  {"S3", 216 * deg, -170e3, 10.0},
                  {"N2", 288 * deg, 142e3, 10.0}};
  return roller;
}

} // namespace magbrush::field::testing
