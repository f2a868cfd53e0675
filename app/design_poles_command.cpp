// `magbrush design poles`: the pole layout for a target, as run() reads:
//   1. the case, the target (profile or specification) and the constraints;
//   2. bounded least squares on the exact ring from several starts (design/pole_design.h);
//   3. the layout against the case's, every requirement met or missed, the binding
//      constraints when it is infeasible, the sensitivity table;
//   4. <case>_designed.yaml, the profile and requirement tables;
//   5. the FEM check: magbrush-field on the designed case, the requirements judged again on
//      its profile;
//   6. the plot (tools/plot_design.py), the time taken and the design's page (app/design_page.h).
#include "app/design_poles_command.h"

#include "app/design_page.h"
#include "app/flux_tools.h"
#include "calibration/flux_scan.h"
#include "common/atomic_file.h"
#include "case/case_parser.h"
#include "case/units.h"
#include "design/design_sensitivity.h"
#include "design/pole_design.h"
#include "design/text_columns.h"

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace magbrush {
namespace {

namespace fs = std::filesystem;
constexpr double to_deg = 180.0 / M_PI;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0)
{
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::vector<std::string> split_commas(const std::vector<std::string> &values)
{
  std::vector<std::string> out;
  for (const auto &v : values)
  {
    std::stringstream ss(v);
    for (std::string item; std::getline(ss, item, ',');)
      if (!item.empty())
        out.push_back(item);
  }
  return out;
}

// The requirements, one line each: target ± tolerance, value, met or missed by how much.
std::string requirements_table(const std::vector<RequirementResult> &reqs)
{
  std::ostringstream out;
  char buf[512];
  std::snprintf(buf, sizeof buf, "  %-44s %-22s %10s   %s\n", "requirement", "target", "value", "verdict");
  out << buf;
  for (const auto &r : reqs)
  {
    const char *op = r.kind == RequirementResult::Kind::equal ? "=" : r.kind == RequirementResult::Kind::at_most ? "≤" : "≥";
    char target[64];
    if (r.tolerance > 0)
      std::snprintf(target, sizeof target, "%s %.2f ± %.2f %s", op, r.target, r.tolerance, r.unit.c_str());
    else
      std::snprintf(target, sizeof target, "%s %.2f %s", op, r.target, r.unit.c_str());
    char verdict[96];
    if (r.met())
      std::snprintf(verdict, sizeof verdict, "met (margin %.2f %s)", -r.miss, r.unit.c_str());
    else
      std::snprintf(verdict, sizeof verdict, "MISSED by %.2f %s", r.miss, r.unit.c_str());
    std::snprintf(buf, sizeof buf, " %10.3f   %s; %s\n", r.value, verdict, r.detail.c_str());
    out << "  " << padded(r.name, 44) << " " << padded(target, 22) << buf;
  }
  return out.str();
}

std::string requirements_csv(const std::vector<RequirementResult> &ring, const std::vector<RequirementResult> *fem)
{
  std::ostringstream out;
  out << "requirement,kind,unit,target,tolerance,value_ring,met_ring,miss_ring"
      << (fem ? ",value_fem,met_fem,miss_fem" : "") << "\n";
  for (size_t k = 0; k < ring.size(); ++k)
  {
    const auto &r = ring[k];
    out << "\"" << r.name << "\","
        << (r.kind == RequirementResult::Kind::equal ? "equal" : r.kind == RequirementResult::Kind::at_most ? "at_most" : "at_least")
        << "," << r.unit << "," << r.target << "," << r.tolerance << "," << r.value << "," << r.met() << "," << r.miss;
    if (fem)
      out << "," << (*fem)[k].value << "," << (*fem)[k].met() << "," << (*fem)[k].miss;
    out << "\n";
  }
  return out.str();
}

// The layout against the case's, with the box of each free unknown and a mark at a bound.
std::string layout_table(const std::vector<Pole> &start, const DesignResult &d)
{
  std::ostringstream out;
  char buf[256];
  out << "  pole   angle [deg]: case → designed   (box)              |M| [kA/m]: case → designed   (box)\n";
  for (size_t i = 0; i < d.poles.size(); ++i)
  {
    std::string angle_box = "fixed", strength_box = "fixed";
    for (const auto &q : d.parameters)
    {
      if (q.pole != i)
        continue;
      char b[64];
      if (q.angle)
        std::snprintf(b, sizeof b, "%.1f..%.1f", q.low * to_deg, q.high * to_deg), angle_box = b;
      else
        std::snprintf(b, sizeof b, "%.0f..%.0f", q.low * 1e-3, q.high * 1e-3), strength_box = b;
    }
    std::snprintf(buf, sizeof buf, "  %-5s  %8.3f → %8.3f   (%-16s)   %8.2f → %8.2f   (%s)\n", d.poles[i].name.c_str(),
                  wrap_0_2pi(start[i].angle) * to_deg, d.poles[i].angle * to_deg, angle_box.c_str(),
                  std::abs(start[i].strength) * 1e-3, std::abs(d.poles[i].strength) * 1e-3, strength_box.c_str());
    out << buf;
  }
  return out.str();
}

// A profile read from a file (the FEM's), interpolated periodically.
ProfileFunction profile_from_file(const std::string &path)
{
  ScanReadOptions o;
  o.min_points = 16;
  const FluxScan fem = read_flux_scan(path, o);
  return [fem](const std::vector<double> &a, std::vector<double> &Bn, std::vector<double> &Bt) {
    std::vector<double> wrapped(a.size());
    for (size_t k = 0; k < a.size(); ++k)
      wrapped[k] = wrap_0_2pi(a[k]);
    Bn = interpolate_periodic(fem.angle, fem.Bn, wrapped);
    Bt = fem.has_tangential() ? interpolate_periodic(fem.angle, fem.Bt, wrapped) : std::vector<double>(a.size(), 0.0);
  };
}

class DesignPolesCommand
{
public:
  explicit DesignPolesCommand(const cli::ParsedArguments &args) : args_(args) {}

  int run()
  {
    const auto t0 = Clock::now();
    load_case_target_and_constraints();
    const auto t_solve = Clock::now();
    design_ = design_poles(*case_.roller, probe_radius_, target_, constraints_, options_);
    solve_seconds_ = seconds_since(t_solve);
    report_design();
    write_designed_case();
    write_tables();
    const auto t_fem = Clock::now();
    check_by_fem();
    fem_seconds_ = seconds_since(t_fem);
    write_profile_csv();
    plot();
    const double total = seconds_since(t0);
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "\nTime: design %.2f s (%d starts, %ld ring evaluations), FEM check %.2f s, total %.2f s\n",
                  solve_seconds_, int(design_.start_costs.size()), design_.evaluations, fem_seconds_, total);
    std::cout << buf;
    report_ << buf;
    write_text_atomically(dir_ + "/design_report.txt", report_.str());
    std::cout << "  report      " << dir_ << "/design_report.txt\n";
    write_page(buf + 1);
    std::cout << "  page        " << dir_ << "/index.html\n";
    return design_.feasible ? 0 : 3;
  }

private:
  const cli::ParsedArguments &args_;
  Case case_;
  double probe_radius_ = 0;
  DesignTarget target_;
  DesignConstraints constraints_;
  DesignOptions options_;
  DesignResult design_;
  std::string dir_, designed_case_;
  std::vector<RequirementResult> fem_requirements_;
  std::string fem_path_;
  double solve_seconds_ = 0, fem_seconds_ = 0;
  SensitivityTable sensitivity_;
  std::string fem_note_;
  std::ostringstream report_; // everything printed, for design_report.txt

  void say(const std::string &text)
  {
    std::cout << text << std::flush;
    report_ << text;
  }

  // 1. The case, the target, the constraints (file, then the command line's).
  void load_case_target_and_constraints()
  {
    case_ = load_case(args_.positional(1), args_.values("--set"));
    const std::string target_file = args_.value("--target");
    if (target_file.empty())
      throw cli::UsageError("design poles needs --target FILE (a profile CSV or a specification YAML)");
    const double tolerance = parse_quantity(args_.value("--tolerance", "1mT"), Dimension::magnetic_flux_density);
    ScanReadOptions scan;
    scan.angle_unit = args_.value("--angle-unit");
    scan.field_unit = args_.value("--field-unit");
    if (args_.has("--constraints"))
      read_design_constraints(args_.value("--constraints"), constraints_);
    target_ = read_design_target(target_file, tolerance, constraints_, scan);
    for (const auto &name : split_commas(args_.values("--fix")))
      constraints_.poles[name].fixed = true;
    if (args_.has("--max-strength"))
      constraints_.max_strength = parse_quantity(args_.value("--max-strength"), Dimension::magnetisation);
    if (args_.has("--angle-range"))
      constraints_.angle_range = parse_quantity(args_.value("--angle-range"), Dimension::angle);
    options_.starts = int(args_.whole_number("--starts", 8, 1, 1000));
    if (target_.release)
      target_.release_inputs = ReleaseInputs::from(case_);
    probe_radius_ = target_.probe_radius > 0 ? target_.probe_radius : probe_radius_of(case_);
    dir_ = args_.value("--output", case_.output.directory + "/design");
    fs::create_directories(dir_);
    say("magbrush design poles: case '" + case_.name + "', " + std::to_string(case_.roller->poles.size()) +
        " poles, target " + target_file + " (" +
        (target_.profile ? std::to_string(target_.profile->angle.size()) + " profile samples" : std::string("specification")) +
        (target_.peaks.empty() ? "" : ", " + std::to_string(target_.peaks.size()) + " pole peaks") +
        (target_.ceilings.empty() ? "" : ", " + std::to_string(target_.ceilings.size()) + " low-field arcs") +
        (target_.min_spacing > 0 ? ", minimum spacing " + fixed(target_.min_spacing * to_deg, 1) + " deg" : "") +
        (target_.release ? ", a release arc" : "") +
        "), probe radius " + fixed(probe_radius_ * 1e3, 3) + " mm\n");
  }

  // 3. The layout, the requirements, the verdict, the sensitivities.
  void report_design()
  {
    std::ostringstream s;
    s << "\nBounded least squares on the exact ring (" << design_.harmonics << " harmonics), "
      << design_.start_costs.size() << " starts: best from start " << design_.best_start << " ("
      << (design_.best_start == 0 ? "the case's layout" : "a random layout") << "), "
      << design_.starts_at_best << " of " << design_.start_costs.size() << " starts reached it; " << design_.status
      << "\n  cost (Σ squared residuals, each scaled by its tolerance) " << scientific(design_.cost) << "\n\n"
      << "Designed layout (signs and shape factors as the case's):\n"
      << layout_table(case_.roller->poles, design_) << "\n"
      << "Requirements, on the exact ring of the designed layout:\n"
      << requirements_table(design_.requirements);
    if (design_.feasible)
      s << "\nEvery requirement is met.\n";
    else
    {
      s << "\nINFEASIBLE: no layout within the constraints meets every requirement; the layout above "
           "is the nearest (least squares). What binds:\n";
      if (design_.binding.empty())
        s << "  no bound binds: the requirements contradict each other (or need a pole the case "
             "lacks); loosen a tolerance or add a pole\n";
      for (const auto &b : design_.binding)
        s << "  " << b << "\n";
    }
    if (design_.feasible && !design_.binding.empty())
    {
      s << "Constraints at their limit:\n";
      for (const auto &b : design_.binding)
        s << "  " << b << "\n";
    }
    const RingProfile ring(*case_.roller, probe_radius_);
    const RequirementSet set(target_, *case_.roller);
    const SensitivityTable t = sensitivities(set, ring, design_.poles);
    s << "\nSensitivity: change of each requirement's value per +1 deg of a pole's angle (1 deg = "
      << fixed(case_.roller->magnet_radius * 1e3 * M_PI / 180.0, 3)
      << " mm on the magnet's surface) or per +10 kA/m of its |M| (stronger):\n"
      << format_sensitivities(t);
    write_text_atomically(dir_ + "/design_sensitivity.csv", sensitivities_csv(t));
    sensitivity_ = t;
    say(s.str());
  }

  // 4. <case>_designed.yaml: the case with the designed poles (checked by loading it back).
  void write_designed_case()
  {
    const std::string stem = fs::path(case_.source_file).stem().string();
    designed_case_ = dir_ + "/" + stem + "_designed.yaml";
    YAML::Node root = YAML::LoadFile(case_.source_file);
    for (const auto &ov : args_.values("--set"))
      apply_override(root, ov);
    root["name"] = case_.name + "_designed";
    root["roller"]["poles"] = poles_yaml(design_.poles);
    if (target_.probe_radius > 0)
      root["field"]["probe_radius"] = fixed(probe_radius_ * 1e3, 6) + " mm";
    std::ostringstream out;
    std::time_t now = std::time(nullptr);
    char stamp[64];
    std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    out << "# " << case_.name << "_designed: case '" << case_.name << "' (" << case_.source_file
        << ") with the poles designed by\n#   magbrush design poles for the target " << args_.value("--target") << " ("
        << stamp << "): " << (design_.feasible ? "every requirement met" : "INFEASIBLE, the nearest layout") << ".\n"
        << "# Comments of the original file are not carried over.\n";
    YAML::Emitter emitter;
    emitter << root;
    out << emitter.c_str() << "\n";
    write_text_atomically(designed_case_, out.str());
    load_case(designed_case_); // throws if the written case does not load
    say("\n  designed case " + designed_case_ + "\n");
  }

  // The target's band for the plot: a profile target's samples ± tolerance, a specification's
  // boxes (peak angle ± tolerance × peak ± tolerance) and ceilings.
  void write_tables()
  {
    std::ostringstream bands;
    bands << "kind,from_deg,to_deg,low_mT,high_mT,label\n";
    for (const auto &p : target_.peaks)
    {
      const auto it = std::find_if(design_.poles.begin(), design_.poles.end(), [&](const Pole &q) { return q.name == p.pole; });
      const double s = it->strength >= 0 ? 1.0 : -1.0;
      const double a = p.angle ? wrap_0_2pi(*p.angle) * to_deg : it->angle * to_deg;
      const double da = p.angle ? p.angle_tolerance * to_deg : 10.0;
      const double lo = p.peak ? (*p.peak - p.peak_tolerance) * 1e3 : 0.0, hi = p.peak ? (*p.peak + p.peak_tolerance) * 1e3 : 0.0;
      bands << "Bn_peak," << a - da << "," << a + da << "," << (s > 0 ? lo : -hi) << "," << (s > 0 ? hi : -lo) << ","
            << p.pole << (p.peak ? "" : " angle") << "\n";
    }
    for (const auto &c : target_.ceilings)
    {
      double from = wrap_0_2pi(c.from) * to_deg, to = from + wrap_0_2pi(c.to - c.from) * to_deg;
      bands << "B_ceiling," << from << "," << to << "," << 0.0 << "," << (c.level + c.tolerance) * 1e3 << ",|B| below\n";
    }
    if (target_.release)
    {
      const double from = wrap_0_2pi(target_.release->from) * to_deg,
                   to = from + wrap_0_2pi(target_.release->to - target_.release->from) * to_deg;
      bands << "release," << from << "," << to << ",0,0,released (a_net >= " << target_.release->margin << " g)\n";
    }
    if (target_.profile)
    {
      const auto &t = *target_.profile;
      std::ostringstream prof;
      prof << "angle_deg,Bn_target_mT,Bt_target_mT,tolerance_mT,weight\n";
      for (size_t k = 0; k < t.angle.size(); ++k)
        prof << t.angle[k] * to_deg << "," << t.Bn[k] * 1e3 << "," << (t.Bt.empty() ? NAN : t.Bt[k] * 1e3) << ","
             << t.tolerance[k] * 1e3 << "," << t.weight[k] << "\n";
      write_text_atomically(dir_ + "/design_target_profile.csv", prof.str());
    }
    write_text_atomically(dir_ + "/design_bands.csv", bands.str());
  }

  // 5. The FEM check.
  void check_by_fem()
  {
    if (args_.has("--no-fem-check"))
    {
      say("\nFEM check skipped (--no-fem-check)\n");
      fem_note_ = "FEM check skipped (--no-fem-check).";
      write_text_atomically(dir_ + "/design_requirements.csv", requirements_csv(design_.requirements, nullptr));
      return;
    }
    say("\nFEM check: magbrush-field on " + designed_case_ + " ...\n");
    const std::vector<std::string> fields_here = {"field.output_dir=" + dir_ + "/fem_check_fields"};
    const std::string failure = run_magnetic_field_solver(designed_case_, dir_ + "/design_fem_check.log", fields_here);
    std::string why;
    if (failure.empty())
    {
      const Case designed = load_case(designed_case_, fields_here);
      fem_path_ = fem_profile_path(designed, probe_radius_, why);
    }
    if (!failure.empty() || fem_path_.empty())
    {
      say("FEM check not done: " + (failure.empty() ? why : failure) + "\n");
      fem_note_ = "FEM check not done: " + (failure.empty() ? why : failure);
      write_text_atomically(dir_ + "/design_requirements.csv", requirements_csv(design_.requirements, nullptr));
      return;
    }
    const RequirementSet set(target_, *case_.roller);
    fem_requirements_ = set.evaluate(design_.poles, profile_from_file(fem_path_));
    bool all_met = true;
    for (const auto &r : fem_requirements_)
      all_met &= r.met();
    // The FEM against the exact ring of the same layout: the discretisation error.
    std::vector<double> grid, Bn, Bt, Fn, Ft;
    for (int k = 0; k < 1440; ++k)
      grid.push_back(k * 0.25 / to_deg);
    Roller designed_roller = *case_.roller;
    designed_roller.poles = design_.poles;
    MultipoleRing(designed_roller).profile(probe_radius_, grid, Bn, Bt);
    profile_from_file(fem_path_)(grid, Fn, Ft);
    double diff = 0, peak = 0;
    for (size_t k = 0; k < grid.size(); ++k)
    {
      diff = std::max(diff, std::hypot(Fn[k] - Bn[k], Ft[k] - Bt[k]));
      peak = std::max(peak, std::hypot(Bn[k], Bt[k]));
    }
    fem_note_ = "The FEM (" + fem_path_ + ") against the exact ring of the designed layout: max |ΔB| = " +
                fixed(diff * 1e3, 3) + " mT (" + scientific(diff / peak) + " of the peak |B|); " +
                (all_met ? "it meets every requirement." : "it misses a requirement.");
    say("Requirements on the finite-element profile (" + fem_path_ + "):\n" + requirements_table(fem_requirements_) +
        (all_met ? "The FEM of the designed layout meets every requirement.\n"
                 : "The FEM of the designed layout misses a requirement (above).\n") +
        "  FEM against the exact ring of the designed layout: max |ΔB| = " + fixed(diff * 1e3, 3) + " mT (" +
        scientific(diff / peak) + " of the peak |B|)\n");
    write_text_atomically(dir_ + "/design_requirements.csv", requirements_csv(design_.requirements, &fem_requirements_));
  }

  void write_profile_csv()
  {
    std::vector<double> grid, Bn, Bt, Fn, Ft;
    for (int k = 0; k < 1440; ++k)
      grid.push_back(k * 0.25 / to_deg);
    Roller designed_roller = *case_.roller;
    designed_roller.poles = design_.poles;
    MultipoleRing(designed_roller).profile(probe_radius_, grid, Bn, Bt);
    std::vector<double> Cn, Ct;
    MultipoleRing(*case_.roller).profile(probe_radius_, grid, Cn, Ct);
    if (!fem_path_.empty())
      profile_from_file(fem_path_)(grid, Fn, Ft);
    std::ostringstream out;
    out << "# Designed sleeve profile of case '" << case_.name << "' at radius " << probe_radius_ * 1e3
        << " mm: exact ring of the designed layout, of the case's layout, and the FEM of the designed case\n"
        << "angle_deg,Bn_mT,Bt_mT,B_mT,Bn_case_mT,Bt_case_mT,Bn_fem_mT,Bt_fem_mT\n";
    char buf[256];
    for (size_t k = 0; k < grid.size(); ++k)
    {
      std::snprintf(buf, sizeof buf, "%.2f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f\n", grid[k] * to_deg, Bn[k] * 1e3,
                    Bt[k] * 1e3, std::hypot(Bn[k], Bt[k]) * 1e3, Cn[k] * 1e3, Ct[k] * 1e3,
                    Fn.empty() ? NAN : Fn[k] * 1e3, Ft.empty() ? NAN : Ft[k] * 1e3);
      out << buf;
    }
    write_text_atomically(dir_ + "/design_profile.csv", out.str());
  }

  void write_page(const std::string &time)
  {
    DesignPage page;
    page.case_name = case_.name;
    page.target = args_.value("--target");
    page.verdict = design_.feasible ? "Every requirement is met on the exact ring."
                                    : "INFEASIBLE: no layout within the constraints meets every requirement; the "
                                      "layout below is the nearest (least squares).";
    page.method = "Bounded least squares on the exact ring from " + std::to_string(design_.start_costs.size()) +
                  " starts (" + std::to_string(design_.starts_at_best) + " reached the best); " + design_.status + ".";
    page.time = time.substr(0, time.find_last_not_of('\n') + 1);
    if (!args_.has("--no-plot") && fs::exists(dir_ + "/design_profile.png"))
      page.image = "design_profile.png";
    for (size_t i = 0; i < design_.poles.size(); ++i)
    {
      bool angle_free = false, strength_free = false;
      for (const auto &q : design_.parameters)
        if (q.pole == i)
          (q.angle ? angle_free : strength_free) = true;
      const Pole &from = case_.roller->poles[i], &to = design_.poles[i];
      page.layout.push_back({to.name, fixed(wrap_0_2pi(from.angle) * to_deg, 3), fixed(to.angle * to_deg, 3),
                             fixed(std::abs(from.strength) * 1e-3, 2), fixed(std::abs(to.strength) * 1e-3, 2),
                             std::string(angle_free ? "angle free" : "angle fixed") +
                                 (strength_free ? ", |M| free" : ", |M| fixed")});
    }
    page.ring = design_.requirements;
    page.fem = fem_requirements_;
    page.fem_note = fem_note_;
    page.binding = design_.binding;
    page.sensitivity = sensitivity_;
    for (const char *f : {"design_report.txt", "design_requirements.csv", "design_sensitivity.csv", "design_profile.csv",
                          "design_bands.csv", "design_target_profile.csv", "design_fem_check.log"})
      if (fs::exists(dir_ + "/" + f))
        page.files.push_back(f);
    page.files.push_back(fs::path(designed_case_).filename().string());
    write_design_page(dir_, page);
  }

  void plot()
  {
    if (args_.has("--no-plot"))
      return;
    const std::string png = dir_ + "/design_profile.png";
    std::vector<std::string> a = {"--profile", dir_ + "/design_profile.csv", "--bands", dir_ + "/design_bands.csv",
                                  "--title", "Case '" + case_.name + "': designed poles against " + args_.value("--target") +
                                                 (design_.feasible ? "" : " (INFEASIBLE: nearest layout)"),
                                  "-o", png};
    if (target_.profile)
      a.insert(a.end(), {"--target", dir_ + "/design_target_profile.csv"});
    run_plot_script("plot_design.py", a, png);
  }
};

} // namespace

int run_design_poles(const cli::ParsedArguments &args)
{
  return DesignPolesCommand(args).run();
}

} // namespace magbrush
