// Verification of the pole design (design/pole_design.h):
//  * a known layout recovered: the profile of a case's roller as the target, every pole of the
//    starting layout perturbed (±5°, ±20 %), the design recovers the original to the accuracy
//    of a fit on noise-free data — on two rollers (the development case's, and an irregular
//    six-pole roller with its own shape factors that no case or fit test uses), with the time;
//  * a specification (peaks, a low-field arc, spacing) met by the designed layout, judged by
//    an independent evaluation of the exact ring (MultipoleRing);
//  * a release requirement (cases/data/kweon_release_spec.yaml: S2 alone moved so that the
//    layer is let go between S2 and S3) met, judged by the release criterion's own profile
//    (release_criterion.h, an independent code path: B² by field_polar on a 0.05° grid);
//  * an infeasible specification reported as such, with the bound that binds;
#include "case/case_parser.h"
#include "fields/multipole_ring.h"
#include "design/pole_design.h"
#include "design/release_criterion.h"
#include "tests/cli_run.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

using namespace magbrush;

namespace {

constexpr double deg = M_PI / 180.0;

Roller case_roller(const std::string &name)
{
  return *load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/" + name).roller;
}

// The roller's own profile at 1° steps (Bn and Bt), 1 mT tolerance: the target.
DesignTarget profile_of(const Roller &roller, double r)
{
  ProfileTarget t;
  t.source = "the case's own profile";
  for (int k = 0; k < 360; ++k)
    t.angle.push_back(k * deg);
  MultipoleRing(roller).profile(r, t.angle, t.Bn, t.Bt);
  t.weight.assign(t.angle.size(), 1.0);
  t.tolerance.assign(t.angle.size(), 1e-3);
  DesignTarget target;
  target.profile = t;
  return target;
}

// Every pole moved by ±5° and made 20 % stronger or weaker, alternately.
Roller perturbed(Roller r)
{
  for (size_t i = 0; i < r.poles.size(); ++i)
  {
    r.poles[i].angle += (i % 2 ? -5.0 : 5.0) * deg;
    r.poles[i].strength *= (i % 3 == 1 ? 0.8 : 1.2);
  }
  return r;
}

void expect_recovered(const Roller &truth, const std::string &case_file, double r)
{
  const auto start = std::chrono::steady_clock::now();
  const DesignResult d = design_poles(perturbed(truth), r, profile_of(truth, r), DesignConstraints{});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  double worst_angle = 0, worst_strength = 0;
  for (size_t i = 0; i < truth.poles.size(); ++i)
  {
    worst_angle = std::max(worst_angle, std::abs(std::remainder(d.poles[i].angle - truth.poles[i].angle, 2 * M_PI)));
    worst_strength = std::max(worst_strength, std::abs(d.poles[i].strength / truth.poles[i].strength - 1));
  }
  std::printf("%s: recovered from ±5°, ±20 %%: largest angle error %.2e deg, strength error %.2e "
              "(relative), cost %.2e, %d of %zu starts at the best, %ld evaluations, %.2f s\n",
              case_file.c_str(), worst_angle / deg, worst_strength, d.cost, d.starts_at_best,
              d.start_costs.size(), d.evaluations, seconds);
  // A fit on noise-free data (test_pole_fit) recovers to ~1e-6; the faint pull towards the
  // start (λ = 1e-3) moves the optimum by ~1e-9°.
  EXPECT_LT(worst_angle / deg, 1e-4);
  EXPECT_LT(worst_strength, 1e-5);
  EXPECT_TRUE(d.feasible);
  for (const auto &req : d.requirements)
    EXPECT_LT(req.value, 1e-3) << req.name; // largest |ΔB| in mT per arc
}

TEST(PoleDesign, RecoversTheDevelopmentRollerFromItsProfile)
{
  expect_recovered(case_roller("kweon_development.yaml"), "kweon_development.yaml", 10e-3);
}

// A roller no case and no fit test has: six poles at irregular angles, one shape factor each,
// a 14 mm magnet on a soft-iron shaft, the probe 1.5 mm outside it.
TEST(PoleDesign, RecoversAnIrregularSixPoleRoller)
{
  Roller r;
  r.shaft_radius = 4e-3;
  r.shaft_mu_r = 800;
  r.magnet_radius = 14e-3;
  r.magnet_mu_r = 1.05;
  r.poles = {{"N1", 12 * deg, 260e3, 12},  {"S1", 65 * deg, -180e3, 8},
             {"N2", 128 * deg, 150e3, 10}, {"S2", 185 * deg, -210e3, 14},
             {"S3", 238 * deg, -160e3, 9}, {"N3", 300 * deg, 190e3, 11}};
  expect_recovered(r, "irregular six-pole roller", 15.5e-3);
}

// The peaks of a layout, by MultipoleRing directly: the largest |Bn| of the pole's sign
// within ±30° on a 0.01° grid (independent of the requirement code's parabola search).
std::pair<double, double> peak_near(const Roller &roller, double r, const std::string &pole)
{
  const Pole &p = *std::find_if(roller.poles.begin(), roller.poles.end(), [&](const Pole &q) { return q.name == pole; });
  std::vector<double> a, Bn, Bt;
  for (int k = -3000; k <= 3000; ++k)
    a.push_back(p.angle + k * 0.01 * deg);
  MultipoleRing(roller).profile(r, a, Bn, Bt);
  size_t best = 0;
  for (size_t k = 0; k < a.size(); ++k)
    if (std::copysign(1.0, p.strength) * Bn[k] > std::copysign(1.0, p.strength) * Bn[best])
      best = k;
  return {std::abs(Bn[best]), a[best]};
}

TEST(PoleDesign, MeetsASpecification)
{
  const Roller start = case_roller("kweon_development.yaml");
  const double r = 10e-3;
  DesignTarget spec;
  spec.peaks.push_back({"S1", 100e-3, 2e-3, 3 * deg, 0.5 * deg});
  spec.peaks.push_back({"N2", std::nullopt, 2e-3, 280 * deg, 1 * deg});
  spec.ceilings.push_back({170 * deg, 190 * deg, 25e-3, 0.0});
  spec.min_spacing = 50 * deg;
  const auto t0 = std::chrono::steady_clock::now();
  const DesignResult d = design_poles(start, r, spec, DesignConstraints{});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const auto &req : d.requirements)
    std::printf("  %-36s target %8.3f ± %.3f %s, value %8.3f (%s)\n", req.name.c_str(), req.target,
                req.tolerance, req.unit.c_str(), req.value, req.met() ? "met" : "MISSED");
  std::printf("specification designed in %.2f s (%ld evaluations)\n", seconds, d.evaluations);
  ASSERT_TRUE(d.feasible);
  Roller designed = start;
  designed.poles = d.poles;
  const auto [S1, S1_angle] = peak_near(designed, r, "S1");
  EXPECT_NEAR(S1, 100e-3, 2e-3);
  EXPECT_NEAR(std::remainder(S1_angle - 3 * deg, 2 * M_PI) / deg, 0.0, 0.5 + 0.01);
  const auto [N2, N2_angle] = peak_near(designed, r, "N2");
  (void)N2;
  EXPECT_NEAR(std::remainder(N2_angle - 280 * deg, 2 * M_PI) / deg, 0.0, 1.0 + 0.01);
  std::vector<double> a, Bn, Bt;
  for (int k = 0; k <= 200; ++k)
    a.push_back((170 + 0.1 * k) * deg);
  MultipoleRing(designed).profile(r, a, Bn, Bt);
  for (size_t k = 0; k < a.size(); ++k)
    EXPECT_LE(std::hypot(Bn[k], Bt[k]), 25e-3 + 1e-5) << a[k] / deg;
}

TEST(PoleDesign, MeetsAReleaseRequirement)
{
  const std::string src = MAGBRUSH_SOURCE_DIR;
  const Case c = load_case(src + "/cases/kweon_release.yaml");
  DesignConstraints constraints;
  DesignTarget spec = read_design_spec(src + "/cases/data/kweon_release_spec.yaml", 1e-3, constraints);
  ASSERT_TRUE(spec.release);
  spec.release_inputs = ReleaseInputs::from(c);
  const DesignResult d = design_poles(*c.roller, 10e-3, spec, constraints);
  for (const auto &req : d.requirements)
    std::printf("  %-36s target %8.3f ± %.3f %s, value %8.3f (%s)\n", req.name.c_str(), req.target,
                req.tolerance, req.unit.c_str(), req.value, req.met() ? "met" : "MISSED");
  ASSERT_TRUE(d.feasible);
  Roller designed = *c.roller;
  designed.poles = d.poles;
  for (size_t i = 0; i < designed.poles.size(); ++i)
    if (designed.poles[i].name != "S2") // the others are fixed by the specification
    {
      EXPECT_NEAR(std::remainder(designed.poles[i].angle - c.roller->poles[i].angle, 2 * M_PI), 0.0, 1e-12);
      EXPECT_EQ(designed.poles[i].strength, c.roller->poles[i].strength);
    }
  const auto [S2, S2_angle] = peak_near(designed, 10e-3, "S2");
  std::printf("designed S2 at %.2f°, %.1f kA/m: peak %.2f mT at %.2f°\n", designed.poles[2].angle / deg,
              std::abs(designed.poles[2].strength) / 1e3, S2 * 1e3, S2_angle / deg);
  EXPECT_NEAR(S2, 50e-3, 10e-3);
  // The case's layout holds on 185–200°; the designed one lets go there by at least 6.5 g.
  const ReleaseInputs in = ReleaseInputs::from(c);
  const ReleaseVerdict before = release_in_window(release_profile(MultipoleRing(*c.roller), in, 0.05 * deg),
                                                  185 * deg, 200 * deg);
  const ReleaseVerdict after = release_in_window(release_profile(MultipoleRing(designed), in, 0.05 * deg),
                                                 185 * deg, 200 * deg);
  std::printf("largest net outward acceleration on 185–200°: case %.2f g, designed %.3f g at %.2f°\n",
              before.peak / 9.81, after.peak / 9.81, after.at / deg);
  EXPECT_FALSE(before.releases);
  EXPECT_TRUE(after.releases);
  EXPECT_GE(after.peak / 9.81, 6.5 - 1e-3); // the grid's 0.05° against the requirement's 0.25°
}

TEST(PoleDesign, ReportsAnInfeasibleTargetWithTheBindingBound)
{
  const Roller start = case_roller("kweon_development.yaml");
  DesignTarget spec;
  spec.peaks.push_back({"S1", 250e-3, 2e-3, std::nullopt, 1 * deg}); // needs |M| far above 400 kA/m
  DesignConstraints limits;
  limits.max_strength = 400e3;
  const DesignResult d = design_poles(start, 10e-3, spec, limits);
  ASSERT_FALSE(d.feasible);
  bool names_the_limit = false;
  for (const auto &b : d.binding)
  {
    std::printf("binding: %s\n", b.c_str());
    names_the_limit |= b.find("S1 |M| at the remanence limit") != std::string::npos;
  }
  EXPECT_TRUE(names_the_limit);
  EXPECT_NEAR(std::abs(d.poles[0].strength), 400e3, 1.0);
  std::printf("nearest layout: S1 peak %.2f mT against 250 ± 2 mT\n", d.requirements[0].value);
}

TEST(PoleDesign, LeavesAFixedPoleWhereItIs)
{
  const Roller truth = case_roller("kweon_development.yaml");
  Roller start = perturbed(truth);
  DesignConstraints limits;
  limits.poles["S1"].fixed = true;
  const DesignResult d = design_poles(start, 10e-3, profile_of(truth, 10e-3), limits);
  EXPECT_NEAR(d.poles[0].angle, std::fmod(start.poles[0].angle + 2 * M_PI, 2 * M_PI), 1e-12);
  EXPECT_EQ(d.poles[0].strength, start.poles[0].strength);
  EXPECT_FALSE(d.feasible); // S1 is 5° and 20 % off: the profile near it cannot be met
  bool says_fixed = false;
  for (const auto &b : d.binding)
    says_fixed |= b.find("S1 is fixed") != std::string::npos;
  EXPECT_TRUE(says_fixed);
}

// The seconds the command printed on its "Time:" line ("total S s").
double total_seconds(const std::string &output)
{
  const auto at = output.find("total ");
  return at == std::string::npos ? 1e9 : std::atof(output.c_str() + at + 6);
}

TEST(DesignCommand, SpecificationMetAndCheckedByFemWithinBudget)
{
  const auto dir = magbrush::testing::test_temp_dir("design_spec");
  const std::string src = MAGBRUSH_SOURCE_DIR;
  const auto r = magbrush::testing::run_program(
      "magbrush", "design poles " + src + "/cases/kweon_development.yaml --target " + src +
                      "/cases/data/kweon_development_spec.yaml --set field.output_dir=" + (dir / "fields").string() +
                      " --no-plot -o " + dir.string());
  std::printf("%s\n", r.output.substr(r.output.find("Time:")).c_str());
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("Every requirement is met."), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("The FEM of the designed layout meets every requirement."), std::string::npos) << r.output;
  EXPECT_LT(total_seconds(r.output), 30.0) << r.output;
  const Case designed = load_case((dir / "kweon_development_designed.yaml").string());
  EXPECT_EQ(designed.roller->poles.size(), 5u);
  for (const char *f : {"design_report.txt", "design_profile.csv", "design_requirements.csv", "design_sensitivity.csv",
                        "index.md", "index.html"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  // The FEM check's fields stay in the design's folder (not in the working directory's results/).
  EXPECT_TRUE(std::filesystem::exists(dir / "fem_check_fields" / "kweon_development_designed_magnetic.h5"));
  // The design's page: the requirements judged on the ring and the FEM, the layout, the sensitivities.
  std::ifstream in(dir / "index.md");
  const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char *section : {"## Requirements", "## Layout", "## Sensitivity", "verdict (FEM)", "S1 peak \\|Bn\\|"})
    EXPECT_NE(page.find(section), std::string::npos) << section << "\n" << page;
}

TEST(DesignCommand, RecoversTheCaseFromItsOwnProfile)
{
  const auto dir = magbrush::testing::test_temp_dir("design_profile");
  const std::string case_file = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kweon_development.yaml";
  const auto flux = magbrush::testing::run_program(
      "magbrush", "flux " + case_file + " --source ring --no-plot -o " + (dir / "own").string());
  ASSERT_EQ(flux.code, 0) << flux.output;
  // Every pole 5° off and 20 % stronger or weaker; the FEM check is the other test's.
  const auto r = magbrush::testing::run_program(
      "magbrush", "design poles " + case_file + " --target " + (dir / "own" / "flux_profile.csv").string() +
                      " --set roller.poles.S1.angle=5deg --set roller.poles.N1.angle=67deg"
                      " --set roller.poles.S2.angle=149deg --set roller.poles.S3.angle=211deg"
                      " --set roller.poles.N2.angle=293deg --set roller.poles.S1.strength=396kA/m"
                      " --set roller.poles.N1.strength=137.6kA/m --set roller.poles.S2.strength=240kA/m"
                      " --set roller.poles.S3.strength=204kA/m --set roller.poles.N2.strength=113.6kA/m"
                      " --no-fem-check --no-plot -o " + dir.string());
  EXPECT_EQ(r.code, 0) << r.output;
  const Roller truth = case_roller("kweon_development.yaml");
  const Case designed = load_case((dir / "kweon_development_designed.yaml").string());
  for (size_t i = 0; i < truth.poles.size(); ++i)
  {
    // The file's 4 decimals of a degree and 3 of a kA/m.
    EXPECT_NEAR(std::remainder(designed.roller->poles[i].angle - truth.poles[i].angle, 2 * M_PI) / deg, 0.0, 1e-4);
    EXPECT_NEAR(designed.roller->poles[i].strength, truth.poles[i].strength, 1.0);
  }
}

} // namespace
