// What a pole design aims at, and what it may change.
//
// A target is either a sleeve profile — the scan format of `magbrush flux` (angle, Bn[, Bt]),
// with optional per-sample columns `weight` (≥ 0, default 1) and `tolerance` (field units,
// default the --tolerance option) — or a specification in YAML:
//
//   probe_radius: 10 mm             # where the requirements hold (default: the case's probe)
//   poles:                          # per named pole: its Bn extremum near its angle
//     S1: {peak: 95 mT, peak_tolerance: 3 mT, angle: 0 deg, angle_tolerance: 1 deg}
//     N2: {angle: 288 deg, angle_tolerance: 2 deg}     # e.g. a pole under the blade
//   field_below:                    # arcs (counter-clockwise from → to) where |B| ≤ level
//     - {from: 165 deg, to: 195 deg, level: 20 mT, tolerance: 1 mT}   # e.g. the release
//   min_spacing: 40 deg             # between neighbouring poles' angles
//   release: {from: 180 deg, to: 200 deg, margin: 0.5}   # a carrier bead is let go somewhere
//                                   # on the arc: the field criterion for release
//                                   # (release_criterion.h) reaches +margin g there
//   profile: scan.csv               # optional: a profile target as well (relative to this file)
//   constraints: ...                # see DesignConstraints (also accepted alone via --constraints)
//
// The constraints bound the layout:
//
//   constraints:
//     max_strength: 400 kA/m        # the magnet's remanence limit, |M| of every pole
//     angle_range: 30 deg           # default bound: each pole within ± this of the case's angle
//     strength_range: [0.1, 2.5]    # default bound: |M| within these multiples of the case's
//     poles:
//       S1: {fixed: true}           # may not move or change
//       S2: {angle: [150 deg, 175 deg], strength: [150 kA/m, 300 kA/m]}
//
// A pole keeps its sign (N or S); shape factors stay the case's (the magnet maker's profile).
#pragma once

#include "calibration/flux_scan.h"
#include "case/case_model.h"
#include "design/release_criterion.h"

#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace magbrush {

struct ProfileTarget
{
  std::string source;
  std::vector<double> angle;     // roller frame [rad]
  std::vector<double> Bn, Bt;    // [T]; Bt empty: Bn only
  std::vector<double> weight;    // per sample, ≥ 0
  std::vector<double> tolerance; // per sample [T], > 0
};

// The Bn extremum of a pole (the extremum of its sign in its sector): its size and/or angle.
struct PeakRequirement
{
  std::string pole;
  std::optional<double> peak;    // |Bn| [T]
  double peak_tolerance = 2e-3;  // [T]
  std::optional<double> angle;   // [rad]
  double angle_tolerance = 1.0 * M_PI / 180.0; // [rad]
};

// |B| = √(Bn² + Bt²) stays at or below `level` over the arc from → to (counter-clockwise).
struct FieldCeiling
{
  double from = 0.0, to = 0.0; // [rad]
  double level = 0.0;          // [T]
  double tolerance = 0.0;      // [T], slack allowed when judging
};

// Somewhere on the arc from → to the net outward acceleration of a carrier bead at the sleeve
// (release_criterion.h) reaches `margin` × g: the layer is let go there.
struct ReleaseRequirement
{
  double from = 0.0, to = 0.0; // [rad]
  double margin = 0.0;         // [g]
};

struct DesignTarget
{
  std::string source;
  double probe_radius = 0.0; // [m]; 0 = the case's probe radius
  std::optional<ProfileTarget> profile;
  std::vector<PeakRequirement> peaks;
  std::vector<FieldCeiling> ceilings;
  double min_spacing = 0.0;  // [rad]; 0 = none
  std::optional<ReleaseRequirement> release;
  std::optional<ReleaseInputs> release_inputs; // the bead, sleeve and gravity (from the case)
  bool empty() const
  {
    return !profile && peaks.empty() && ceilings.empty() && min_spacing <= 0.0 && !release;
  }
};

// A pole's box: angle in [low, high] (unwrapped around its start), |M| in [low, high].
struct PoleLimits
{
  double angle_low = 0, angle_high = 0;       // [rad]
  double strength_low = 0, strength_high = 0; // |M| [A/m]
  bool fixed = false;
};

struct DesignConstraints
{
  double max_strength = std::numeric_limits<double>::infinity(); // |M| ≤ [A/m]
  double angle_range = 30.0 * M_PI / 180.0;                      // default ± [rad]
  double strength_factor_low = 0.1, strength_factor_high = 2.5;  // default |M| multiples
  struct PerPole
  {
    bool fixed = false;
    std::optional<std::pair<double, double>> angle;    // [rad]
    std::optional<std::pair<double, double>> strength; // |M| [A/m]
  };
  std::map<std::string, PerPole> poles;

  // The box of every pole of the case's layout; throws for a named pole the case lacks or a
  // box that excludes nothing sensible (low > high).
  std::vector<PoleLimits> limits_for(const std::vector<Pole> &poles) const;
};

// The profile target from a scan-format CSV (weights and tolerances read by column name).
ProfileTarget read_profile_target(const std::string &path, double default_tolerance,
                                  const ScanReadOptions &options = {});

// The specification (and the constraints it carries) from YAML; throws naming the bad key.
DesignTarget read_design_spec(const std::string &path, double default_tolerance,
                              DesignConstraints &constraints);

// Only the `constraints:` section of a YAML file (keys as above), added to `constraints`.
void read_design_constraints(const std::string &path, DesignConstraints &constraints);

// A target file of either kind: YAML (.yaml/.yml) is a specification, anything else a profile.
DesignTarget read_design_target(const std::string &path, double default_tolerance,
                                DesignConstraints &constraints, const ScanReadOptions &options = {});

} // namespace magbrush
