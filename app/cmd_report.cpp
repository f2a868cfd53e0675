// `magbrush report CASE`: the report of a finished run — plots like Kawamoto's Fig. 17–20 (slip,
// pressures, their ratio, touching density, chain inclination along the nip), the sleeve flux
// profile (over a measured scan when the case names one), a view of the brush in the nip from
// the last snapshot, the time series, and index.md / index.html with the key numbers and the
// links to the ParaView files.
//
// The steps, as report() reads:
//   1. load the case (with --set overrides, exactly as the run did);
//   2. check that the DEM outputs are there (clear error naming the missing file otherwise);
//   3. write into <output.directory>/report/: the resolved case, the measured scan normalised
//      to angle_deg,Bn_mT,Bt_mT (read by the same reader as `magbrush flux`);
//   4. call tools/report.py (found next to the sources this binary was built from, or in
//      $MAGBRUSH_TOOLS) with /usr/bin/python3 or $MAGBRUSH_PYTHON: it draws the PNGs and writes
//      index.md and index.html, every file atomically.
#include "app/subcommand.h"

#include "calibration/flux_scan.h"
#include "common/atomic_file.h"
#include "common/child_process.h"
#include "case/case_format.h"
#include "case/case_parser.h"
#include "fields/field_files.h"
#include "case/run_folder.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush {
namespace {

namespace fs = std::filesystem;

// The options, declared once: the parser and `magbrush run` read them (common/command_line.h).
const cli::CommandSpec &report_command_line()
{
  static const cli::CommandSpec spec = [] {
    cli::CommandSpec s;
    s.program = "magbrush report";
    s.usage = "magbrush report CASE [--set key=value ...] [-o DIR]";
    s.description = R"(Writes the report of a finished run of CASE into <output.directory>/report/ (or DIR):
  nip_slip.png, nip_pressure.png, nip_ratio.png, nip_density.png, nip_force_per_bead.png,
  chain_inclination.png   profiles along the nip (Kawamoto Fig. 17-20), when the scene has a drum
  brush_height.png        the brush's tip height against the gap and the carriers per sleeve area
                          along the sleeve, when the scene has a drum
  flux_profile.png        the computed sleeve flux (over output.measured_flux_file's scan if given)
  brush_snapshot.png      the brush in the nip at the last snapshot, beads coloured by speed
  time_series.png         kinetic energy, contacts, wall loads, bead budget
  toner_development.png   TMA and fog against time, the averaging window with its mean, its
                          halves (the steady-state test) and the neutralisation bound, when the
                          run measures toner development
  index.md, index.html    the key numbers with their standard errors (slip at the gap centre
                          against the relative surface speed, peak normal pressure against
                          B^2/2mu0, tangential/normal, touching density, beads in/out), every
                          key number of dem/summary.csv with ± and its bound, the inputs (the
                          main keys, the overrides, case_resolved.txt linked), run times per
                          stage and force term, the plots and links to the ParaView files
The time series shade each averaging window; the nip profiles leave out the bins averaged over
fewer contacts than a tenth of the window's samples (marked on the axis) and draw each plot's
bound: the relative surface speed, the bead-drum friction coefficient, B^2/2mu0.
)";
    s.positionals = {{"CASE", "the case file of the run"}};
    s.options = {cli::set_option(),
                 {"--output", {"-o"}, "DIR", "write the report here instead of <output.directory>/report",
                  false, {}, /*for_pipeline=*/false}};
    s.epilog = R"(Needs the DEM outputs (<output.directory>/dem/: run `magbrush dem CASE` or `magbrush run CASE`
first) and python3 with matplotlib, numpy and h5py (Debian: python3-matplotlib python3-h5py);
$MAGBRUSH_PYTHON picks the interpreter, $MAGBRUSH_TOOLS the folder holding report.py.
)";
    s.examples = {{"magbrush report cases/kawamoto_nip_fed.yaml", "the report of the case's run: results/kawamoto_nip_fed/report/"},
                  {"magbrush report cases/kawamoto_nip_fed.yaml --set drum.gap=0.5mm",
                   "the report of that variant's run (the same --set list finds its folder)"}};
    s.exit_status = "0 done, 1 missing outputs or a failed plot script, 2 bad usage.";
    return s;
  }();
  return spec;
}

// tools/report.py (app/subcommand.h find_tool_script).
std::string find_report_script() { return find_tool_script("report.py"); }

// A number for the command line of the plot script, with all the digits it needs.
std::string number(double value)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

// The command as one line, for messages only (it is never given to a shell).
std::string command_text(const std::vector<std::string> &command)
{
  std::string text;
  for (const auto &word : command)
    text += (text.empty() ? "" : " ") + word;
  return text;
}

std::string python_interpreter()
{
  if (const char *env = std::getenv("MAGBRUSH_PYTHON"))
    return env;
  if (fs::exists("/usr/bin/python3"))
    return "/usr/bin/python3"; // the Debian one, with python3-matplotlib / python3-h5py
  return "python3";
}

// The case's measured scan in the report's own simple format (angle_deg, Bn_mT, Bt_mT), so
// that the plot script does not need to know the many scan dialects `magbrush flux` reads.
std::string normalised_scan(const Case &c, const fs::path &report_dir)
{
  if (c.measured_flux_file.empty())
    return "";
  // In the roller frame: the scan's angular origin (the encoder offset a pole fit found) applied.
  ScanReadOptions read_options;
  read_options.angle_offset = c.measured_flux_angle_origin;
  const FluxScan scan = read_flux_scan(c.measured_flux_file, read_options);
  std::ostringstream o;
  o << "# measured sleeve flux from " << c.measured_flux_file << " (units normalised by magbrush report)\n";
  o << (scan.has_tangential() ? "angle_deg,Bn_mT,Bt_mT\n" : "angle_deg,Bn_mT\n");
  char line[128];
  for (std::size_t k = 0; k < scan.size(); ++k)
  {
    double a = std::fmod(scan.angle[k] * 180.0 / M_PI, 360.0);
    if (a < 0)
      a += 360.0;
    if (scan.has_tangential())
      std::snprintf(line, sizeof line, "%.6f,%.6f,%.6f\n", a, scan.Bn[k] * 1e3, scan.Bt[k] * 1e3);
    else
      std::snprintf(line, sizeof line, "%.6f,%.6f\n", a, scan.Bn[k] * 1e3);
    o << line;
  }
  const fs::path out = report_dir / "measured_flux.csv";
  write_text_atomically(out.string(), o.str());
  return out.string();
}

int report(const cli::ParsedArguments &args)
{
  const std::string case_path = args.positional(0), output_dir = args.value("--output");
  const std::vector<std::string> overrides = args.values("--set");

  const Case c = load_case(case_path, overrides);
  const fs::path results = c.output.directory;
  const fs::path dem_dir = results / "dem";
  const fs::path report_dir = output_dir.empty() ? results / "report" : fs::path(output_dir);
  // The DEM outputs the report is made of.
  for (const char *needed : {"time_series.csv", "particles.xdmf"})
    if (!fs::exists(dem_dir / needed))
    {
      std::cerr << "magbrush report: no DEM results for case '" << c.name << "': expected " << (dem_dir / needed).string()
                << ", which is missing.\n  Run the particles first: magbrush dem " << case_path
                << " (or the whole pipeline: magbrush run " << case_path << ").\n";
      return 1;
    }
  const bool nip = c.sleeve && c.drum.present && c.dem.periodic_length > 0.0;
  if (nip && !fs::exists(dem_dir / "nip_profile.csv"))
  {
    std::cerr << "magbrush report: case '" << c.name << "' has a nip but " << (dem_dir / "nip_profile.csv").string()
              << " is missing: the DEM run was made by an engine without the nip measurements, or stopped before "
                 "its end. Rebuild (cmake --build build --target magbrush-dem) and rerun `magbrush dem "
              << case_path << "`.\n";
    return 1;
  }
  fs::create_directories(report_dir);
  write_text_atomically((report_dir / "case_resolved.txt").string(),
                        "# case " + c.name + " as resolved for this report (" + case_path + ")\n" + format_case(c));
  // A folder named by the digest of its overrides says which they are, even when its stages
  // were run one by one rather than by `magbrush run` (which writes it first).
  if (c.output.automatic && !fs::exists(results / "variant.txt"))
    write_text_atomically((results / "variant.txt").string(), variant_text(case_path, c.output.overrides));
  const std::string scan = normalised_scan(c, report_dir);

  const std::string script = find_report_script();
  if (script.empty())
  {
    std::cerr << "magbrush report: tools/report.py not found next to the sources of this build; set MAGBRUSH_TOOLS to "
                 "the folder that holds it\n";
    return 1;
  }
  const Vec2 drum_centre = c.drum.present && c.sleeve ? c.drum.center(c.sleeve->radius) : Vec2{0, 0};
  std::vector<std::string> command = {python_interpreter(),
                                      script,
                                      "--case-name", c.name,
                                      "--dem-dir", dem_dir.string(),
                                      "--field-prefix", field::field_file(c, ""),
                                      "--out", report_dir.string(),
                                      "--run-times", (results / "run_times.csv").string(),
                                      "--sleeve-radius", number(c.sleeve ? c.sleeve->radius : 0.0),
                                      "--drum-radius", number(c.drum.present ? c.drum.radius : 0.0),
                                      "--drum-center", number(drum_centre[0]) + "," + number(drum_centre[1]),
                                      "--sleeve-sense", c.sleeve && c.sleeve->rpm < 0.0 ? "-1" : "1"};
  if (!scan.empty())
  {
    command.push_back("--measured-flux");
    command.push_back(scan);
  }
  std::cout << "magbrush report: writing " << report_dir.string() << "/ ..." << std::endl;
  if (const std::string why = run_program_failure(command); !why.empty())
  {
    std::cerr << "magbrush report: the plot script failed (" << why << "): " << command_text(command)
              << "\n  It needs python3 with numpy, matplotlib and h5py (Debian: apt-get install python3-matplotlib "
                 "python3-h5py), or set MAGBRUSH_PYTHON to an interpreter that has them.\n";
    return 1;
  }
  std::cout << "magbrush report: " << (report_dir / "index.html").string() << " (and index.md)\n";
  return 0;
}

int run_report(const std::vector<std::string> &args)
{
  return cli::run_command(report_command_line(), {args.begin() + 1, args.end()}, report);
}

const bool registered = register_subcommand(
    {"report", "plots, key numbers and ParaView links of a finished run (index.html)", run_report,
     report_command_line, 50});

} // namespace
} // namespace magbrush
