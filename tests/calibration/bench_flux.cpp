// Accuracy against cost for the flux tools (prints tables, asserts nothing):
//  1. the exact ring: number of Fourier harmonics → error of B on the magnet surface and at
//     the probe radius, and the time of one 360-point profile;
//  2. the pole fit: harmonics of the forward model → parameter error and fit time;
//  3. the pole fit: scan noise → parameter error (and the reported uncertainty) and fit time.
#include "calibration/pole_fit.h"
#include "fields/multipole_ring.h"
#include "tests/calibration/test_support.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

using namespace magbrush;
using namespace magbrush::flux_test;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double wrap_pm_pi(double a)
{
  a = std::remainder(a, 2 * M_PI);
  return a <= -M_PI ? a + 2 * M_PI : a;
}

FluxScan synthetic_scan(const Roller &roller, double sigma, unsigned seed)
{
  FluxScan s;
  for (int k = 0; k < 360; ++k)
    s.angle.push_back(k * deg);
  MultipoleRing(roller).profile(10e-3, s.angle, s.Bn, s.Bt);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  for (size_t k = 0; k < s.angle.size(); ++k)
  {
    s.Bn[k] += noise(rng);
    s.Bt[k] += noise(rng);
  }
  return s;
}

Roller design()
{
  Roller r = example_roller();
  const double a[] = {0, 70, 145, 215, 290};
  for (size_t i = 0; i < r.poles.size(); ++i)
  {
    r.poles[i].angle = a[i] * deg;
    r.poles[i].strength = r.poles[i].strength > 0 ? 150e3 : -200e3;
  }
  return r;
}

void errors(const PoleFitResult &fit, const Roller &truth, double &angle, double &strength,
            double &angle_sigma)
{
  angle = strength = angle_sigma = 0;
  for (size_t i = 0; i < truth.poles.size(); ++i)
  {
    angle = std::max(angle, std::abs(wrap_pm_pi(fit.poles[i].pole.angle -
                                                 truth.poles[i].angle)));
    strength = std::max(strength, std::abs(fit.poles[i].pole.strength / truth.poles[i].strength - 1));
    angle_sigma = std::max(angle_sigma, fit.poles[i].angle_sigma);
  }
}

} // namespace

int main()
{
  const Roller roller = example_roller();
  std::printf("Flux tools: accuracy against cost (example roller: ideal iron shaft 3 mm, magnet "
              "9.3 mm, 5 poles, alpha = 10)\n\n");

  // 1. Harmonics of the exact ring.
  const MultipoleRing reference(roller, {200, 1e-14, 1024});
  std::vector<double> angles;
  for (int k = 0; k < 360; ++k)
    angles.push_back(k * deg);
  std::vector<double> Rn_m, Rt_m, Rn_p, Rt_p;
  reference.profile(roller.magnet_radius, angles, Rn_m, Rt_m);
  reference.profile(10e-3, angles, Rn_p, Rt_p);
  std::printf("1. Exact ring: Fourier harmonics N (automatic choice: %d)\n",
              MultipoleRing(roller).harmonic_count());
  std::printf("   N    max|dB|/max|B| at r = R_m   at r = 10 mm   build [ms]   360-pt profile [us]\n");
  for (int N : {5, 10, 15, 20, 25, 30, 35, 40, 60, 100})
  {
    auto t0 = std::chrono::steady_clock::now();
    const MultipoleRing ring(roller, {N, 1e-14, 1024});
    const double build = seconds_since(t0);
    std::vector<double> Bn, Bt;
    double e_m = 0, s_m = 0, e_p = 0, s_p = 0;
    ring.profile(roller.magnet_radius, angles, Bn, Bt);
    for (size_t k = 0; k < angles.size(); ++k)
    {
      e_m = std::max(e_m, std::hypot(Bn[k] - Rn_m[k], Bt[k] - Rt_m[k]));
      s_m = std::max(s_m, std::hypot(Rn_m[k], Rt_m[k]));
    }
    const int repeats = 200;
    t0 = std::chrono::steady_clock::now();
    for (int rep = 0; rep < repeats; ++rep)
      ring.profile(10e-3, angles, Bn, Bt);
    const double per_profile = seconds_since(t0) / repeats;
    for (size_t k = 0; k < angles.size(); ++k)
    {
      e_p = std::max(e_p, std::hypot(Bn[k] - Rn_p[k], Bt[k] - Rt_p[k]));
      s_p = std::max(s_p, std::hypot(Rn_p[k], Rt_p[k]));
    }
    std::printf("  %3d   %10.2e              %10.2e     %8.3f     %10.1f\n", N, e_m / s_m, e_p / s_p,
                build * 1e3, per_profile * 1e6);
  }

  // 2. Harmonics of the fit's forward model (noise-free scan: the error is the model's).
  std::printf("\n2. Pole fit, noise-free scan: harmonics of the forward model\n");
  std::printf("   N    max angle error [deg]   max strength error   residual RMS [mT]   fit time [ms]   evaluations\n");
  const FluxScan clean = synthetic_scan(roller, 0.0, 1);
  for (int N : {15, 20, 25, 30, 40, 71})
  {
    PoleFitOptions o;
    o.harmonics = N;
    o.fit_offset = false;
    const auto t0 = std::chrono::steady_clock::now();
    const PoleFitResult fit = fit_poles(design(), clean, 10e-3, o);
    const double t = seconds_since(t0);
    double ea, es, sa;
    errors(fit, roller, ea, es, sa);
    std::printf("  %3d   %12.2e            %10.2e          %10.2e          %8.1f       %4d   (%d)\n", N, ea / deg, es,
                fit.rms * 1e3, t * 1e3, fit.evaluations, fit.harmonics);
  }

  // 3. Scan noise.
  std::printf("\n3. Pole fit (shared alpha, no offset), 360-point scan: noise sigma on Bn and Bt, "
              "worst of 3 seeds\n");
  std::printf("   sigma [mT]   max angle error [deg] (reported 1-sigma)   max strength error   "
              "fit time [ms]\n");
  for (double sigma : {0.1e-3, 0.4e-3, 1e-3, 2e-3, 5e-3})
  {
    double wa = 0, ws = 0, wsig = 0, time = 0;
    for (unsigned seed : {1u, 2u, 3u})
    {
      PoleFitOptions o;
      o.fit_offset = false;
      const FluxScan scan = synthetic_scan(roller, sigma, seed);
      const auto t0 = std::chrono::steady_clock::now();
      const PoleFitResult fit = fit_poles(design(), scan, 10e-3, o);
      time = std::max(time, seconds_since(t0));
      double ea, es, sa;
      errors(fit, roller, ea, es, sa);
      wa = std::max(wa, ea);
      ws = std::max(ws, es);
      wsig = std::max(wsig, sa);
    }
    std::printf("   %6.1f       %8.4f (%.4f)                        %8.3f %%           %6.1f\n",
                sigma * 1e3, wa / deg, wsig / deg, 100 * ws, time * 1e3);
  }
  return 0;
}
