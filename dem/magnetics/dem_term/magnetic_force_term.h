// The DEM force term of the induced-dipole magnetics: plugs InducedDipoles into the engine's
// ForceTerm interface (dem/force_term.h).
//
// Only carrier beads (populations of kind carrier) take part; each gets μr and M_s from its
// population's material. Per step, the term gathers the carriers' positions into compact
// arrays, and either re-evaluates the magnetics (needs_refresh: refresh interval elapsed or a
// bead moved more than the staleness fraction of its radius) or adds the held forces of the
// last evaluation — Kawamoto's "magnetics every 5 µs while stepping at 20 ns".
#pragma once

#include "force_term.h"
#include "induced_dipoles.h"

#include "applied_magnetic_field.h"
#include "case_model.h"

#include <array>
#include <cstdint>
#include <vector>

namespace magbrush::magnetics {

class MagneticForceTerm : public dem::ForceTerm
{
public:
  // `box` = the DEM's periodic lengths (0 = open); `settings` usually
  // MagneticSettings::from_case(c.dem). In a slab periodic along exactly two axes the slab
  // tail correction is switched on unless `slab_tail` is false (docs/magnetics.md: a hard
  // cutoff leaves ~30 % force errors at 8 diameters there).
  MagneticForceTerm(const Case &c, MagneticSettings settings, const AppliedMagneticField &field,
                    const std::array<double, 3> &box, bool slab_tail = true);

  const char *name() const override { return "magnetic dipoles"; }
  void add_forces(const dem::ParticleState &state, dem::ForceBuffers &forces, double t) override;
  void particles_reordered(const std::vector<std::int32_t> &order) override;

  const MagneticStats &last_stats() const { return stats_; }
  // A disabled term adds nothing (benchmarks compare settings in one system).
  void set_enabled(bool enabled) { enabled_ = enabled; }
  long evaluations() const { return evaluations_; }
  const InducedDipoles &dipoles() const { return dipoles_; }

private:
  // Per population: is it a carrier, and its material's μr and M_s (copied from the case).
  struct Species
  {
    bool carrier = false;
    double mu_r = 1.0, saturation_magnetisation = 0.0;
  };
  std::vector<Species> species_;
  std::size_t state_size_ = 0;
  InducedDipoles dipoles_;
  AppliedMagneticField field_;
  MagneticStats stats_;
  long evaluations_ = 0;

  // Compact carrier arrays; carrier_[k] = full index of compact bead k.
  std::vector<std::uint32_t> carrier_;
  std::vector<double> x_, y_, z_, radius_, mu_r_, Ms_, fx_, fy_, fz_, tx_, ty_, tz_;
  bool must_refresh_ = true;
  bool enabled_ = true;

  void select_carriers(const dem::ParticleState &state);
};

} // namespace magbrush::magnetics
