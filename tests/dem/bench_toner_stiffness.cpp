// The toner stiffness factor (dem.toner_stiffness_factor) as an accuracy knob. A 7 µm toner
// against a 50 GPa wall needs a step of ~1 ns, ~40× below the carriers'; scaling the toner's
// Young's modulus by f lengthens the stable step by ~f^(-1/2) (Rayleigh) to f^(-2/5) (Hertz).
// What it costs, against the full stiffness (f = 1), for three development observables:
//  * the pull-off field of a toner on a plate (ramped field): in a Hertz + Derjaguin (DMT)
//    model F0 = A R / (6 z0²) does not depend on E, so only the ramp's dynamic lag changes;
//  * the rebound speed of a toner thrown at the plate slowly (near capture by adhesion),
//    where the dissipated energy depends on how far the adhesion loads the Hertz spring;
//  * the contact duration of that impact, ∝ E^(-2/5) (the time a toner sits on a carrier or
//    the drum in a collision, which sets how long it feels contact forces).
// Printed: step, steps per simulated µs, run time, and each error.
#include "tests/dem/adhesion_scenes.h"

#include <chrono>
#include <cmath>
#include <cstdio>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

int main()
{
  const double factors[] = {1.0, 0.3, 0.1, 0.03, 0.01, 0.001};
  const double slow = 0.03, fast = 0.1; // impact speeds [m/s]; captured below ~0.02 m/s
  PullOff ref_pull;
  Rebound ref_slow, ref_fast;
  std::printf("toner stiffness factor f: errors against f = 1 (7 um toner, 50 nm asperities, A = 1.4e-19 J, "
              "50 GPa plate)\n");
  std::printf("%8s %10s %9s %9s | %12s | %11s %11s | %11s %11s | %13s\n", "f", "dt [s]", "steps/us", "run [s]",
              "pull-off err", "v_out(0.03)", "err", "v_out(0.1)", "err", "t_contact err");
  for (const double f : factors)
  {
    const auto start = std::chrono::steady_clock::now();
    const PullOff pull = pull_off(false, 40e-6, f);
    const Rebound s = rebound(slow, f), q = rebound(fast, f);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (f == 1.0)
    {
      ref_pull = pull;
      ref_slow = s;
      ref_fast = q;
    }
    std::printf("%8.3g %10.3g %9.0f %9.3f | %12.3e | %11.4g %11.3e | %11.4g %11.3e | %13.3e\n", f, pull.dt,
                1e-6 / pull.dt, seconds, pull.field / ref_pull.field - 1.0, s.speed,
                (s.speed - ref_slow.speed) / slow, q.speed, (q.speed - ref_fast.speed) / fast,
                q.contact_time / ref_fast.contact_time - 1.0);
  }
  std::printf("pull-off against F0/q at f = 1: %.3e (the ramp's lag, 40 us ramp)\n",
              ref_pull.field / ref_pull.predicted - 1.0);
  return 0;
}
