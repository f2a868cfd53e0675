// Shared helpers of the flux tests: the roller that generated the example scan (its header:
// ideal iron shaft r < 3 mm, magnet 3..9.3 mm, μ_r = 1, probe radius 10 mm, five poles with
// α = 10), the pole formula itself, and a plain reader for the example file.
#pragma once

#include "case/case_model.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush::flux_test {

constexpr double mu0 = 4e-7 * M_PI;
constexpr double deg = M_PI / 180.0;

inline Roller example_roller()
{
  Roller r;
  r.shaft_radius = 3e-3;
  r.shaft_mu_r = std::numeric_limits<double>::infinity();
  r.magnet_radius = 9.3e-3;
  r.magnet_mu_r = 1.0;
  r.poles = {{"S1", 0 * deg, -330e3, 10}, {"N1", 72 * deg, 172e3, 10},
             {"S2", 144 * deg, -200e3, 10}, {"S3", 216 * deg, -170e3, 10},
             {"N2", 288 * deg, 142e3, 10}};
  return r;
}

// Σ_i M_i exp(−α_i wrap(θ − φ_i)²), straight from the definition.
inline double pole_magnetisation(const Roller &roller, double theta)
{
  double m = 0;
  for (const Pole &p : roller.poles)
  {
    double u = std::remainder(theta - p.angle, 2 * M_PI);
    if (u <= -M_PI)
      u += 2 * M_PI;
    m += p.strength * std::exp(-p.shape_factor * u * u);
  }
  return m;
}

inline std::string example_scan_path()
{
  return std::string(MAGBRUSH_SOURCE_DIR) + "/cases/data/sleeve_profile_example.csv";
}

struct PlainScan
{
  std::vector<double> angle, Bn, Bt; // rad, T, T
};

// Independent of calibration/flux_scan (deliberately naive): skip '#' lines and the header.
inline PlainScan read_example_scan_plain()
{
  std::ifstream in(example_scan_path());
  if (!in)
    throw std::runtime_error("cannot open " + example_scan_path());
  PlainScan s;
  std::string line;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#' || line[0] == 'a')
      continue;
    std::istringstream ls(line);
    double a, bn, bt;
    char c1, c2;
    ls >> a >> c1 >> bn >> c2 >> bt;
    s.angle.push_back(a * deg);
    s.Bn.push_back(bn * 1e-3);
    s.Bt.push_back(bt * 1e-3);
  }
  return s;
}

} // namespace magbrush::flux_test
