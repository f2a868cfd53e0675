// The production field stage end to end (bin/magbrush-field on a paper case, coarse mesh):
// the first run stores both fields; an unchanged case is "up to date" and rewrites nothing;
// moving a pole regenerates only the magnetic field; changing the bias only the electric one; a
// solid area is stored as one phase.
#include "fields/cartesian_field_interpolator.h"
#include "fields/field_grid.h"

#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

const std::string out_dir = (magbrush::testing::test_temp_dir("field_app") / "out").string();

// The case with its 1 mm lines (an image that moves with the drum) instead of its solid area.
const std::string striped = "--set electric.image.period=2mm --set electric.image.duty=0.5 "
                            "--set development.block_length=0m ";

// The case's own mesh settings: a coarser nip mesh makes the field stage slower, not faster
// (the continuation into the conductors searches anchors its polygonal cells miss).
std::string run_field(const std::string &extra, int &rc, const std::string &lines = striped)
{
  const std::string log = out_dir + ".log";
  const std::string command =
    std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush-field " + MAGBRUSH_SOURCE_DIR +
    "/cases/kweon_development.yaml --no-vtu --set field.output_dir=" + out_dir + " " + lines + extra + " > " +
    log + " 2>&1";
  rc = std::system(command.c_str());
  std::ifstream in(log);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

} // namespace

TEST(FieldApp, StoresFieldsAndReusesThemUntilTheirInputsChange)
{
  fs::remove_all(out_dir);
  int rc = 0;
  const std::string first = run_field("", rc);
  ASSERT_EQ(rc, 0) << first;
  const std::string magnetic = out_dir + "/kweon_development_magnetic.h5";
  const std::string electric = out_dir + "/kweon_development_electric.h5";
  ASSERT_TRUE(fs::exists(magnetic)) << first;
  ASSERT_TRUE(fs::exists(electric)) << first;
  ASSERT_TRUE(fs::exists(out_dir + "/kweon_development_profile_sleeve.csv"));

  // The stored magnetic grid carries its case hash and a small error against the exact ring.
  const auto m = magbrush::read_magnetic_grid(magnetic);
  EXPECT_EQ(m.info.kind, "magnetic");
  EXPECT_FALSE(m.info.provenance.case_hash.empty());
  EXPECT_LT(m.info.provenance.error_estimate, 0.05);
  const auto e = magbrush::read_electric_grid(electric);
  // The bias solution is the bias on the sleeve surface (10 mm radius, the drum on +x), the
  // image is stored at field.electric_phase_samples phases of its 2 mm period.
  const magbrush::CartesianFieldInterpolator bias(e.grid.bias);
  EXPECT_NEAR(bias.potential({10e-3, 0.0, 0.0}), -650.0, 0.5);
  EXPECT_NEAR(bias.potential({10e-3 * std::cos(0.1), 10e-3 * std::sin(0.1), 0.0}), -650.0, 0.5);
  EXPECT_EQ(e.grid.phase_samples(), 16);
  EXPECT_DOUBLE_EQ(e.grid.image_period, 2e-3);
  EXPECT_DOUBLE_EQ(e.grid.drum_radius, 15e-3);

  const auto m_time = fs::last_write_time(magnetic), e_time = fs::last_write_time(electric);
  const std::string again = run_field("", rc);
  ASSERT_EQ(rc, 0) << again;
  EXPECT_NE(again.find("magnetic field up to date"), std::string::npos) << again;
  EXPECT_NE(again.find("electric field up to date"), std::string::npos) << again;
  EXPECT_EQ(fs::last_write_time(magnetic), m_time);
  EXPECT_EQ(fs::last_write_time(electric), e_time);

  const std::string moved = run_field("--set roller.poles.N1.angle=75deg", rc);
  ASSERT_EQ(rc, 0) << moved;
  EXPECT_NE(moved.find("computing the magnetic field"), std::string::npos) << moved;
  EXPECT_NE(moved.find("electric field up to date"), std::string::npos) << moved;

  const std::string biased = run_field("--set roller.poles.N1.angle=75deg --set electric.bias=-700V", rc);
  ASSERT_EQ(rc, 0) << biased;
  EXPECT_NE(biased.find("magnetic field up to date"), std::string::npos) << biased;
  EXPECT_NE(biased.find("computing the electric field"), std::string::npos) << biased;

  // The case's own solid area is the same at every phase of the drum: one solve, no period.
  const std::string solid = run_field("--only electric", rc, "");
  ASSERT_EQ(rc, 0) << solid;
  const auto s = magbrush::read_electric_grid(electric);
  EXPECT_EQ(s.grid.phase_samples(), 1);
  EXPECT_EQ(s.grid.image_period, 0.0);
  fs::remove_all(out_dir);
}

// A zero nip field (no bias, both image potentials 0) is not solved, and not stored: the DEM's
// qE term is off for it (tests/dem/force_terms/test_scene_needs.cpp).
TEST(FieldApp, ZeroElectricFieldIsNotSolved)
{
  fs::remove_all(out_dir);
  int rc = 0;
  const std::string log = run_field("--only electric --set electric.bias=0V --set electric.image.dark_potential=0V "
                                    "--set electric.image.light_potential=0V",
                                    rc);
  ASSERT_EQ(rc, 0) << log;
  EXPECT_NE(log.find("electric field: skipped, it is zero"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(out_dir + "/kweon_development_electric.h5"));
}
