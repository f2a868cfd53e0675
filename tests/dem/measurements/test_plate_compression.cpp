// The plate-compression measurement against results known exactly: beads pressed into a plate
// by a given overlap carry the Hertz force (4/3) E* √r δ^{3/2}; a plate sliding over beads
// that cannot follow it (pinned by their inertia) feels μ_wall × the normal force on every
// bead; densities, spacing and pressure follow from the count and the periodic area; the
// applied |B| follows the piecewise-linear schedule.
#include "dem/measurements/plate_compression.h"

#include "dem/measurements/measurement_registry.h"

#include "fields/applied_magnetic_field.h"
#include "case/case_parser.h"
#include "dem/dem_system.h"

#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace magbrush;
using namespace magbrush::dem;
namespace fs = std::filesystem;

namespace {

constexpr double plate_height = 1.0e-3;    // stage at z = 0, plate at z = 1 mm
constexpr double lx = 1.0e-3, ly = 0.5e-3; // periodic area 0.5 mm²

// A box with a stage and a plate; the plate path is given as YAML.
std::string scene(const std::string &plate_path, double bead_density)
{
  std::ostringstream s;
  s << "scene: box\n"
       "planes:\n"
       "  - {name: stage, point: [0, 0, 0], normal: [0, 0, 1], material: wall}\n"
       "  - name: plate\n"
       "    point: [0 mm, 0 mm, 1 mm]\n"
       "    normal: [0, 0, -1]\n"
       "    material: wall\n"
    << plate_path
    << "materials:\n"
       "  bead: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: "
    << bead_density
    << " kg/m^3, friction: 0.45}\n"
       "  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35}\n"
       "populations:\n"
       "  - {name: carrier, material: bead, diameter: 60 um, count: 1, insert_box: [[0, 0, 0.2 mm], [1 mm, 0.5 mm, 0.8 "
       "mm]]}\n"
       "applied_field:\n"
       "  kind: uniform\n"
       "  schedule:\n"
       "    - {time: 0 s, magnitude: 0 mT}\n"
       "    - {time: 100 ns, magnitude: 130 mT}\n"
       "    - {time: 200 ns, magnitude: 30 mT}\n"
       "dem:\n"
       "  time_step: 1e-8 s\n"
       "  duration: 1 us\n"
       "  periodic_length_x: 1 mm\n"
       "  periodic_length_y: 0.5 mm\n"
       "  gravity: [0, 0, 0]\n"
       "  air_viscosity: 0 Pa*s\n"
       "compression:\n"
       "  sample_interval: 10 ns\n"
       "  average_window: 50 ns\n";
  return s.str();
}

// Beads of radius r_k pressed into the plate by δ_k, well apart from each other and the stage.
struct PressedBead
{
  double x, y, r, delta;
};
const std::vector<PressedBead> beads{{0.10e-3, 0.10e-3, 30e-6, 0.5e-6},
                                     {0.30e-3, 0.25e-3, 27e-6, 1.0e-6},
                                     {0.55e-3, 0.40e-3, 33e-6, 0.2e-6},
                                     {0.80e-3, 0.15e-3, 30e-6, 2.0e-6},
                                     {0.95e-3, 0.45e-3, 25e-6, 0.8e-6}};

// Hertz: bead (E 1 GPa, ν 0.35) on the wall (E 50 GPa, ν 0.3); R* = r for a plane.
double hertz_force(const PressedBead &b)
{
  const double inv_e = (1 - 0.35 * 0.35) / 1e9 + (1 - 0.3 * 0.3) / 5e10;
  return 4.0 / 3.0 / inv_e * std::sqrt(b.r) * std::pow(b.delta, 1.5);
}

void place_beads(DemSystem &s, double density)
{
  for (const auto &b : beads)
    s.particles().add({b.x, b.y, plate_height - b.r + b.delta}, b.r, density, 0, 0.0);
  s.initialize();
}

std::vector<std::vector<double>> read_csv(const std::string &path)
{
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);)
  {
    if (line.empty() || line[0] == '#' || !(std::isdigit(static_cast<unsigned char>(line[0])) || line[0] == '-'))
      continue;
    std::vector<double> row;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');)
      row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

const std::string static_plate = "    path: []\n";

} // namespace

TEST(PlateCompression, AppliesToBoxScenesWithPlateAndStage)
{
  const Case c = parse_case_text(scene(static_plate, 2200), "column.yaml");
  EXPECT_TRUE(PlateCompression::applies(c));
  Case other = c;
  other.compression.plate = "lid";
  EXPECT_FALSE(PlateCompression::applies(other));
  // Not periodic in the plate plane: no pressure area, a clear refusal.
  Case open = c;
  open.dem.periodic_length_y = 0.0;
  try
  {
    PlateCompression m(open);
    FAIL() << "expected a refusal";
  }
  catch (const std::invalid_argument &e)
  {
    EXPECT_NE(std::string(e.what()).find("periodic along y"), std::string::npos) << e.what();
  }
  // The registry adds it to the Kawamoto case.
  bool listed = false;
  for (const auto &f : measurement_factories())
    listed = listed || f.name == "plate compression";
  EXPECT_TRUE(listed);
}

TEST(PlateCompression, PressedBeadsGiveHertzForcesDensityAndSpacing)
{
  // Beads pinned by their inertia (density 1e12 kg/m³: a mN force moves them < 1e-12 m over
  // the run), so that the overlaps stay the given ones at every step.
  const double density = 1e12;
  const Case c = parse_case_text(scene(static_plate, density), "column.yaml");
  DemSystem s(c);
  place_beads(s, density);
  PlateCompression m(c);
  EXPECT_DOUBLE_EQ(m.area(), lx * ly);
  s.step();
  const PlateContactMap map = m.contact_map(s);
  ASSERT_EQ(map.beads.size(), beads.size());
  double total = 0.0;
  for (const auto &got : map.beads)
  {
    const PressedBead &b = beads[static_cast<std::size_t>(got.id)];
    const double exact = hertz_force(b);
    total += exact;
    EXPECT_NEAR(got.fn, exact, 1e-6 * exact) << "bead " << got.id;
    EXPECT_NEAR(got.u, b.x, 1e-12);
    EXPECT_NEAR(got.v, b.y, 1e-12);
    EXPECT_NEAR(std::hypot(got.ft_u, got.ft_v), 0.0, 1e-9 * exact);
  }
  EXPECT_NEAR(map.gap, plate_height, 1e-15);
  // The engine's own wall load (an independent sum) agrees.
  EXPECT_NEAR(s.wall_loads()[1].force[2], total, 1e-9 * total);

  // Rows: 5 samples per window, each the mean of its samples.
  fs::path dir = magbrush::testing::test_temp_dir("plate");
  std::vector<double> fn_samples;
  for (int k = 0; k < 10; ++k)
  {
    if (k > 0)
      s.step();
    m.sample(s);
    double f = 0.0;
    for (const auto &b : m.last_map().beads)
      f += b.fn;
    fn_samples.push_back(f);
  }
  ASSERT_EQ(m.rows().size(), 2u);
  for (int w = 0; w < 2; ++w)
  {
    const auto &r = m.rows()[static_cast<std::size_t>(w)];
    double mean = 0.0;
    for (int k = 0; k < 5; ++k)
      mean += fn_samples[static_cast<std::size_t>(5 * w + k)] / 5.0;
    EXPECT_NEAR(r.fn, mean, 1e-12 * mean);
    EXPECT_NEAR(r.fn, total, 1e-6 * total);
    EXPECT_DOUBLE_EQ(r.touching, 5.0);
    EXPECT_EQ(r.samples, 5);
  }
  m.write(dir.string());
  const auto rows = read_csv((dir / "plate_compression.csv").string());
  ASSERT_EQ(rows.size(), 2u);
  // time, length, B, Fn, Ftx, Fty, Ft, pn, pt, touching, density/mm², per bead, spacing, ratio
  const auto &r = rows[0];
  const double area_mm2 = lx * ly * 1e6, n = 5.0;
  EXPECT_NEAR(r[1], plate_height, 1e-12);
  EXPECT_NEAR(r[7], r[3] / (lx * ly), 1e-6 * r[7]);         // pressure
  EXPECT_NEAR(r[9], n, 1e-12);                              // touching
  EXPECT_NEAR(r[10], n / area_mm2, 1e-6);                   // 10 beads/mm²
  EXPECT_NEAR(r[11], r[3] / n, 1e-6 * r[11]);               // mean force per bead
  EXPECT_NEAR(r[12], std::sqrt(lx * ly / n), 1e-9 * r[12]); // l/√n
  // The contact map at the end carries the exact per-bead forces.
  const auto map_rows = read_csv((dir / "contact_map_000.csv").string());
  ASSERT_EQ(map_rows.size(), beads.size());
  for (const auto &row : map_rows)
  {
    const double exact = hertz_force(beads[static_cast<std::size_t>(row[0])]);
    EXPECT_NEAR(row[4], exact, 1e-6 * exact);
  }
  fs::remove_all(dir);
}

TEST(PlateCompression, SlidingPlateFeelsTheWallFrictionOnEveryBead)
{
  // The plate slides along +x at 1 m/s over beads too heavy to follow it (density 1e12 kg/m³:
  // the contact forces move them by < 1e-12 m). The Mindlin spring loads to the Coulomb limit
  // within ~30 steps, then every contact slides: |F_t| = μ_wall F_n exactly, against the
  // motion (the brush drags the plate backwards: F_t,x < 0 on the plate).
  const double density = 1e12;
  const std::string sliding = "    path:\n"
                              "      - {time: 0 s, displacement: [0, 0, 0]}\n"
                              "      - {time: 1 s, displacement: [1 m, 0, 0]}\n";
  const Case c = parse_case_text(scene(sliding, density), "column.yaml");
  DemSystem s(c);
  place_beads(s, density);
  PlateCompression m(c);
  for (int k = 0; k < 200; ++k)
    s.step();
  const PlateContactMap map = m.contact_map(s);
  ASSERT_EQ(map.beads.size(), beads.size());
  for (const auto &b : map.beads)
  {
    EXPECT_NEAR(std::hypot(b.ft_u, b.ft_v), 0.35 * b.fn, 1e-9 * b.fn) << "bead " << b.id;
    EXPECT_LT(b.ft_u, 0.0);
    EXPECT_NEAR(b.fn, hertz_force(beads[static_cast<std::size_t>(b.id)]), 1e-6 * b.fn);
  }
  EXPECT_NEAR(m.gap(s.time()), plate_height, 1e-15); // sliding keeps the brush length
}

TEST(PlateCompression, RowsCarryTheScheduledFieldAndThePlateGap)
{
  // Plate coming down 0.1 mm per µs: the gap is the path's, the field the schedule's.
  const std::string down = "    path:\n"
                           "      - {time: 0 s, displacement: [0, 0, 0]}\n"
                           "      - {time: 1 us, displacement: [0, 0, -0.1 mm]}\n";
  const Case c = parse_case_text(scene(down, 2200), "column.yaml");
  PlateCompression m(c);
  EXPECT_NEAR(m.gap(0.0), 1.0e-3, 1e-15);
  EXPECT_NEAR(m.gap(0.5e-6), 0.95e-3, 1e-15);
  EXPECT_NEAR(m.gap(2e-6), 0.9e-3, 1e-15); // held at the last path point
  DemSystem s(c);
  s.particles().add({0.5e-3, 0.25e-3, 0.5e-3}, 30e-6, 2200, 0, 0.0); // touches nothing
  s.initialize();
  const AppliedMagneticField field = AppliedMagneticField::from_settings(c.applied_field);
  double sum_b = 0.0, sum_gap = 0.0;
  for (int k = 0; k < 5; ++k)
  {
    s.step();
    m.sample(s);
    sum_b += field.field({0, 0, 0}, s.time())[2];
    sum_gap += 1.0e-3 - 0.1e-3 * s.time() / 1e-6;
  }
  ASSERT_EQ(m.rows().size(), 1u);
  EXPECT_NEAR(m.rows()[0].field, sum_b / 5, 1e-12);
  EXPECT_NEAR(m.rows()[0].gap, sum_gap / 5, 1e-15);
  EXPECT_DOUBLE_EQ(m.rows()[0].touching, 0.0);
  EXPECT_DOUBLE_EQ(m.rows()[0].fn, 0.0);
}

TEST(PlateCompression, SchemaDefaultsAgreeWithTheContractStruct)
{
  // A case that gives no `compression` section gets the struct's defaults from the schema.
  std::string text = scene(static_plate, 2200);
  text = text.substr(0, text.find("compression:\n"));
  const Case c = parse_case_text(text, "column.yaml");
  const CompressionSettings d;
  EXPECT_EQ(c.compression.plate, d.plate);
  EXPECT_EQ(c.compression.stage, d.stage);
  EXPECT_DOUBLE_EQ(c.compression.sample_interval, d.sample_interval);
  EXPECT_DOUBLE_EQ(c.compression.average_window, d.average_window);
  EXPECT_DOUBLE_EQ(c.compression.map_interval, d.map_interval);
  EXPECT_TRUE(AppliedField{}.schedule.empty());
}
