// What `magbrush flux` and `magbrush design` share: the probe radius of a case, the computed
// sleeve profile (the finite-element one when `magbrush field` has written it for the case as
// it is now, else the exact multipole ring), running the field solver on a case file, running
// a plotting script under tools/, and editing a case's YAML with --set overrides.
#pragma once

#include "case/case_model.h"
#include "fields/multipole_ring.h"

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace magbrush {

// "%.*f" and "%.1e" as strings.
std::string fixed(double v, int digits);
std::string scientific(double v);

// field.probe_radius, 0 = the sleeve radius; throws when it lies inside the magnet.
double probe_radius_of(const Case &c);

// The FEM profile at this radius, if magbrush-field wrote one for the case as it is now
// (radius and stored-field hash checked); "" with the reason in `why_not` otherwise.
std::string fem_profile_path(const Case &c, double probe_radius, std::string &why_not);

struct ComputedProfile
{
  std::string source; // words
  std::vector<double> Bn, Bt;
};

// The profile at `angles`: interpolated from the FEM file when `fem_path` is given, else the
// exact ring at `probe_radius`.
ComputedProfile computed_at(const std::vector<double> &angles, const MultipoleRing &ring,
                            double probe_radius, const std::string &fem_path);

// magbrush-field CASE --only magnetic --no-vtu [--set OVERRIDE ...] with its output in `log`: ""
// when it ran, else what went wrong (including "not built"). A check of a written case passes
// `field.output_dir=<its folder>/...` so that the check's fields stay with it, not in the
// working directory's results/.
std::string run_magnetic_field_solver(const std::string &case_file, const std::string &log,
                                      const std::vector<std::string> &overrides = {});

// tools/<script> with the first python3 that has matplotlib ($MAGBRUSH_PYTHON, python3 on the
// PATH, /usr/bin/python3); prints "  plot  PNG" or a warning saying why there is none.
void run_plot_script(const std::string &script_name, const std::vector<std::string> &arguments,
                     const std::string &png);

// Apply one "a.b.c=value" override to a case's YAML tree (lists addressed by element name or
// [index]), so that a written case describes the case that was actually computed.
void apply_override(YAML::Node root, const std::string &override_text);

// The case's pole list as YAML (flow style: name, angle in deg, signed strength in kA/m,
// shape factor), angles in [0, 360) also after rounding.
YAML::Node poles_yaml(const std::vector<Pole> &poles);

} // namespace magbrush
