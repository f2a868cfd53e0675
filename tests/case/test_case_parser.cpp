// The case parser: the paper scenes load with the values the papers give, defaults match
// the contract struct, overrides behave like file values, errors carry file:line:column,
// the schema and the printed case agree, and printing then re-reading gives the same case.
#include "case/case_format.h"
#include "case/case_parser.h"
#include "case/case_schema.h"
#include "case/case_validation.h"
#include "fields/multipole_ring.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

using namespace magbrush;
namespace fs = std::filesystem;

namespace {
constexpr double pi = 3.14159265358979323846;
const std::string source_dir = MAGBRUSH_SOURCE_DIR;

std::string read_file(const std::string &path)
{
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string error_of(const std::string &text, const std::vector<std::string> &overrides = {})
{
  try
  {
    parse_case_text(text, "t.yaml", overrides);
  }
  catch (const CaseError &e)
  {
    return e.what();
  }
  return "(no error)";
}

const std::string minimal = source_dir + "/tests/case/valid/minimal_roller.yaml";

double nip_relative_speed(const Case &c)
{
  return std::abs(c.sleeve->omega() * c.sleeve->radius + c.drum.omega() * c.drum.radius);
}
} // namespace

TEST(CaseFiles, EveryCaseInCasesLoads)
{
  int n = 0;
  for (const auto &entry : fs::directory_iterator(source_dir + "/cases"))
    if (entry.path().extension() == ".yaml")
    {
      SCOPED_TRACE(entry.path().string());
      EXPECT_NO_THROW(load_case(entry.path().string()));
      ++n;
    }
  EXPECT_GE(n, 3);
  for (const auto &entry : fs::directory_iterator(source_dir + "/tests/case/valid"))
  {
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(load_case(entry.path().string()));
  }
}

TEST(CaseFiles, KawamotoNipHasThePaperValues)
{
  const Case c = load_case(source_dir + "/cases/kawamoto_nip.yaml");
  EXPECT_EQ(c.name, "kawamoto_nip");
  ASSERT_TRUE(c.sleeve && c.roller && c.drum.present);
  EXPECT_DOUBLE_EQ(c.sleeve->radius, 0.0125);
  EXPECT_NEAR(c.sleeve->rpm, 219.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.drum.radius, 0.05);
  EXPECT_NEAR(c.drum.rpm, -29.0, 1e-12);
  EXPECT_NEAR(c.drum.gap, 400e-6, 1e-18);
  // The paper's relative speed 0.135 m/s: pi (25 mm x 219 - 100 mm x 29) / 60 = 0.13483 m/s.
  EXPECT_NEAR(c.sleeve->surface_speed(), pi * 0.025 * 219 / 60, 1e-12);
  EXPECT_NEAR(nip_relative_speed(c), pi * (0.025 * 219 - 0.1 * 29) / 60, 1e-12);
  EXPECT_NEAR(nip_relative_speed(c), 0.135, 0.0005);
  ASSERT_EQ(c.populations.size(), 1u);
  EXPECT_EQ(c.populations[0].count, 12300);
  EXPECT_NEAR(c.populations[0].diameter_mean, 60e-6, 1e-18);
  const Material &carrier = c.material("carrier");
  EXPECT_DOUBLE_EQ(carrier.youngs_modulus, 1e9);
  EXPECT_DOUBLE_EQ(carrier.poisson_ratio, 0.35);
  EXPECT_DOUBLE_EQ(carrier.friction, 0.45);
  EXPECT_DOUBLE_EQ(carrier.damping, 0.6);
  EXPECT_EQ(carrier.polygon_angles, 12);
  EXPECT_DOUBLE_EQ(carrier.mu_r, 3.9);
  EXPECT_DOUBLE_EQ(c.material("wall").youngs_modulus, 5e10);
  EXPECT_DOUBLE_EQ(c.material("wall").friction, 0.35);
  EXPECT_DOUBLE_EQ(c.dem.time_step, 2e-8);
  EXPECT_DOUBLE_EQ(c.dem.magnetic_refresh, 5e-6);
  EXPECT_DOUBLE_EQ(c.dem.periodic_length, 1e-3);
  EXPECT_EQ(c.applied_field.kind, AppliedField::Kind::roller);
  EXPECT_FALSE(c.electric.enabled);
  ASSERT_EQ(c.roller->poles.size(), 5u);
  EXPECT_EQ(c.roller->poles[0].name, "S1");
  EXPECT_LT(c.roller->poles[0].strength, 0.0);
  EXPECT_NEAR(c.roller->poles[0].angle, c.drum.angle, 1e-12); // development pole faces the drum
}

TEST(CaseFiles, BrushCompressionAndItsCarrierVariants)
{
  const std::string path = source_dir + "/cases/kawamoto_brush_compression.yaml";
  const Case c = load_case(path);
  EXPECT_EQ(c.scene, "box");
  EXPECT_EQ(c.applied_field.kind, AppliedField::Kind::uniform);
  EXPECT_DOUBLE_EQ(c.applied_field.uniform_magnitude, 0.13);
  EXPECT_DOUBLE_EQ(c.dem.periodic_length_x, 2e-3);
  EXPECT_DOUBLE_EQ(c.dem.gravity[2], -9.81);
  ASSERT_EQ(c.planes.size(), 2u);
  EXPECT_EQ(c.planes[1].path.back().second[0], 1.5e-3); // slides 1.5 mm sideways
  EXPECT_EQ(c.populations[0].count, 4420);
  const Case c42 = load_case(path, {"populations.carrier.diameter=42um", "populations.carrier.diameter_std=4.2um",
                                    "populations.carrier.count=13700"});
  EXPECT_EQ(c42.populations[0].count, 13700);
  EXPECT_NEAR(c42.populations[0].diameter_mean, 42e-6, 1e-18);
}

TEST(CaseFiles, KweonFullRollerIsAClosedDeveloperLoop)
{
  // The whole roller as the paper's flow simulations (Fig. 4-7): carriers only, fed from a
  // finite sump at the pick-up, regulated by the guide and the doctor blade, released back to
  // the sump; no toner, no nip field (those are the development case's).
  const Case c = load_case(source_dir + "/cases/kweon_full_roller.yaml");
  EXPECT_FALSE(c.electric.enabled);
  ASSERT_EQ(c.blades.size(), 2u);
  EXPECT_TRUE(c.blades[0].is_doctor_blade);
  EXPECT_NEAR(c.blades[0].gap, 0.5e-3, 1e-15);
  // The generated blade's polygon really is `gap` from the sleeve.
  EXPECT_NEAR(polygon_distance_to_point(c.blades[0].polygon, {0, 0}) - c.sleeve->radius, 0.5e-3, 1e-12);
  EXPECT_GT(polygon_signed_area(c.blades[1].polygon), 0.0);
  ASSERT_EQ(c.populations.size(), 1u);
  EXPECT_EQ(c.populations[0].kind, ParticleKind::carrier);
  EXPECT_EQ(c.populations[0].count, 0);
  // The loop: a finite sump feeds the sleeve, everything leaving returns to it.
  EXPECT_GT(c.flow.inflow_areal_mass, 0.0);
  EXPECT_GT(c.flow.inflow_sump_mass, 0.0);
  EXPECT_GT(c.flow.outflow_radius, c.sleeve->radius);
  // The guide wall lies above the fed layer: the inflow passes under it.
  EXPECT_LT(c.sleeve->radius + c.flow.inflow_layer_height,
            polygon_distance_to_point(c.blades[1].polygon, {0, 0}));
  EXPECT_TRUE(fs::exists(c.measured_flux_file)) << c.measured_flux_file;
  // polarity + unsigned strength = signed strength
  EXPECT_LT(c.roller->poles[0].strength, 0.0);
  EXPECT_GT(c.roller->poles[1].strength, 0.0);
}

TEST(CaseFiles, KweonReleaseBracketsTheLikePolesAndRemovesWhatLeavesTheSleeve)
{
  // The release sector: fed before S2, the two measuring lines on either side of the like
  // poles S2/S3, the carried-back outflow past the second line, and what left the sleeve
  // removed before it can cross that line as "carried".
  const Case c = load_case(source_dir + "/cases/kweon_release.yaml");
  EXPECT_TRUE(c.blades.empty());
  ASSERT_EQ(c.roller->poles.size(), 5u);
  const double s2 = c.roller->poles[2].angle, s3 = c.roller->poles[3].angle;
  EXPECT_LT(c.roller->poles[2].strength, 0.0); // both S: they repel
  EXPECT_LT(c.roller->poles[3].strength, 0.0);
  EXPECT_LT(c.flow.inflow_angle, c.dma.release_from);
  EXPECT_LT(c.dma.release_from, s2 + 0.5 * (s3 - s2));
  EXPECT_GT(c.dma.release_to, s3);
  EXPECT_LT(c.dma.release_to, c.flow.outflow_angle);
  // A bead leaving the sleeve along the tangent at 200 deg is at R / cos(release_to - 200 deg)
  // from the axis when it reaches the second line: beyond the outflow's radius, so removed.
  const double R = c.sleeve->radius, leave = 200.0 * M_PI / 180.0;
  EXPECT_GT(R / std::cos(c.dma.release_to - leave), c.flow.outflow_radius);
  // Only the layer counts at the lines, and its chains (up to ~1.5 mm) are part of it.
  EXPECT_LT(R + c.dma.height, c.flow.outflow_radius);
  EXPECT_GE(c.dma.height, 1.5e-3);
}

// The default case is Kawamoto's nip supplied by the sleeve: the same roller, drum and beads as
// the paper's placed scene, none placed, a sump inflow before the nip window and the outflow
// after it (so that the window's bead budget counts the flux), and room for the layer where it
// is placed: random placement refuses above 30 % solid, at the entry (the layer height or the
// local gap, the smaller) and, for the prefill, in the gap itself.
TEST(CaseFiles, KawamotoFedIsThePapersNipSuppliedWithRoomForItsLayer)
{
  const Case fed = load_case(source_dir + "/cases/kawamoto_nip_fed.yaml");
  const Case paper = load_case(source_dir + "/cases/kawamoto_nip.yaml");
  ASSERT_TRUE(fed.roller && paper.roller && fed.sleeve && paper.sleeve);
  ASSERT_EQ(fed.roller->poles.size(), paper.roller->poles.size());
  for (std::size_t i = 0; i < fed.roller->poles.size(); ++i)
  {
    EXPECT_EQ(fed.roller->poles[i].angle, paper.roller->poles[i].angle);
    EXPECT_EQ(fed.roller->poles[i].strength, paper.roller->poles[i].strength);
  }
  EXPECT_EQ(fed.sleeve->radius, paper.sleeve->radius);
  EXPECT_EQ(fed.sleeve->rpm, paper.sleeve->rpm);
  EXPECT_EQ(fed.drum.radius, paper.drum.radius);
  EXPECT_EQ(fed.drum.rpm, paper.drum.rpm);
  EXPECT_EQ(fed.drum.gap, paper.drum.gap);
  ASSERT_EQ(fed.populations.size(), 1u);
  EXPECT_EQ(fed.populations[0].diameter_mean, paper.populations[0].diameter_mean);
  EXPECT_EQ(fed.populations[0].count, 0);
  EXPECT_EQ(fed.flow.inflow_supply, "sump");
  EXPECT_LT(fed.flow.inflow_angle, -fed.nip.chain_half_angle);
  EXPECT_GT(fed.flow.outflow_angle, fed.nip.chain_half_angle);
  EXPECT_EQ(fed.flow.average_from, fed.nip.average_from);
  EXPECT_LT(fed.nip.average_from, fed.dem.duration);

  // Radial distance from the sleeve surface to the drum along the ray at sleeve angle a.
  const double R = fed.sleeve->radius, Rd = fed.drum.radius, D = R + fed.drum.gap + Rd;
  auto gap_at = [&](double a) {
    const double c = std::cos(a - fed.drum.angle);
    return D * c - std::sqrt(D * D * c * c - D * D + Rd * Rd) - R;
  };
  EXPECT_NEAR(gap_at(fed.drum.angle), fed.drum.gap, 1e-12);
  double rho = 0.0;
  for (const Material &m : fed.materials)
    if (m.name == fed.populations[0].material)
      rho = m.density;
  ASSERT_GT(rho, 0.0);
  const double entry = std::min(fed.flow.inflow_layer_height, gap_at(fed.flow.inflow_angle));
  const double solid_at_entry = fed.flow.inflow_areal_mass / (rho * entry);
  const double solid_in_gap = fed.flow.inflow_areal_mass / (rho * fed.drum.gap);
  std::printf("fed nip: gap at the entry %.3f mm, solid fraction at the entry %.3f, in the gap %.3f\n",
              gap_at(fed.flow.inflow_angle) * 1e3, solid_at_entry, solid_in_gap);
  EXPECT_LT(solid_at_entry, 0.30);
  // The prefill reaches through the gap centre to the outflow.
  EXPECT_GE(fed.flow.inflow_angle + fed.flow.inflow_prefill_arc, fed.flow.outflow_angle - 1e-9);
  EXPECT_LT(solid_in_gap, 0.30);
}

TEST(CaseFiles, KweonDevelopmentHasTheBiasRangeAndChargedToner)
{
  const Case c = load_case(source_dir + "/cases/kweon_development.yaml");
  EXPECT_TRUE(c.electric.enabled);
  EXPECT_GE(std::abs(c.electric.bias), 500.0);
  EXPECT_LE(std::abs(c.electric.bias), 800.0);
  ASSERT_EQ(c.populations.size(), 2u);
  EXPECT_EQ(c.populations[1].kind, ParticleKind::toner);
  EXPECT_NEAR(c.populations[1].charge_to_mass, -30e-3, 1e-15);
  // Its toner rides the carriers until near the drum, fed with them (the reduced toner model).
  EXPECT_GT(c.populations[1].carried_until_gap, 0.0);
  EXPECT_TRUE(c.populations[1].attached);
  ASSERT_TRUE(c.flow.inflow() && c.sleeve && c.drum.present);
  // The window is the nip's: the feed upstream of the development pole facing the drum, and
  // the removal downstream of the measuring window: the drum point measure_to past the gap
  // centre must still be before the outflow, seen from the roller axis, or the developed toner
  // is removed before it is measured.
  const double x = c.development.measure_to;
  const double radial = c.sleeve->radius + c.drum.gap + x * x / (2.0 * c.drum.radius);
  const double measured_at = c.drum.angle + std::atan2(x, radial);
  EXPECT_LT(c.flow.inflow_angle, c.drum.angle);
  // The nip is filled from the start: the prefill reaches the outflow, thinned past the gap
  // (the feed layer does not fit under the drum).
  EXPECT_GE(c.flow.inflow_angle + c.flow.inflow_prefill_arc, c.flow.outflow_angle - 1e-9);
  EXPECT_EQ(c.flow.inflow_prefill_no_room, "thin");
  EXPECT_LT(measured_at, c.flow.outflow_angle);
  EXPECT_GT(c.development.measure_from, 0.0);
  EXPECT_GT(c.development.average_from, 0.0);
  EXPECT_GT(c.dem.duration, c.development.average_from);
}

// The stored fields go with the run's results unless the case puts them elsewhere, so that
// two runs of one case into two folders (two biases; two tests side by side) never share one.
TEST(CaseParser, TheFieldsAreStoredInTheOutputDirectoryUnlessTheCaseSaysWhere)
{
  EXPECT_EQ(load_case(minimal).field.output_dir, "results/minimal_roller/fields");
  EXPECT_EQ(load_case(minimal, {"output.directory=runs/a"}).field.output_dir, "runs/a/fields");
  EXPECT_EQ(load_case(minimal, {"output.directory=runs/a", "field.output_dir=shared"}).field.output_dir, "shared");
}

TEST(CaseParser, DefaultsAgreeWithTheContractStruct)
{
  const Case c = load_case(minimal);
  const FieldSettings f;
  EXPECT_DOUBLE_EQ(c.field.mesh_size_far, f.mesh_size_far);
  EXPECT_DOUBLE_EQ(c.field.mesh_size_sleeve, f.mesh_size_sleeve);
  EXPECT_DOUBLE_EQ(c.field.mesh_size_gap, f.mesh_size_gap);
  EXPECT_EQ(c.field.element_degree, f.element_degree);
  EXPECT_DOUBLE_EQ(c.field.outer_radius_factor, f.outer_radius_factor);
  EXPECT_DOUBLE_EQ(c.field.grid_radial_spacing, f.grid_radial_spacing);
  EXPECT_NEAR(c.field.grid_angular_spacing, f.grid_angular_spacing, 1e-15);
  EXPECT_DOUBLE_EQ(c.field.grid_electric_spacing, f.grid_electric_spacing);
  // A case from a file names its folder after itself (case/run_folder.h); one built by hand
  // writes into the struct's results/.
  EXPECT_EQ(c.field.output_dir, "results/minimal_roller/fields");
  EXPECT_EQ(f.output_dir, "results/fields");
  const DemSettings d;
  EXPECT_DOUBLE_EQ(c.dem.time_step_safety, d.time_step_safety);
  EXPECT_EQ(c.dem.magnetic_model, d.magnetic_model);
  EXPECT_DOUBLE_EQ(c.dem.magnetic_cutoff, d.magnetic_cutoff);
  EXPECT_DOUBLE_EQ(c.dem.magnetic_tolerance, d.magnetic_tolerance);
  EXPECT_DOUBLE_EQ(c.dem.verlet_skin, d.verlet_skin);
  EXPECT_DOUBLE_EQ(c.dem.air_viscosity, d.air_viscosity);
  EXPECT_EQ(c.dem.gravity, d.gravity);
  EXPECT_EQ(c.dem.seed, d.seed);
  EXPECT_DOUBLE_EQ(c.dem.max_overlap_fraction, d.max_overlap_fraction);
  EXPECT_EQ(c.dem.restitution_model, d.restitution_model);
  EXPECT_DOUBLE_EQ(c.dem.max_kinetic_energy_growth, d.max_kinetic_energy_growth);
  const Material m;
  EXPECT_DOUBLE_EQ(c.material("wall").poisson_ratio, m.poisson_ratio);
  EXPECT_DOUBLE_EQ(c.material("wall").restitution, m.restitution);
  const OutputSettings o;
  EXPECT_EQ(c.output.directory, o.directory + "/minimal_roller");
  EXPECT_EQ(c.name, "minimal_roller"); // the file stem
  EXPECT_EQ(c.roller->poles[0].shape_factor, 10.0);
  EXPECT_EQ(c.drum.pc_eps_r, Drum{}.pc_eps_r);
}

TEST(CaseParser, OverridesUseTheSameConversionAndNames)
{
  const Case c = load_case(minimal, {"drum.gap=0.3mm", "roller.poles.S1.angle=95deg", "roller.poles.[0].strength=1.2e5 A/m",
                                     "sleeve.rpm=-2 rad/s", "electric.bias=-500 V"});
  EXPECT_NEAR(c.drum.gap, 0.3e-3, 1e-18);
  EXPECT_NEAR(c.roller->poles[1].angle, 95 * pi / 180, 1e-15);
  EXPECT_DOUBLE_EQ(c.roller->poles[0].strength, 1.2e5);
  EXPECT_NEAR(c.sleeve->rpm, -2 * 60 / (2 * pi), 1e-12);
  EXPECT_TRUE(c.electric.enabled); // the override created the section
  EXPECT_DOUBLE_EQ(c.electric.bias, -500.0);
  // A later override wins.
  EXPECT_NEAR(load_case(minimal, {"drum.gap=1mm", "drum.gap=2mm"}).drum.gap, 2e-3, 1e-18);
  // A bare number needs its unit in an override as in the file (0 excepted).
  const std::string bare = error_of(read_file(minimal), {"drum.gap=0.3"});
  EXPECT_NE(bare.find("--set 'drum.gap=0.3': drum.gap: 0.3 \u2014 a length needs a unit: 0.3 mm?"), std::string::npos)
      << bare;
  EXPECT_EQ(load_case(minimal, {"drum.pc_thickness=0"}).drum.pc_thickness, 0.0);
  // Errors name the override, not the file.
  const std::string e = error_of(read_file(minimal), {"roller.poles.S1.angle=-5deg"});
  EXPECT_NE(e.find("--set 'roller.poles.S1.angle=-5deg': roller.poles.S1.angle: expected an angle in [0 deg, 360 deg)"),
            std::string::npos)
      << e;
  EXPECT_NE(error_of(read_file(minimal), {"sleeve.radius"}).find("expected key.path=value"), std::string::npos);
  EXPECT_NE(error_of(read_file(minimal), {"dem.seeed=3"}).find("did you mean 'seed'?"), std::string::npos);
  // Unnamed list elements by index, also written as key[i].
  const std::string box = source_dir + "/cases/kawamoto_brush_compression.yaml";
  EXPECT_DOUBLE_EQ(load_case(box, {"planes.plate.path[3].time=9ms"}).planes[1].path[3].first, 9e-3);
  EXPECT_DOUBLE_EQ(load_case(box, {"planes.plate.path.[3].time=9ms"}).planes[1].path[3].first, 9e-3);
  const std::string e2 = error_of(read_file(box), {"planes.plate.path[3].time=1ms"});
  EXPECT_NE(e2.find("--set 'planes.plate.path[3].time=1ms': planes.plate.path[3].time: path times must increase"),
            std::string::npos)
      << e2;
}

TEST(CaseParser, ErrorsCarryFileLineColumnPathExpectedAndFound)
{
  const std::string text = "sleeve:\n  radius: 10 mm\n  rpm: 25 mm\n";
  const std::string e = error_of(text);
  EXPECT_NE(e.find("t.yaml:3:8: sleeve.rpm: expected an angular velocity (e.g. 219 rpm), found '25 mm': that is a length"),
            std::string::npos)
      << e;
  // Several errors in one go, in file order.
  const std::string many = error_of("sleeve:\n  radius: 10 rpm\n  rpn: 3 rpm\nrollr: {}\n");
  EXPECT_NE(many.find("(3 errors)"), std::string::npos) << many;
  EXPECT_LT(many.find("t.yaml:2:11"), many.find("t.yaml:3:3"));
  EXPECT_NE(many.find("did you mean 'rpm'?"), std::string::npos);
  EXPECT_NE(many.find("t.yaml:4:1: rollr: unknown key 'rollr' (did you mean 'roller'?)"), std::string::npos) << many;
}

TEST(CaseParser, DidYouMean)
{
  const std::vector<std::string> keys{"radius", "diameter", "thickness", "rpm"};
  EXPECT_EQ(did_you_mean("diamter", keys), "diameter");   // deletion
  EXPECT_EQ(did_you_mean("raidus", keys), "radius");      // transposition
  EXPECT_EQ(did_you_mean("Thickness", keys), "thickness"); // case
  EXPECT_EQ(did_you_mean("rpn", keys), "rpm");
  EXPECT_EQ(did_you_mean("diam", keys), "diameter");      // prefix
  EXPECT_EQ(did_you_mean("colour", keys), "");            // nothing close
}

TEST(CaseParser, GeometryNonsenseIsCaughtInProcess)
{
  const std::string base = read_file(minimal);
  EXPECT_NE(error_of(base, {"drum.gap=-0.1mm"}).find("cut into the sleeve"), std::string::npos);
  EXPECT_NE(error_of(base, {"roller.shaft_radius=9.5mm"}).find("must be smaller than the magnet"), std::string::npos);
  EXPECT_NE(error_of(base, {"sleeve.thickness=1.5mm"}).find("must fit inside the sleeve"), std::string::npos);
  EXPECT_NE(error_of(base, {"roller.poles.S1.angle=5deg"}).find("at least 10 deg apart"), std::string::npos);
  EXPECT_NE(error_of(base, {"populations.carrier.diameter_std=20um"}).find("mean - 3 std"), std::string::npos);
  EXPECT_NE(error_of(base, {"field.probe_radius=8mm"}).find("inside the magnet"), std::string::npos);
  EXPECT_NE(error_of(base, {"dem.time_step=1us", "dem.duration=0.5us"}).find("shorter than one time step"),
            std::string::npos);
  // The flow keys' combinations.
  const std::string sump = error_of(base, {"inflow.areal_mass=0.4kg/m^2", "inflow.sump_mass=0.5kg/m"});
  EXPECT_NE(sump.find("inflow.sump_mass"), std::string::npos) << sump;
  EXPECT_NE(sump.find("needs inflow.supply: sump"), std::string::npos) << sump;
  EXPECT_NE(error_of(base, {"inflow.prefill_arc=10deg"}).find("set inflow.areal_mass"), std::string::npos);
  // Geometry errors are collected too.
  const std::string two = error_of(base, {"drum.gap=-1mm", "roller.shaft_radius=9.5mm"});
  EXPECT_NE(two.find("(2 errors)"), std::string::npos) << two;
}

// Every measurement's averaging window lies inside the run and holds more than one sample
// interval (the developed image in blocks: at least one block of drum travel), or the case is
// refused naming both keys and their values.
TEST(CaseParser, AveragingWindowsLieInsideTheRun)
{
  const std::string fed = source_dir + "/cases/kawamoto_nip_fed.yaml";
  const std::string late = error_of(read_file(fed), {"dem.duration=0.5ms"});
  EXPECT_NE(late.find("nip.average_from: the averaging window of the nip profiles starts at or after the end of the "
                      "run (nip.average_from = 25 ms, dem.duration = 500 us)"),
            std::string::npos)
      << late;
  EXPECT_NE(late.find("flow_report.average_from"), std::string::npos) << late;
  EXPECT_NO_THROW(load_case(fed, {"dem.duration=0.5ms", "nip.average_from=0s", "flow_report.average_from=0s"}));
  // A first leg of a longer run (a sweep's spin-up, a run to be continued) says so.
  EXPECT_NE(late.find("a first leg of a run to be continued: dem.leg: true"), std::string::npos) << late;
  EXPECT_NO_THROW(load_case(fed, {"dem.duration=0.5ms", "dem.leg=true"}));
  const std::string short_window = error_of(read_file(fed), {"dem.duration=25.01ms"});
  EXPECT_NE(short_window.find("shorter than one sample interval (flow_report.sample_interval = 20 us)"),
            std::string::npos)
      << short_window;
  // The developed image over whole periods: 1 um of drum at ~0.27 m/s is ~3.7 us.
  const std::string cell = source_dir + "/tests/scenes/development/development_cell.yaml";
  const std::vector<std::string> periods{"development.average_over=image_periods", "electric.image.period=1um",
                                         "dem.duration=10us", "nip.average_from=0s"};
  auto with = [&](std::string o) {
    auto v = periods;
    v.push_back(std::move(o));
    return v;
  };
  const std::string block = error_of(read_file(cell), with("development.average_from=9us"));
  EXPECT_NE(block.find("shorter than one block of the developed image's means (one image period, "
                       "electric.image.period = 1 um"),
            std::string::npos)
      << block;
  EXPECT_NO_THROW(load_case(cell, with("development.average_from=0s")));
  // A solid area's blocks are development.block_length of drum.
  const std::string solid = error_of(read_file(cell), {"development.average_over=image_periods", "electric.image.duty=1",
                                                       "development.block_length=10um", "dem.duration=10us",
                                                       "nip.average_from=0s", "development.average_from=9us"});
  EXPECT_NE(solid.find("(development.block_length = 10 um of drum surface"), std::string::npos) << solid;
  // A measurement the scene does not have is not checked (no periodic slab: no nip measurement).
  EXPECT_NO_THROW(load_case(minimal, {"dem.duration=1ms", "nip.average_from=5ms"}));
}

TEST(CaseParser, GeneratedBladePolygon)
{
  const auto p = generated_blade_polygon(0.01, pi / 2, 0.5e-3, 1e-3, 5e-3);
  ASSERT_EQ(p.size(), 4u);
  EXPECT_NEAR(polygon_distance_to_point(p, {0, 0}), 0.0105, 1e-15);
  EXPECT_NEAR(polygon_signed_area(p), 5e-6, 1e-18); // counter-clockwise, thickness x length
  EXPECT_TRUE(polygon_is_simple(p));
  EXPECT_FALSE(polygon_is_simple({{0, 0}, {1, 1}, {1, 0}, {0, 1}}));
}

TEST(CaseSchema, PrintedEntriesAndSchemaAgree)
{
  // Every printed entry names a schema key, and a case using every key prints every leaf
  // (apart from the alternatives folded into others).
  const Case c = load_case(source_dir + "/tests/case/valid/full_roller.yaml");
  std::set<std::string> printed;
  for (const auto &e : resolved_entries(c))
  {
    EXPECT_NE(find_key_spec(e.pattern), nullptr) << e.pattern;
    printed.insert(e.pattern);
  }
  const std::set<std::string> folded{"sleeve.diameter", "drum.diameter", "roller.shape_factor",
                                     "roller.poles[].polarity", "blades[].angle", "blades[].thickness",
                                     "blades[].length", "electric.image.dark_potential",
                                     "electric.image.light_potential", "planes[].path[].time",
                                     "planes[].path[].displacement", "planes[].name", "planes[].point",
                                     "applied_field.schedule[].time", "applied_field.schedule[].magnitude",
                                     "planes[].normal", "planes[].material"};
  for (const auto &k : case_schema())
    if (!k.is_container() && !folded.count(k.path))
    {
      EXPECT_TRUE(printed.count(k.path)) << k.path << " is in the schema but not printed";
    }
  // Schema sanity: children have parents; defaults of leaves parse.
  for (const auto &k : case_schema())
  {
    const std::string parent = parent_pattern(k.path);
    if (!parent.empty())
    {
      std::string container = parent;
      if (container.size() > 2 && container.substr(container.size() - 2) == "[]")
        container = container.substr(0, container.size() - 2);
      if (container.size() > 2 && container.substr(container.size() - 2) == ".*")
        container = container.substr(0, container.size() - 2);
      EXPECT_NE(find_key_spec(container), nullptr) << k.path;
    }
    EXPECT_FALSE(k.doc.empty()) << k.path;
  }
}

TEST(CaseFormat, PrintedCaseReadsBackToTheSameCase)
{
  // Every "path = value" line of the printed case, given back as an override, must leave the
  // case unchanged to the printed precision (6 digits).
  for (const char *file : {"/cases/kawamoto_nip.yaml", "/cases/kawamoto_brush_compression.yaml"})
  {
    SCOPED_TRACE(file);
    const Case c = load_case(source_dir + file);
    std::vector<std::string> overrides;
    for (const auto &e : resolved_entries(c))
      if (e.path != "measured_flux_file")
        overrides.push_back(e.path + "=" + e.pretty);
    const Case again = load_case(source_dir + file, overrides);
    const auto a = resolved_entries(c), b = resolved_entries(again);
    ASSERT_EQ(a.size(), b.size());
    const std::regex number(R"([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)");
    for (size_t i = 0; i < a.size(); ++i)
    {
      EXPECT_EQ(a[i].path, b[i].path);
      std::vector<double> x, y;
      for (auto it = std::sregex_iterator(a[i].exact.begin(), a[i].exact.end(), number); it != std::sregex_iterator(); ++it)
        x.push_back(std::stod(it->str()));
      for (auto it = std::sregex_iterator(b[i].exact.begin(), b[i].exact.end(), number); it != std::sregex_iterator(); ++it)
        y.push_back(std::stod(it->str()));
      ASSERT_EQ(x.size(), y.size()) << a[i].path;
      for (size_t k = 0; k < x.size(); ++k)
        EXPECT_NEAR(x[k], y[k], 1e-5 * std::abs(x[k])) << a[i].path;
    }
  }
}

TEST(CaseFormat, SchemaReferenceIsUpToDate)
{
  // docs/case_reference.md is generated by `magbrush check --explain --markdown`.
  const std::string doc = read_file(source_dir + "/docs/case_reference.md");
  EXPECT_EQ(doc, format_schema(true)) << "regenerate: build/bin/magbrush check --explain --markdown > docs/case_reference.md";
  for (const auto &k : case_schema())
    EXPECT_NE(format_schema(false).find(last_component(k.path)), std::string::npos);
}

namespace {
// The synthetic gaussmeter scan shipped with the cases: angle_deg, Bn_mT, Bt_mT.
std::vector<std::array<double, 3>> read_scan()
{
  std::ifstream in(source_dir + "/cases/data/sleeve_profile_example.csv");
  std::vector<std::array<double, 3>> rows;
  for (std::string line; std::getline(in, line);)
  {
    std::array<double, 3> r;
    if (line.empty() || line[0] == '#' || std::sscanf(line.c_str(), "%lf,%lf,%lf", &r[0], &r[1], &r[2]) != 3)
      continue;
    rows.push_back(r);
  }
  return rows;
}

// Largest |Bn| difference between the case's roller (exact multipole ring at the sleeve
// surface) and the scan, which was generated independently from the roller in its header.
double max_scan_deviation(const Case &c)
{
  const MultipoleRing ring(*c.roller);
  double worst = 0.0;
  for (const auto &row : read_scan())
    worst = std::max(worst, std::abs(ring.field_polar(c.sleeve->radius, row[0] * pi / 180).Br * 1e3 - row[1]));
  return worst;
}
} // namespace

TEST(CaseFiles, RollersReproduceTheExampleScan)
{
  ASSERT_EQ(read_scan().size(), 360u);
  // Kweon: the scan's roller at its own scale (probe radius 10 mm = sleeve surface).
  // The scan has 0.4 mT of noise per point: 360 points stay within about 4 sigma.
  EXPECT_LT(max_scan_deviation(load_case(source_dir + "/cases/kweon_full_roller.yaml")), 1.6);
  // Kawamoto: the same roller scaled by 1.25 onto the 12.5 mm sleeve; uniform scaling of a
  // magnetised body leaves B unchanged at corresponding points.
  EXPECT_LT(max_scan_deviation(load_case(source_dir + "/cases/kawamoto_nip.yaml")), 1.6);
}

TEST(CaseFiles, KawamotoDevelopmentPoleFieldAtTheNip)
{
  const Case c = load_case(source_dir + "/cases/kawamoto_nip.yaml");
  const MultipoleRing ring(*c.roller);
  const double b = std::abs(ring.field_polar(c.sleeve->radius, c.drum.angle).Br);
  EXPECT_GT(b, 0.095);
  EXPECT_LT(b, 0.130);
}
