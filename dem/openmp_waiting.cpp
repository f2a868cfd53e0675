#include "dem/openmp_waiting.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace magbrush::dem {

namespace {
// libgomp's spin loop (config/linux/wait.h, do_spin): load the flag, compare, cpu_relax().
inline void relax()
{
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield" ::: "memory");
#else
  std::atomic_signal_fence(std::memory_order_seq_cst);
#endif
}
} // namespace

double spin_round_seconds()
{
  std::atomic<int> flag{0};
  constexpr int rounds = 20000;
  double best = 1e30;
  for (int trial = 0; trial < 5; ++trial)
  {
    const auto t0 = std::chrono::steady_clock::now();
    int seen = 0;
    for (int k = 0; k < rounds; ++k)
    {
      seen += flag.load(std::memory_order_relaxed);
      relax();
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (seen == 0)
      best = std::min(best, s / rounds);
  }
  return best;
}

bool choose_openmp_waiting(double spin_seconds)
{
  if (std::getenv("OMP_WAIT_POLICY") || std::getenv("GOMP_SPINCOUNT"))
    return false; // the user's choice wins
  const double round = spin_round_seconds();
  // Clamped: a pause may be nearly free (old CPUs) or slow (~40 ns); keep 0.5–100 µs-ish.
  const long count = std::clamp(std::lround(spin_seconds / std::max(round, 1e-10)), 100L, 200000L);
  setenv("OMP_WAIT_POLICY", "PASSIVE", 1);
  setenv("GOMP_SPINCOUNT", std::to_string(count).c_str(), 1);
  return true;
}

std::string openmp_waiting_description()
{
  const char *policy = std::getenv("OMP_WAIT_POLICY");
  const char *spin = std::getenv("GOMP_SPINCOUNT");
  std::string s = std::string("OMP_WAIT_POLICY=") + (policy ? policy : "(unset)");
  if (spin)
  {
    char buf[128];
    const double us = 1e6 * spin_round_seconds() * std::atof(spin);
    std::snprintf(buf, sizeof buf, ", GOMP_SPINCOUNT=%s (spin ~%.0f us, then sleep)", spin, us);
    s += buf;
  }
  return s;
}

} // namespace magbrush::dem
