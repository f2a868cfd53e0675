// The requirements of a design target, judged on a profile: each one's achieved value, met or
// missed and by how much, and its residuals for the least squares (scaled by the tolerance, so
// that a residual of 1 is a requirement just at the edge of its tolerance).
//
//   profile arcs     one per pole sector of the case's layout (the angles nearer that pole than
//                    any other): the largest |ΔBn| or |ΔBt| against the target over the sector,
//                    judged against each sample's tolerance; residuals √w ΔB / tolerance
//   pole peaks       the Bn extremum of the pole's sign within its current sector, located on a
//                    1° grid and refined by successive parabolas to 1e-9 rad, so that its size
//                    and angle are smooth functions of the layout; residual (value − target)/tol
//   field below      |B| at 0.5° steps over the arc; residual (|B| − level)₊ / scale per sample
//                    (scale: the tolerance, or 5 % of the level; a one-sided requirement aims
//                    2 % of its scale inside its limit, so that the optimum lands inside)
//   minimum spacing  per neighbouring pair, (spacing − gap)₊ / 0.5°
//   release          the largest net outward acceleration of a carrier bead on the arc
//                    (release_criterion.h), always on the exact ring (it needs ∂B²/∂r, which a
//                    probe profile does not give); residual (margin − largest)₊ / 0.1 g
#pragma once

#include "design/design_target.h"
#include "design/ring_profile.h"

#include <string>
#include <vector>

namespace magbrush {

struct RequirementResult
{
  enum class Kind { equal, at_most, at_least };
  std::string name;    // "S1 peak |Bn|", "|B| below 20 mT over 165–195°", ...
  std::string unit;    // display unit of target, tolerance, value, miss: "mT" or "deg"
  Kind kind = Kind::equal;
  double target = 0, tolerance = 0, value = 0;
  double miss = 0;     // how far beyond its tolerance (≤ 0: met)
  std::string detail;  // where, over how many samples
  std::vector<double> residuals;
  bool met() const { return miss <= 1e-9; }
  // A scalar requirement (peak, ceiling, spacing, arc) is one row of the sensitivity table.
};

class RequirementSet
{
public:
  // The case's roller: its poles fix the profile target's arcs (the case's pole sectors), its
  // geometry and shapes the ring on which the release requirement is judged.
  RequirementSet(const DesignTarget &target, const Roller &roller);
  std::vector<RequirementResult> evaluate(const std::vector<Pole> &poles,
                                          const ProfileFunction &profile) const;
  // All residuals of evaluate() stacked, in a fixed order and count for a given target.
  static std::vector<double> stacked_residuals(const std::vector<RequirementResult> &results);

private:
  DesignTarget target_;
  std::vector<Pole> nominal_;
  std::vector<std::vector<size_t>> arc_samples_; // profile samples per nominal sector
  std::vector<double> ceiling_angles_;           // all arcs' sample angles, concatenated
  std::vector<size_t> ceiling_start_;
  std::vector<double> release_angles_;
  std::vector<RingProfile> release_rings_; // at the bead's centre − h, + h

  void release(const std::vector<Pole> &poles, std::vector<RequirementResult> &out) const;
  void profile_arcs(const ProfileFunction &profile, std::vector<RequirementResult> &out) const;
  void pole_peaks(const std::vector<Pole> &poles, const ProfileFunction &profile,
                  std::vector<RequirementResult> &out) const;
  void field_below(const ProfileFunction &profile, std::vector<RequirementResult> &out) const;
  void spacing(const std::vector<Pole> &poles, std::vector<RequirementResult> &out) const;
};

// The angle in (−π, π] and in [0, 2π).
double wrap_pm_pi(double a);
double wrap_0_2pi(double a);

} // namespace magbrush
