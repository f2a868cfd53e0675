// The DEM adapter: two carriers (and one toner) in the engine, in a uniform field, receive the
// mutual-dipole pair force; the toner receives nothing; held forces are reused between
// refreshes and follow the engine's particle re-sorting; an engine wrap and re-sort are no
// move; the ramp (held forces ∝ s²) and the local refresh through the engine; the
// staleness-mode key.
#include "dem/force_terms/magnetic_force_term.h"
#include "magnetics/two_sphere_exact.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_parser.h"
#include "dem/dem_system.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace magbrush;
using namespace magbrush::magnetics;

namespace {
const char *scene = R"(
name: magnetic_pair
scene: box
materials:
  carrier: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 2200 kg/m^3, mu_r: 3.9, friction: 0.45, damping: 0.6}
  toner: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 1000 kg/m^3, friction: 0.45, damping: 0.6}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, damping: 0.6}
populations:
  - {name: carrier, kind: carrier, material: carrier, diameter: 60 um, count: 2, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 1 mm]]}
  - {name: toner, kind: toner, material: toner, diameter: 8 um, count: 1, charge_to_mass: -30 uC/g, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 1 mm]]}
planes:
  - {name: stage, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
applied_field: {kind: uniform, direction: [0, 0, 1], magnitude: 130 mT}
dem: {time_step: 1e-9 s, magnetic_model: mutual_dipole, magnetic_cutoff: 8, magnetic_refresh: 5 us, gravity: [0, 0, 0]}
)";
} // namespace

TEST(MagneticForceTerm, PairForceThroughTheEngine)
{
  Case c = parse_case_text(scene, "magnetic_pair.yaml");
  dem::DemSystem system(c);
  auto &p = system.particles();
  const double a = 30e-6, D = 2.5;
  p.add({0.5e-3, 0.5e-3, 0.4e-3}, a, 2200.0, 0, 0.0);
  p.add({0.5e-3, 0.5e-3, 0.4e-3 + D * a}, a, 2200.0, 0, 0.0);
  p.add({0.2e-3, 0.2e-3, 0.2e-3}, 4e-6, 1000.0, 1, 0.0);
  system.initialize();
  MagneticSettings s = MagneticSettings::from_case(c.dem);
  s.tolerance = 1e-12;
  auto owned = std::make_unique<MagneticForceTerm>(
    c, s, AppliedMagneticField::uniform({0, 0, 1}, 0.13), system.box().length);
  MagneticForceTerm *term = owned.get();
  dem::ForceBuffers f;
  f.resize(3);
  f.clear();
  term->add_forces(p, f, 0.0);
  const TwoSphereForce md = mutual_dipole_pair_force(a, (3.9 - 1) / (3.9 + 2), D * a);
  const double H = 0.13 / mu0;
  const double expected = mu0 * H * H * md.parallel; // on the upper bead, along +z
  // The engine re-sorts particles (cell order): find them by population and height.
  auto find = [&](bool upper_carrier, bool toner) {
    std::size_t best = 99;
    for (std::size_t k = 0; k < p.size(); ++k)
    {
      if ((p.species[k] == 1) != toner)
        continue;
      if (best == 99 || toner || (upper_carrier ? p.z[k] > p.z[best] : p.z[k] < p.z[best]))
        best = k;
    }
    return best;
  };
  const std::size_t upper = find(true, false), lower = find(false, false), toner = find(false, true);
  EXPECT_NEAR(f.fz[upper], expected, 1e-9 * std::abs(expected));
  EXPECT_NEAR(f.fz[lower], -expected, 1e-9 * std::abs(expected));
  EXPECT_EQ(f.fx[toner], 0.0);
  EXPECT_EQ(f.fz[toner], 0.0);
  EXPECT_EQ(term->evaluations(), 1);
  // Within the refresh interval, with no motion, the held forces are reused.
  f.clear();
  term->add_forces(p, f, 1e-6);
  EXPECT_EQ(term->evaluations(), 1);
  EXPECT_NEAR(f.fz[upper], expected, 1e-9 * std::abs(expected));
  // A re-sort (reverse the order) is no reason to re-evaluate: the held forces follow the beads.
  const std::vector<std::int32_t> order = {2, 1, 0};
  std::vector<double> scratch;
  std::vector<std::int32_t> iscratch;
  p.permute(order, scratch, iscratch);
  term->particles_reordered(order);
  f.clear();
  term->add_forces(p, f, 2e-6);
  EXPECT_EQ(term->evaluations(), 1);
  const std::size_t upper2 = find(true, false);
  EXPECT_EQ(upper2, 2 - upper);
  EXPECT_NEAR(f.fz[upper2], expected, 1e-9 * std::abs(expected));
  system.add_force_term(std::move(owned));
}

// The case key of the staleness mode: its default is the contract struct's, and every mode
// name parses (a bad one names the key).
TEST(MagneticForceTerm, StalenessModeKey)
{
  Case c = parse_case_text(scene, "magnetic_pair.yaml");
  EXPECT_EQ(c.dem.magnetic_staleness_mode, DemSettings{}.magnetic_staleness_mode);
  EXPECT_EQ(MagneticSettings::from_case(c.dem).staleness_mode, StalenessMode::relative);
  for (const char *mode : {"relative", "local", "absolute"})
    EXPECT_EQ(to_string(parse_staleness_mode(mode)), mode);
  EXPECT_THROW(parse_staleness_mode("sometimes"), std::invalid_argument);
}

// dem.magnetic_hold: the default holds forces; "dipoles" sets MagneticSettings::hold_dipoles;
// anything else is refused with the key's name.
TEST(MagneticForceTerm, HoldKey)
{
  Case c = parse_case_text(scene, "magnetic_pair.yaml");
  EXPECT_EQ(c.dem.magnetic_hold, DemSettings{}.magnetic_hold);
  EXPECT_FALSE(MagneticSettings::from_case(c.dem).hold_dipoles);
  c.dem.magnetic_hold = "dipoles";
  EXPECT_TRUE(MagneticSettings::from_case(c.dem).hold_dipoles);
  c.dem.magnetic_hold = "fields";
  EXPECT_THROW(MagneticSettings::from_case(c.dem), std::invalid_argument);
}

// dem.magnetic_skin (0: the contact list's dem.verlet_skin) and dem.magnetic_live_steps reach
// the magnetics, and the skin is the lists': a bead moved by a quarter diameter expires them
// under the default skin (0.3 diameters: rebuilt at 0.15) but not under a skin of one diameter.
TEST(MagneticForceTerm, SkinAndLiveStepsKeys)
{
  Case c = parse_case_text(scene, "magnetic_pair.yaml");
  EXPECT_EQ(c.dem.magnetic_skin, DemSettings{}.magnetic_skin);
  EXPECT_EQ(MagneticSettings::from_case(c.dem).skin_fraction, c.dem.verlet_skin);
  EXPECT_EQ(MagneticSettings::from_case(c.dem).live_pair_steps, 20);
  long rebuilds[2] = {0, 0};
  for (const int k : {0, 1})
  {
    std::string text = scene;
    if (k)
      text.replace(text.find("gravity: [0, 0, 0]}"), 19, "gravity: [0, 0, 0], magnetic_skin: 1, magnetic_live_steps: 40}");
    Case ck = parse_case_text(text, "magnetic_pair.yaml");
    if (k)
    {
      EXPECT_EQ(MagneticSettings::from_case(ck.dem).skin_fraction, 1.0);
      EXPECT_EQ(MagneticSettings::from_case(ck.dem).live_pair_steps, 40);
    }
    dem::DemSystem system(ck);
    auto &p = system.particles();
    const double a = 30e-6;
    p.add({0.5e-3, 0.5e-3, 0.4e-3}, a, 2200.0, 0, 0.0);
    p.add({0.5e-3, 0.5e-3, 0.4e-3 + 2.5 * a}, a, 2200.0, 0, 0.0);
    system.initialize();
    MagneticForceTerm term(ck, MagneticSettings::from_case(ck.dem), AppliedMagneticField::uniform({0, 0, 1}, 0.13),
                           system.box().length);
    dem::ForceBuffers f;
    f.resize(2);
    f.clear();
    term.add_forces(p, f, 0.0);
    p.x[0] += 0.5 * a; // a quarter diameter
    f.clear();
    term.add_forces(p, f, 6e-6); // past the 5 us interval: a full evaluation
    EXPECT_EQ(term.evaluations(), 2);
    rebuilds[k] = term.refresh_counts().rebuilds;
  }
  EXPECT_EQ(rebuilds[0], 2); // the first build, and the expired lists
  EXPECT_EQ(rebuilds[1], 1); // the first build only
}

// Holding the dipoles through the engine: a pair of carriers in a uniform field, the upper one
// pulled by 4 % of a radius, below the staleness limit (no refresh). Holding the forces keeps
// the force at the old separation; holding the dipoles evaluates the pair's force at the new
// separation from the held dipoles, much closer to the exact mutual-dipole force there, with
// Newton's third law exact.
TEST(MagneticForceTerm, HeldDipolesFollowAPulledBead)
{
  const double a = 30e-6, D = 2.3, pull = 0.04;
  const double beta = (3.9 - 1) / (3.9 + 2);
  const double H = 0.13 / mu0;
  const double exact = mu0 * H * H * mutual_dipole_pair_force(a, beta, (D + pull) * a).parallel;
  double error[2] = {0.0, 0.0};
  for (const bool dipoles : {false, true})
  {
    Case c = parse_case_text(scene, "magnetic_pair.yaml");
    dem::DemSystem system(c);
    auto &p = system.particles();
    p.add({0.5e-3, 0.5e-3, 0.4e-3}, a, 2200.0, 0, 0.0);
    p.add({0.5e-3, 0.5e-3, 0.4e-3 + D * a}, a, 2200.0, 0, 0.0);
    system.initialize();
    MagneticSettings s = MagneticSettings::from_case(c.dem);
    s.tolerance = 1e-13;
    s.model = DipoleModel::mutual_dipole; // (the exact reference is the mutual-dipole force)
    s.staleness_fraction = 0.5;
    s.hold_dipoles = dipoles;
    s.live_pair_steps = 1;
    MagneticForceTerm term(c, s, AppliedMagneticField::uniform({0, 0, 1}, 0.13), system.box().length);
    const std::size_t upper = p.z[0] > p.z[1] ? 0 : 1;
    dem::ForceBuffers f;
    f.resize(2);
    f.clear();
    term.add_forces(p, f, 0.0);
    p.z[upper] += pull * a;
    f.clear();
    term.add_forces(p, f, 1e-7);
    EXPECT_EQ(term.evaluations(), 1);
    EXPECT_EQ(term.local_refreshes(), 0);
    EXPECT_EQ(f.fz[1 - upper], -f.fz[upper]);
    error[dipoles] = std::abs(f.fz[upper] - exact) / std::abs(exact);
    std::vector<double> fx, fy, fz;
    term.last_forces(fx, fy, fz);
    EXPECT_EQ(fz[upper], f.fz[upper]);
  }
  std::printf("pair at %.2f radii pulled by %.2f: held forces %.2e, held dipoles %.2e (relative error)\n", D, pull,
              error[0], error[1]);
  EXPECT_GT(error[0], 0.02);
  EXPECT_LT(error[1], error[0] / 3.0);
}

// Through the engine, a pair of carriers in a ramped uniform field: nothing is solved while
// the field is zero, the field coming on is evaluated at once, the held forces follow the ramp
// exactly (F ∝ B²), and a carrier pulled along the axis gets a local refresh (no full one)
// that gives the exact mutual-dipole force at the new separation.
TEST(MagneticForceTerm, RampAndLocalRefreshThroughTheEngine)
{
  Case c = parse_case_text(scene, "magnetic_pair.yaml");
  dem::DemSystem system(c);
  auto &p = system.particles();
  const double a = 30e-6, D = 2.5, ramp = 1e-5;
  p.add({0.5e-3, 0.5e-3, 0.4e-3}, a, 2200.0, 0, 0.0);
  p.add({0.5e-3, 0.5e-3, 0.4e-3 + D * a}, a, 2200.0, 0, 0.0);
  system.initialize();
  MagneticSettings s = MagneticSettings::from_case(c.dem);
  s.tolerance = 1e-13;
  MagneticForceTerm term(c, s, AppliedMagneticField::uniform({0, 0, 1}, 0.13, ramp), system.box().length);
  const double beta = (3.9 - 1) / (3.9 + 2);
  auto expected = [&](double t, double separation) { // on the upper bead, along +z
    const double H = 0.13 * std::min(1.0, t / ramp) / mu0;
    return mu0 * H * H * mutual_dipole_pair_force(a, beta, separation).parallel;
  };
  const std::size_t upper = p.z[0] > p.z[1] ? 0 : 1;
  dem::ForceBuffers f;
  f.resize(2);
  auto step = [&](double t) {
    f.clear();
    term.add_forces(p, f, t);
  };
  step(0.0);
  EXPECT_EQ(term.refresh_counts().zero_field, 1);
  EXPECT_EQ(f.fz[upper], 0.0);
  step(1e-8); // the field came on
  EXPECT_EQ(term.evaluations(), 2);
  EXPECT_NEAR(f.fz[upper], expected(1e-8, D * a), 1e-9 * std::abs(expected(1e-8, D * a)));
  step(2e-6); // held, rescaled by (s(t)/s_held)²
  EXPECT_EQ(term.evaluations(), 2);
  EXPECT_NEAR(f.fz[upper], expected(2e-6, D * a), 1e-9 * std::abs(expected(2e-6, D * a)));
  p.z[upper] += 0.08 * a;
  step(3e-6); // pulled by 8 % of a radius: a local refresh
  EXPECT_EQ(term.evaluations(), 2);
  EXPECT_EQ(term.local_refreshes(), 1);
  EXPECT_NEAR(f.fz[upper], expected(3e-6, (D + 0.08) * a), 1e-9 * std::abs(expected(3e-6, (D + 0.08) * a)));
  EXPECT_EQ(f.fz[1 - upper], -f.fz[upper]);
  std::vector<double> fx, fy, fz;
  term.last_forces(fx, fy, fz);
  EXPECT_EQ(fz[upper], f.fz[upper]);
}

// The engine wraps beads into [0, L) along periodic axes at its list rebuilds and re-sorts its
// arrays: neither is a move for the magnetics (no refresh, the same forces, the lists kept).
TEST(MagneticForceTerm, EngineWrapAndResortAreNoMove)
{
  Case c = parse_case_text(scene, "magnetic_pair.yaml");
  dem::DemSystem system(c);
  auto &p = system.particles();
  const double a = 30e-6, L = 1e-3;
  p.add({0.99e-3, 0.5e-3, 0.4e-3}, a, 2200.0, 0, 0.0);
  p.add({0.99e-3, 0.5e-3, 0.4e-3 + 2.2 * a}, a, 2200.0, 0, 0.0);
  p.add({0.2e-3, 0.5e-3, 0.4e-3}, a, 2200.0, 0, 0.0);
  system.initialize();
  MagneticForceTerm term(c, MagneticSettings::from_case(c.dem), AppliedMagneticField::uniform({0, 0, 1}, 0.13),
                         {L, 0.0, 0.0});
  dem::ForceBuffers f;
  f.resize(3);
  f.clear();
  term.add_forces(p, f, 0.0);
  const std::vector<double> fz0(f.fz.begin(), f.fz.begin() + 3);
  // Wrap the two beads near x = L across the face (as the engine would: x − L)...
  for (std::size_t k = 0; k < 3; ++k)
    if (p.x[k] > 0.5 * L)
      p.x[k] -= L;
  // ... and re-sort the arrays.
  const std::vector<std::int32_t> order = {2, 0, 1};
  std::vector<double> scratch;
  std::vector<std::int32_t> iscratch;
  p.permute(order, scratch, iscratch);
  term.particles_reordered(order);
  f.clear();
  term.add_forces(p, f, 1e-6);
  EXPECT_EQ(term.evaluations(), 1);
  EXPECT_EQ(term.local_refreshes(), 0);
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_EQ(f.fz[k], fz0[static_cast<std::size_t>(order[k])]);
}
