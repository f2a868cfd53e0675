// The magnetic term's held steps inside the engine's thread team against the same steps
// through the serial path (MagneticForceTerm::set_held_steps_in_team), interleaved in ONE
// process on ONE trajectory. Both ways give the same bits, so the run alternates windows of
// `window_steps` steps between them and sums each way's wall time and the engine's phase
// clocks: the machine's load drifting over a minute (±30 % between identical runs on the
// shared 2-core machine) then falls on both alike, which two separate runs cannot promise.
//
// Scene: the placed quick scene (cases/kawamoto_nip.yaml, 4,300 beads, 40 ns steps, the
// magnetics holding dipoles at staleness 0.6 and 40 µs, skin 1 diameter, close pairs every 40
// steps), settled and turned for `turning_us`
// first, so that the brush flows; its roller field is computed by `magbrush field` here.
//
// The second way can instead be the team's steps without the quiet steps (`quiet` as the
// fourth argument: MagneticForceTerm::set_quiet_steps, every held step gathers the positions
// and checks them) against the quiet ones: the same bits too.
//
//   bench_magnetic_team_steps [windows per way (20)] [window_steps (250)] [turning_us (200)] [serial|quiet]
//
// Prints each way's wall time, the ratio, and where the difference sits (the engine's phases).
#include "dem/dem_run.h"
#include "dem/force_terms/magnetic_force_term.h"
#include "dem/huge_page_heap.h"
#include "dem/openmp_waiting.h"

#include "case/case_parser.h"

#include <omp.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

using namespace magbrush;
namespace fs = std::filesystem;

namespace {

magnetics::MagneticForceTerm &magnetics_of(dem::DemSystem &s)
{
  for (const auto &t : s.force_terms())
    if (auto *m = dynamic_cast<magnetics::MagneticForceTerm *>(t.get()))
      return *m;
  throw std::runtime_error("the case has no magnetic term");
}

// Engine phase clocks: integration, contacts (particles + walls), force terms, other.
struct Phases
{
  double wall = 0.0, integration = 0.0, contacts = 0.0, magnetics = 0.0, other_terms = 0.0;
};

Phases clocks(const dem::DemSystem &s)
{
  const dem::PhaseTimes p = s.phase_times();
  Phases out;
  out.integration = p.integrate;
  out.contacts = p.particle_contacts + p.wall_contacts;
  for (std::size_t k = 0; k < s.force_terms().size(); ++k)
    (dynamic_cast<const magnetics::MagneticForceTerm *>(s.force_terms()[k].get()) ? out.magnetics
                                                                                  : out.other_terms) += p.terms[k];
  return out;
}

void add_difference(Phases &sum, const Phases &after, const Phases &before, double wall)
{
  sum.wall += wall;
  sum.integration += after.integration - before.integration;
  sum.contacts += after.contacts - before.contacts;
  sum.magnetics += after.magnetics - before.magnetics;
  sum.other_terms += after.other_terms - before.other_terms;
}

} // namespace

int main(int argc, char **argv)
{
  // The wait policy and heap of `magbrush-dem` (dem_main.cpp): a short spin, then sleep.
  const bool waiting = dem::choose_openmp_waiting();
  if (dem::choose_huge_page_heap() || waiting)
    execv("/proc/self/exe", argv);
  const int windows = argc > 1 ? std::atoi(argv[1]) : 20;
  const long window_steps = argc > 2 ? std::atol(argv[2]) : 250;
  const double turning_us = argc > 3 ? std::atof(argv[3]) : 200.0;
  const bool against_looking = argc > 4 && std::string(argv[4]) == "quiet";
  const fs::path dir = fs::temp_directory_path() / ("magbrush_bench_team_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string file = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_nip.yaml";
  const std::vector<std::string> overrides = {
    "populations.carrier.count=4300", "populations.carrier.insert_box=[[12.1mm,-2.5mm,0mm],[13.0mm,1.5mm,1mm]]",
    "dem.time_step=40ns", "dem.magnetic_hold=dipoles", "dem.magnetic_staleness=0.6", "dem.magnetic_refresh=40us",
    "dem.magnetic_skin=1", "dem.magnetic_live_steps=40",
    "dem.output_interval=0 s", "field.output_dir=" + (dir / "fields").string(), "output.directory=" + dir.string()};
  std::string cmd = "cd '" + dir.string() + "' && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 '" +
                    std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush' field '" + file + "'";
  for (const auto &o : overrides)
    cmd += " --set '" + o + "'";
  cmd += " > field.log 2>&1";
  int status = 0;
  try
  {
    if (std::system(cmd.c_str()) != 0)
      throw std::runtime_error("`magbrush field` failed (see " + (dir / "field.log").string() + ")");
    Case c = load_case(file, overrides);
    c.dem.duration = turning_us * 1e-6;
    dem::RunOptions options;
    options.output_dir = (dir / "dem").string();
    options.progress_interval = 1e9;
    std::ostringstream log;
    dem::DemRun run(c, options, log);
    run.run(); // insert, settle, turn
    dem::DemSystem &system = run.system();
    magnetics::MagneticForceTerm &term = magnetics_of(system);
    std::printf("# bench_magnetic_team_steps: %d OpenMP threads (%s), %zu particles, %d windows of %ld steps per "
                "way, after %.3g us of turning\n",
                omp_get_max_threads(), dem::openmp_waiting_description().c_str(), system.particles().size(), windows,
                window_steps, turning_us);
    Phases way[2];
    long in_team = 0, quiet = 0;
    for (int w = 0; w < 2 * windows; ++w)
    {
      const int k = (w + w / 2) % 2; // in_team, serial, serial, in_team, ...: neither always first
      term.set_held_steps_in_team(against_looking || k == 0);
      term.set_quiet_steps(k == 0);
      const long before_team = term.steps_held_in_team(), before_quiet = term.quiet_steps();
      const Phases before = clocks(system);
      const double t0 = omp_get_wtime();
      system.advance(window_steps);
      const double wall = omp_get_wtime() - t0;
      add_difference(way[k], clocks(system), before, wall);
      if (k == 0)
      {
        in_team += term.steps_held_in_team() - before_team;
        quiet += term.quiet_steps() - before_quiet;
      }
    }
    const long steps = windows * window_steps;
    std::printf("| way | wall [s] | per step [us] | integration | contacts | magnetics | other terms |\n");
    std::printf("|---|---|---|---|---|---|---|\n");
    const char *names[2] = {"held steps in the team", against_looking ? "in the team, every step checked" : "serial path"};
    for (int k = 0; k < 2; ++k)
      std::printf("| %s | %.3f | %.1f | %.3f | %.3f | %.3f | %.3f |\n", names[k], way[k].wall,
                  1e6 * way[k].wall / static_cast<double>(steps), way[k].integration, way[k].contacts,
                  way[k].magnetics, way[k].other_terms);
    std::printf("in the team: %ld of %ld steps (%ld quiet); %s / in the team: %.3f\n", in_team, steps, quiet,
                against_looking ? "checked every step" : "serial", way[1].wall / way[0].wall);
  }
  catch (const std::exception &e)
  {
    std::printf("bench_magnetic_team_steps: %s\n", e.what());
    status = 1;
  }
  fs::remove_all(dir);
  return status;
}
