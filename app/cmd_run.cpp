// `magbrush run CASE`: the whole pipeline — validate, mesh, fields, DEM, report — each
// stage skipped when its outputs are up to date (the stages themselves decide that), with
// the wall time of every stage and a summary of where the outputs are.
#include "subcommand.h"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

namespace magbrush {
namespace {

const char *run_help =
    R"(Usage: magbrush run CASE [--set key=value ...] [--only STAGE[,STAGE]] [--skip STAGE[,STAGE]]

Runs the whole pipeline on one case, in order:
  check   validate the case (file, line, key, unit, range)
  mesh    write the Gmsh meshes of the roller and the nip
  field   solve the magnetic and electric fields, store them as grids (reused when
          the field-relevant inputs are unchanged)
  dem     run the particles on the stored fields
  report  plots, summary and ParaView files
Options after CASE are passed to every stage (e.g. --set drum.gap=0.3mm).
A stage that this build does not provide yet is listed and skipped.
)";

const Subcommand *find_stage(const std::string &name)
{
  for (const auto &c : subcommands())
    if (c.name == name)
      return &c;
  return nullptr;
}

std::vector<std::string> split_commas(const std::string &s)
{
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= s.size())
  {
    const size_t end = s.find(',', start);
    out.push_back(s.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos)
      break;
    start = end + 1;
  }
  return out;
}

bool contains(const std::vector<std::string> &v, const std::string &s)
{
  for (const auto &x : v)
    if (x == s)
      return true;
  return false;
}

int run_pipeline(const std::vector<std::string> &args)
{
  std::vector<std::string> stage_args; // CASE and the options every stage understands
  std::vector<std::string> only, skip;
  for (size_t i = 1; i < args.size(); ++i)
  {
    if (args[i] == "--help" || args[i] == "-h")
    {
      std::cout << run_help;
      return 0;
    }
    if ((args[i] == "--only" || args[i] == "--skip") && i + 1 < args.size())
    {
      (args[i] == "--only" ? only : skip) = split_commas(args[i + 1]);
      ++i;
      continue;
    }
    stage_args.push_back(args[i]);
  }
  if (stage_args.empty())
  {
    std::cerr << run_help;
    return 2;
  }

  const std::vector<std::string> pipeline = {"check", "mesh", "field", "dem", "report"};
  std::vector<std::pair<std::string, double>> timings;
  std::vector<std::string> unavailable;
  const auto t_start = std::chrono::steady_clock::now();
  for (size_t k = 0; k < pipeline.size(); ++k)
  {
    const std::string &name = pipeline[k];
    if ((!only.empty() && !contains(only, name)) || contains(skip, name))
      continue;
    const Subcommand *stage = find_stage(name);
    if (!stage)
    {
      unavailable.push_back(name);
      continue;
    }
    std::cout << "\n== magbrush run: stage " << k + 1 << "/" << pipeline.size() << ": " << name
              << " ==" << std::endl;
    std::vector<std::string> a = {name};
    a.insert(a.end(), stage_args.begin(), stage_args.end());
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = stage->run(a);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    timings.emplace_back(name, dt);
    if (rc != 0)
    {
      std::cerr << "magbrush run: stage '" << name << "' failed (exit " << rc
                << "); later stages not run. Outputs of earlier stages are kept.\n";
      return rc;
    }
  }

  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  std::cout << "\n== magbrush run: done in " << total << " s ==\n";
  for (const auto &[name, dt] : timings)
    std::printf("  %-7s %8.2f s\n", name.c_str(), dt);
  if (!unavailable.empty())
  {
    std::cout << "  not in this build yet:";
    for (const auto &n : unavailable)
      std::cout << " " << n;
    std::cout << "\n";
  }
  return 0;
}

const bool registered = register_subcommand(
    {"run", "the whole pipeline: check, mesh, field, dem, report", run_pipeline, 90});

} // namespace
} // namespace magbrush
