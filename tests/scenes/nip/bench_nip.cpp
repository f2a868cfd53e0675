// Benchmark of the development nip. Prints tables, asserts nothing, exits 0.
//
//   bench_nip [--case CASE] [--parts magnetics,diameters] [--set key=value ...]
//
//  magnetics: the case run through `magbrush run` twice — with our magnetics (the default
//             cell-multipole far field) and with the papers' (hard cutoff radius 4 diameters,
//             refresh 5 us) —
//             the simulated time per wall hour, particle-steps per second, the time split per
//             phase and force term (from each run's dem.log), and the difference of the nip
//             profiles between the two (RMS over the bins where both have beads at the drum,
//             relative to the mean of ours).
//  diameters: `magbrush sweep` over the carrier diameter 42/50/60 um with the supplied layer
//             kept (counts scaled by (60/d)^3): touching density x d^2 and the pressures
//             against the 60 um run (Kawamoto: density proportional to 1/d^2, pressure nearly
//             independent of d; the issue's bound: within +-20 %).
//
// Default CASE: tests/scenes/nip/kawamoto_nip_reduced.yaml (0.3 mm slab, about 1 min per run with
// the papers' magnetics). The full default scene: --case cases/kawamoto_nip.yaml (see
// docs/nip.md for its measured times). Runs in build/bench_nip_runs/ (kept for inspection).
#include "tests/csv_columns.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace fs = std::filesystem;

namespace {

const std::string source_dir = MAGBRUSH_SOURCE_DIR;

using Table = magbrush::testing::CsvColumns;

Table read_csv(const fs::path &path) { return magbrush::testing::read_csv_columns(path); }

double num(const std::string &s) { return std::atof(s.c_str()); }

std::map<std::string, double> summary(const fs::path &dem)
{
  std::map<std::string, double> v;
  const Table t = read_csv(dem / "nip_summary.csv");
  if (t.count("key"))
    for (std::size_t k = 0; k < t.at("key").size(); ++k)
      v[t.at("key")[k]] = num(t.at("value")[k]);
  return v;
}

struct DemCost
{
  long steps = 0;
  double simulated = 0, wall = 0, rate = 0;
  std::vector<std::pair<std::string, double>> phases; // name, seconds
};

DemCost read_log(const fs::path &log)
{
  DemCost c;
  std::ifstream in(log);
  std::string line;
  const std::regex done(R"(done: (\d+) steps to t = ([0-9.eE+-]+) s in ([0-9.eE+-]+) s wall \(([0-9.eE+-]+) particle-steps/s\))");
  const std::regex phase(R"(^\s+(.+?)\s+([0-9.]+) s\s+[0-9.]+ %)");
  bool table = false;
  while (std::getline(in, line))
  {
    std::smatch m;
    if (std::regex_search(line, m, done))
    {
      c.steps = std::atol(m[1].str().c_str());
      c.simulated = num(m[2]);
      c.wall = num(m[3]);
      c.rate = num(m[4]);
    }
    if (line.rfind("time per phase", 0) == 0)
    {
      table = true;
      c.phases.clear();
      continue;
    }
    if (table && std::regex_search(line, m, phase))
      c.phases.emplace_back(m[1], num(m[2]));
    else
      table = false;
  }
  return c;
}

int run(const std::string &cmd)
{
  std::printf("$ %s\n", cmd.c_str());
  std::fflush(stdout);
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

// RMS difference of a profile column between two runs over the bins where both have beads at
// the drum, relative to the mean magnitude of the first.
double profile_difference(const Table &a, const Table &b, const std::string &column)
{
  double d2 = 0, m = 0;
  int n = 0;
  for (std::size_t k = 0; k < a.at("x_mm").size() && k < b.at("x_mm").size(); ++k)
  {
    if (num(a.at("contact_samples")[k]) <= 0 || num(b.at("contact_samples")[k]) <= 0)
      continue;
    const double va = num(a.at(column)[k]), vb = num(b.at(column)[k]);
    d2 += (va - vb) * (va - vb);
    m += std::abs(va);
    ++n;
  }
  return n > 0 && m > 0 ? std::sqrt(d2 / n) / (m / n) : NAN;
}

} // namespace

int main(int argc, char **argv)
{
  std::string case_path = source_dir + "/tests/scenes/nip/kawamoto_nip_reduced.yaml";
  std::string parts = "magnetics,diameters", extra;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--case" && i + 1 < argc)
      case_path = argv[++i];
    else if (a == "--parts" && i + 1 < argc)
      parts = argv[++i];
    else if (a == "--set" && i + 1 < argc)
      extra += std::string(" --set '") + argv[++i] + "'";
  }
  const fs::path work = fs::absolute("bench_nip_runs");
  fs::create_directories(work);
  const std::string magbrush = fs::absolute("bin/magbrush").string();
  const std::string env = "cd '" + work.string() + "' && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ";
  std::printf("bench_nip: case %s\n", case_path.c_str());

  if (parts.find("magnetics") != std::string::npos)
  {
    struct Variant
    {
      const char *name, *tag, *sets;
    };
    // Ours: the schema's default far field (the reduced case sets the papers' magnetics, so the
    // default is restated here: keep it in step with case/case_keys_magnetics.cpp).
    const Variant variants[] = {{"ours (cell-multipole far field)", "ours",
                                 " --set dem.magnetic_far_field=cell_multipole"},
                                {"papers' (cutoff 4 d, refresh 5 us)", "papers",
                                 " --set dem.magnetic_far_field=none --set dem.magnetic_cutoff=4 "
                                 "--set dem.magnetic_refresh=5us"}};
    std::vector<DemCost> costs;
    std::vector<fs::path> dirs;
    for (const auto &v : variants)
    {
      const fs::path out = work / (std::string("magnetics_") + v.tag);
      dirs.push_back(out);
      run(env + "'" + magbrush + "' run '" + case_path + "' --skip mesh --set output.directory='" + out.string() +
          "'" + v.sets + extra + " > '" + out.string() + ".log' 2>&1");
      costs.push_back(read_log(out / "dem" / "dem.log"));
    }
    std::printf("\n== nip run cost (wall clock on this machine, 2 threads) ==\n");
    std::printf("%-36s %10s %12s %12s %16s %18s\n", "magnetics", "steps", "simulated", "wall [s]", "sim. ms / hour",
                "particle-steps/s");
    for (std::size_t k = 0; k < costs.size(); ++k)
      std::printf("%-36s %10ld %10.3g ms %12.1f %16.3g %18.3g\n", variants[k].name, costs[k].steps,
                  costs[k].simulated * 1e3, costs[k].wall,
                  costs[k].wall > 0 ? costs[k].simulated * 1e3 * 3600.0 / costs[k].wall : NAN, costs[k].rate);
    std::printf("(the wall time includes the settling phase before t = 0; steps and simulated time count t >= 0 only)\n");
    std::printf("\n== time per phase and force term [s] (share) ==\n");
    for (std::size_t k = 0; k < costs.size(); ++k)
    {
      std::printf("%s:\n", variants[k].name);
      for (const auto &[name, sec] : costs[k].phases)
        std::printf("  %-24s %10.2f  %5.1f %%\n", name.c_str(), sec, costs[k].wall > 0 ? 100 * sec / costs[k].wall : 0);
    }
    const Table a = read_csv(dirs[0] / "dem" / "nip_profile.csv"), b = read_csv(dirs[1] / "dem" / "nip_profile.csv");
    auto sa = summary(dirs[0] / "dem"), sb = summary(dirs[1] / "dem");
    if (a.count("x_mm") && b.count("x_mm"))
    {
      std::printf("\n== nip profiles: papers' magnetics against ours ==\n");
      std::printf("%-34s %12s %12s\n", "key number", "ours", "papers'");
      for (const char *key : {"slip_at_gap_centre", "peak_normal_pressure", "normal_pressure_at_gap_centre",
                              "tangential_over_normal", "density_at_gap_centre", "normal_force_per_length",
                              "touching_beads"})
        std::printf("%-34s %12.4g %12.4g\n", key, sa[key], sb[key]);
      std::printf("RMS profile difference / mean of ours: slip %.3f, normal pressure %.3f, tangential pressure %.3f, "
                  "density %.3f\n",
                  profile_difference(a, b, "slip_speed_m_s"), profile_difference(a, b, "normal_pressure_Pa"),
                  profile_difference(a, b, "tangential_pressure_Pa"), profile_difference(a, b, "density_per_mm2"));
    }
  }

  if (parts.find("diameters") != std::string::npos)
  {
    const fs::path out = work / "diameters";
    run(env + "'" + magbrush + "' sweep '" + case_path + "' --name diameter --set output.directory='" + out.string() +
        "'" + extra + " --vary populations.carrier.diameter=42um,50um,60um > '" + out.string() + ".log' 2>&1");
    const Table t = read_csv(out / "sweep_diameter" / "sweep_summary.csv");
    if (t.count("point") && t.at("point").size() == 3)
    {
      std::printf("\n== carrier diameter (supplied layer kept: counts x (60/d)^3) ==\n");
      std::printf("%8s %8s %14s %14s %18s %14s %14s %10s\n", "d [um]", "beads", "density /mm2", "density*d^2",
                  "vs 60 um (1/d^2)", "peak p [Pa]", "F_n/L [N/m]", "slip/rel");
      const double ref_density = num(t.at("density_x_d2_at_gap_centre")[2]);
      const double ref_force = num(t.at("normal_force_per_length_N_m")[2]);
      for (std::size_t k = 0; k < 3; ++k)
        std::printf("%8.0f %8s %14.4g %14.4g %18.3f %14.4g %14.4g %10.3f\n", num(t.at("diameter_um")[k]),
                    t.at("count")[k].c_str(), num(t.at("density_at_gap_centre_per_mm2")[k]),
                    num(t.at("density_x_d2_at_gap_centre")[k]), num(t.at("density_x_d2_at_gap_centre")[k]) / ref_density,
                    num(t.at("peak_normal_pressure_Pa")[k]), num(t.at("normal_force_per_length_N_m")[k]),
                    num(t.at("slip_at_gap_centre_m_s")[k]) / num(t.at("relative_surface_speed_m_s")[k]));
      std::printf("Kawamoto: density x d^2 the same for all d (issue: within +-20 %%); total force nearly independent "
                  "of d (F_n/L vs 60 um: %.3f, %.3f, 1)\n",
                  num(t.at("normal_force_per_length_N_m")[0]) / ref_force,
                  num(t.at("normal_force_per_length_N_m")[1]) / ref_force);
    }
    else
      std::printf("diameter sweep: no summary (see %s.log)\n", out.string().c_str());
  }
  return 0;
}
