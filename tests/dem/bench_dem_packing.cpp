// Throughput of the contact engine on a dense periodic packing, the workload of the nip and
// the compression scenes: 60 µm carriers, 2200 kg/m³, E = 1 GPa, ν = 0.35, μ = 0.45,
// Kawamoto damping 0.6 and polygon-rule rolling friction, ~6 contacts per particle (a simple
// cubic lattice compressed by 0.5 % of the diameter, randomly perturbed and set moving), all
// three directions periodic, N ≈ 14k and 55k.
//
// Prints particle-steps per second on 1 and 2 threads, the split of the step time between
// neighbour list, contacts, integration and output (one HDF5 snapshot every 100 steps), the
// parallel speed-up, and the memory per particle including the contact history.
//   bench_dem_packing [steps [max_threads [repeats]]]   (default 300 2 1)
// BENCH_SIDES=38 (or 24, or 24,38: the default) runs only those lattice sizes, e.g. to profile
// one of them alone.
// The machine may be shared: each row also gives the median rate over 10-step windows (a
// preempted window does not pull it down), the 1-minute load average, and the CPU time of the
// busiest thread. The "CPU speed-up" (1-thread CPU time / busiest thread's CPU time with more
// threads) shows how evenly the work splits whatever the load; it leaves out the time threads
// wait at the step's barriers, which only a quiet machine shows (the wall-time speed-up). With repeats > 1
// every configuration runs `repeats` times (1 and 2 threads back to back, so that the
// speed-up compares runs under the same load) and a summary gives medians and ranges.
#include "dem/dem_system.h"
#include "dem/huge_page_heap.h"
#include "dem/openmp_waiting.h"
#include "dem/snapshot_writer.h"
#include "tests/test_temp_dir.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <vector>
#include <cstdlib>
#include <unistd.h>
#include <filesystem>
#include <random>

using namespace magbrush;
using namespace magbrush::dem;

namespace {

Case packing_case(int per_side, double spacing)
{
  Case c;
  c.name = "bench";
  c.scene = "box";
  Material m;
  m.name = "carrier";
  m.youngs_modulus = 1e9;
  m.poisson_ratio = 0.35;
  m.density = 2200;
  m.friction = 0.45;
  m.polygon_angles = 12;
  m.damping = 0.6;
  c.materials.push_back(m);
  Population p;
  p.name = "carrier";
  p.material = "carrier";
  p.diameter_mean = 60e-6;
  c.populations.push_back(p);
  const double L = per_side * spacing;
  c.dem.periodic_length = c.dem.periodic_length_x = c.dem.periodic_length_y = L;
  c.dem.gravity = {0, 0, 0};
  c.dem.verlet_skin = 0.1; // of the diameter: 6 µm
  return c;
}

double load_average()
{
  double l = -1;
  std::ifstream("/proc/loadavg") >> l;
  return l;
}

double median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// CPU time consumed so far by each thread of the OpenMP team [s] (libgomp keeps its threads
// between regions, so two readings bracket the work of each thread).
std::vector<double> thread_cpu_times(int threads)
{
  std::vector<double> t(static_cast<std::size_t>(threads), 0.0);
#pragma omp parallel num_threads(threads)
  {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    t[static_cast<std::size_t>(omp_get_thread_num())] = static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  return t;
}

struct Result
{
  double window_rate = 0, load = 0; // median over 10-step windows; load average at the end
  double busiest_thread_cpu = 0;    // CPU seconds of the busiest thread in the timed loop
  double rate = 0, neighbour = 0, contact = 0, integrate = 0, output = 0, total = 0, bytes = 0, contacts = 0;
  long rebuilds = 0;
  double rebuild_ms = 0, rebuild_steps = 0; // cost of one list rebuild, in ms and in steps
};

// The packing: per_side³ spheres on a slightly compressed cubic lattice with random jitter
// and velocities, initialised and warmed up (first rebuilds, page faults).
std::unique_ptr<DemSystem> make_packing(int per_side)
{
  const double d = 60e-6, spacing = 0.995 * d;
  auto sys = std::make_unique<DemSystem>(packing_case(per_side, spacing));
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto &p = sys->particles();
  for (int i = 0; i < per_side; ++i)
    for (int j = 0; j < per_side; ++j)
      for (int k = 0; k < per_side; ++k)
      {
        p.add({(i + 0.5) * spacing + 0.2e-6 * u(rng), (j + 0.5) * spacing + 0.2e-6 * u(rng),
               (k + 0.5) * spacing + 0.2e-6 * u(rng)},
              0.5 * d, 2200, 0, 0.0);
        p.vx.back() = 0.05 * u(rng);
        p.vy.back() = 0.05 * u(rng);
        p.vz.back() = 0.05 * u(rng);
      }
  sys->initialize();
  sys->advance(20);
  return sys;
}

// The 2-thread speed-up measured so that a shared (or oversubscribed virtual) machine cannot
// fake it: ONE system alternates 10-step windows on 1 and on 2 threads (the results do not
// depend on the thread count), so a slow spell of the host hits both alike. Returns the
// ratio of the summed times and the median of the window-pair ratios.
std::pair<double, double> interleaved_speedup(int per_side, int steps)
{
  auto sys = make_packing(per_side);
  double t1 = 0, t2 = 0;
  std::vector<double> ratios;
  for (int k = 0; k < steps; k += 10)
  {
    double t[2];
    for (int threads : {1, 2})
    {
      omp_set_num_threads(threads);
      sys->advance(1); // let the team form (a thread woken from sleep) outside the timing
      const double t0 = omp_get_wtime();
      sys->advance(10);
      t[threads - 1] = omp_get_wtime() - t0;
    }
    t1 += t[0];
    t2 += t[1];
    ratios.push_back(t[0] / t[1]);
  }
  return {t1 / t2, median(ratios)};
}

Result run(int per_side, int threads, int steps)
{
  omp_set_num_threads(threads);
  const auto holder = make_packing(per_side);
  DemSystem &sys = *holder;
  auto &p = sys.particles();
  const PhaseTimes before = sys.phase_times();
  const long rebuilds0 = sys.neighbour_rebuilds();
  const auto dir = magbrush::testing::test_temp_dir("bench_dem") / "snapshots";
  SnapshotWriter writer(dir.string());
  double output = 0.0;
  std::vector<double> windows;
  const std::vector<double> cpu0 = thread_cpu_times(threads);
  const double t0 = omp_get_wtime();
  double w0 = t0;
  // Ten steps at a time in one go (the engine keeps its thread team between them), as
  // DemRun does between outputs.
  for (int k = 10; k <= steps; k += 10)
  {
    sys.advance(10);
    if (k % 100 == 0)
    {
      const double o0 = omp_get_wtime();
      writer.write(sys);
      output += omp_get_wtime() - o0;
    }
    if (k % 10 == 0)
    {
      const double w1 = omp_get_wtime();
      windows.push_back(w1 - w0);
      w0 = w1;
    }
  }
  Result r;
  r.total = omp_get_wtime() - t0;
  const std::vector<double> cpu1 = thread_cpu_times(threads);
  for (std::size_t t = 0; t < cpu1.size(); ++t)
    r.busiest_thread_cpu = std::max(r.busiest_thread_cpu, cpu1[t] - cpu0[t]);
  r.window_rate = windows.empty() ? 0.0 : 10.0 * static_cast<double>(p.size()) / median(windows);
  r.load = load_average();
  const PhaseTimes &after = sys.phase_times();
  r.neighbour = after.neighbour - before.neighbour;
  r.contact = after.particle_contacts - before.particle_contacts;
  r.integrate = after.integrate - before.integrate + after.guards - before.guards;
  r.output = output;
  r.rate = static_cast<double>(steps) * static_cast<double>(p.size()) / r.total;
  r.bytes = static_cast<double>(sys.memory_bytes()) / static_cast<double>(p.size());
  r.contacts = 2.0 * static_cast<double>(sys.particle_contacts()) / static_cast<double>(p.size());
  r.rebuilds = sys.neighbour_rebuilds() - rebuilds0;
  // The list rarely needs rebuilding in a dense packing (skin 6 µm); measure one rebuild
  // (re-sort + cell list + history transfer) explicitly.
  const double nb0 = sys.phase_times().neighbour;
  for (int k = 0; k < 5; ++k)
  {
    sys.request_neighbour_rebuild();
    sys.step();
  }
  r.rebuild_ms = 1e3 * (sys.phase_times().neighbour - nb0) / 5.0;
  r.rebuild_steps = 1e-3 * r.rebuild_ms / (r.total / steps);
  std::filesystem::remove_all(dir);
  return r;
}

// The lattice sizes (particles per side) to run: BENCH_SIDES="24,38" by default.
std::vector<int> bench_sides()
{
  std::vector<int> sides;
  const char *env = std::getenv("BENCH_SIDES");
  for (const char *c = env ? env : "24,38"; *c;)
  {
    char *end = nullptr;
    const long v = std::strtol(c, &end, 10);
    if (end == c)
      break;
    if (v > 0)
      sides.push_back(static_cast<int>(v));
    c = *end == ',' ? end + 1 : end;
  }
  return sides;
}

} // namespace

int main(int argc, char **argv)
{
  // The OpenMP runtime reads its wait policy once, at start-up, and glibc its allocator
  // tunables: choose them (a spin as long as a wake-up, then sleep: openmp_waiting.h; the
  // arrays on huge pages: huge_page_heap.h) and restart once so that they take effect.
  const bool waiting = magbrush::dem::choose_openmp_waiting();
  const bool huge_pages = magbrush::dem::choose_huge_page_heap();
  if (waiting || huge_pages)
    execv("/proc/self/exe", argv);
  const int steps = argc > 1 ? std::atoi(argv[1]) : 300;
  const int max_threads = argc > 2 ? std::atoi(argv[2]) : 2;
  const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 1;
  std::printf("DEM dense periodic packing: 60 um, 2200 kg/m3, E = 1 GPa, nu = 0.35, mu = 0.45, rolling "
              "friction, damping; %d steps (+20 warm-up), snapshot every 100 steps; %d repeat(s)\n\n",
              steps, repeats);
  std::printf("OpenMP waiting: %s\n", magbrush::dem::openmp_waiting_description().c_str());
  std::printf("allocator: %s (huge pages: MAGBRUSH_HUGE_PAGES=0 turns them off)\n\n",
              magbrush::dem::huge_page_heap_description().c_str());
  std::printf("%8s %7s %12s %8s | %7s %7s %7s %7s | %8s %9s %8s %8s   %-16s %12s %5s %9s\n", "N", "threads",
              "p-steps/s", "speedup", "neigh%", "cont%", "integ%", "out%", "B/part", "contacts", "rebuilds",
              "wall s", "one rebuild", "median 10-st", "load", "CPU s");
  std::printf("%8s %7s %12s %8s | %7s %7s %7s %7s | %8s %9s %8s %8s   %-16s %12s %5s %9s\n", "", "", "", "", "", "", "",
              "", "", "", "", "", "ms (steps)", "p-steps/s", "1 min", "busiest");
  // rate[(N, threads)] and speed-up[(N, threads)] over the repeats
  std::map<std::pair<int, int>, std::vector<double>> rates, window_rates, speedups, cpu_speedups, loads;
  for (int rep = 0; rep < repeats; ++rep)
    for (int per_side : bench_sides())
    {
      double single = 0, single_cpu = 0;
      for (int threads = 1; threads <= max_threads; ++threads)
      {
        const Result r = run(per_side, threads, steps);
        if (threads == 1)
        {
          single = r.rate;
          single_cpu = r.busiest_thread_cpu;
        }
        const int N = per_side * per_side * per_side;
        rates[{N, threads}].push_back(r.rate);
        window_rates[{N, threads}].push_back(r.window_rate);
        speedups[{N, threads}].push_back(r.rate / single);
        cpu_speedups[{N, threads}].push_back(single_cpu / r.busiest_thread_cpu);
        loads[{N, threads}].push_back(r.load);
        char rebuild[32];
        std::snprintf(rebuild, sizeof rebuild, "%.2f (%.1f)", r.rebuild_ms, r.rebuild_steps);
        std::printf("%8d %7d %12.4g %8.2f | %7.1f %7.1f %7.1f %7.1f | %8.0f %9.2f %8ld %8.2f   %-16s %12.4g %5.2f %9.3f\n",
                    N, threads, r.rate, r.rate / single, 100 * r.neighbour / r.total, 100 * r.contact / r.total,
                    100 * r.integrate / r.total, 100 * r.output / r.total, r.bytes, r.contacts, r.rebuilds,
                    r.total, rebuild, r.window_rate, r.load, r.busiest_thread_cpu);
      }
    }
  if (repeats > 1)
  {
    std::printf("\nsummary over %d repeats: median (min-max); speed-up = 2-thread / 1-thread rate of the same "
                "repeat (back to back)\n",
                repeats);
    std::printf("%8s %7s %28s %28s %24s %24s %18s\n", "N", "threads", "p-steps/s", "median 10-step p-steps/s",
                "speed-up", "CPU speed-up", "load 1 min");
    for (const auto &[key, v] : rates)
    {
      const auto mm = [](const std::vector<double> &x, const char *fmt) {
        char b[64];
        std::snprintf(b, sizeof b, fmt, median(x), *std::min_element(x.begin(), x.end()),
                      *std::max_element(x.begin(), x.end()));
        return std::string(b);
      };
      std::printf("%8d %7d %28s %28s %24s %24s %18s\n", key.first, key.second, mm(v, "%.4g (%.3g-%.3g)").c_str(),
                  mm(window_rates[key], "%.4g (%.3g-%.3g)").c_str(), mm(speedups[key], "%.2f (%.2f-%.2f)").c_str(),
                  mm(cpu_speedups[key], "%.2f (%.2f-%.2f)").c_str(), mm(loads[key], "%.2f (%.2f-%.2f)").c_str());
    }
  }
  if (max_threads >= 2)
  {
    std::printf("\n2-thread speed-up from interleaved windows (one system, 10 steps on 1 thread, then 10 on 2, "
                "%d steps each; robust against a slow spell of a shared host):\n%8s %22s %26s\n",
                steps, "N", "sum(t1)/sum(t2)", "median of window ratios");
    for (int per_side : bench_sides())
    {
      const auto [ratio, med] = interleaved_speedup(per_side, steps);
      std::printf("%8d %22.2f %26.2f\n", per_side * per_side * per_side, ratio, med);
    }
  }
  std::printf("\n(contacts = touching neighbours per particle; B/part = particle, force, neighbour-list, history "
              "and scratch storage per particle)\n");
  return 0;
}
