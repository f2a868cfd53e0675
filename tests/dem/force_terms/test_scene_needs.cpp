// "Skip what a scene doesn't need", asserted: each force term's rule
// (dem/force_terms/force_term_registry.h) turns it off, with the reason the log prints, when
// the scene gives it nothing to do —
//   no charged population (no toner)     → no Coulomb, no conductor images, no qE;
//   no electric field (bias 0, no image) → no qE;
//   a zero magnetic field                → no magnetic term (no dipole solve, no grid read);
//   a uniform field                      → the magnetic term reads no grid;
//   no Hamaker constant                  → the contact kernels run without adhesion;
// and a whole run's log says what was skipped and why. (Unchanged inputs → no remesh:
// tests/geometry/test_cmd_mesh.cpp; no re-field: tests/field_solver/test_field_app.cpp.)
#include "dem/dem_run.h"
#include "dem/force_terms/force_term_registry.h"
#include "tests/test_temp_dir.h"

#include "case/case_parser.h"
#include "fields/field_files.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <sstream>
#include <string>

namespace magbrush {
namespace {

namespace fs = std::filesystem;

const std::string cases_dir = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/";

// Each registered term's reason to be off for case c ("" = on), by name.
std::map<std::string, std::string> reasons(const Case &c)
{
  std::map<std::string, std::string> out;
  for (const auto &f : dem::force_term_factories())
    out[f.name] = f.not_needed_because(c);
  return out;
}

// Kweon's development scene with its toner taken out: the developer is carriers alone.
Case without_toner(Case c)
{
  std::vector<Population> kept;
  for (const auto &p : c.populations)
    if (p.kind != ParticleKind::toner)
      kept.push_back(p);
  c.populations = kept;
  return c;
}

TEST(SceneNeeds, TheTonerSceneRunsEveryElectricTerm)
{
  const auto on = reasons(load_case(cases_dir + "kweon_development.yaml"));
  for (const char *term : {"Coulomb", "conductor images", "applied electric field qE", "magnetic dipoles"})
    EXPECT_EQ(on.at(term), "") << term;
}

TEST(SceneNeeds, NoTonerNoCoulombNoImagesNoQE)
{
  const Case c = without_toner(load_case(cases_dir + "kweon_development.yaml"));
  ASSERT_FALSE(c.populations.empty());
  const auto off = reasons(c);
  EXPECT_EQ(off.at("Coulomb"), "no population is charged");
  EXPECT_EQ(off.at("conductor images"), "no population is charged");
  EXPECT_EQ(off.at("applied electric field qE"), "no population is charged");
  EXPECT_EQ(off.at("magnetic dipoles"), ""); // the carriers still feel the roller
}

TEST(SceneNeeds, NoElectricFieldNoQE)
{
  Case c = load_case(cases_dir + "kweon_development.yaml");
  ASSERT_EQ(reasons(c).at("applied electric field qE"), "");
  c.electric.bias = 0.0;
  ASSERT_NE(c.electric.image.kind, LatentImage::Kind::none);
  EXPECT_EQ(reasons(c).at("applied electric field qE"), "") << "a latent image alone is a field";
  c.electric.image.kind = LatentImage::Kind::none;
  EXPECT_EQ(reasons(c).at("applied electric field qE"),
            "the electric field is zero (electric.bias = 0 V and no latent image)");
  // The charges still act on each other and on their images: those terms stay on.
  EXPECT_EQ(reasons(c).at("Coulomb"), "");
  c.electric.bias = -300.0;
  EXPECT_EQ(reasons(c).at("applied electric field qE"), "");
}

TEST(SceneNeeds, ZeroMagneticFieldNoMagneticSolve)
{
  Case box = load_case(cases_dir + "kawamoto_brush_compression.yaml");
  ASSERT_EQ(reasons(box).at("magnetic dipoles"), "");
  box.applied_field.schedule = {{0.0, 0.0}, {3e-4, 0.0}};
  box.applied_field.uniform_magnitude = 0.0; // (the parser sets it to the schedule's peak)
  EXPECT_EQ(reasons(box).at("magnetic dipoles"),
            "the applied uniform field is zero (applied_field.magnitude and every schedule value are 0 T)");

  Case roller = load_case(cases_dir + "kweon_full_roller.yaml");
  ASSERT_EQ(reasons(roller).at("magnetic dipoles"), "");
  for (auto &p : roller.roller->poles)
    p.strength = 0.0;
  EXPECT_EQ(reasons(roller).at("magnetic dipoles"), "every pole of the roller has zero strength (the roller field is zero)");
}

// A uniform field is evaluated in closed form: the term is built and computes forces with no
// field grid anywhere (a roller field would throw on the missing grid).
TEST(SceneNeeds, UniformFieldReadsNoGrid)
{
  const fs::path empty = testing::test_temp_dir("scene_needs_no_grid");
  Case c = load_case(cases_dir + "kawamoto_brush_compression.yaml",
                     {"field.output_dir=" + empty.string(), "populations.carrier.count=40"});
  ASSERT_FALSE(fs::exists(field::magnetic_grid_path(c)));
  dem::DemSystem system(c);
  const auto choices = dem::add_case_force_terms(system, c);
  bool magnetic_on = false;
  for (const auto &choice : choices)
    magnetic_on = magnetic_on || (choice.name == "magnetic dipoles" && choice.on);
  ASSERT_TRUE(magnetic_on);
  system.insert_particles();
  EXPECT_NO_THROW(system.initialize());
  EXPECT_NO_THROW(system.advance(10));
  EXPECT_TRUE(fs::is_empty(empty)) << "something was written into the field directory";

  Case roller = load_case(cases_dir + "kweon_full_roller.yaml", {"field.output_dir=" + empty.string()});
  dem::DemSystem other(roller);
  EXPECT_THROW(dem::add_case_force_terms(other, roller), std::exception) << "a roller field needs its grid";
}

// The contact table of a scene without Hamaker constants has no adhesion (the kernels take
// their non-adhesive instantiation and the neighbour list reaches no further than contact).
TEST(SceneNeeds, NoHamakerConstantNoAdhesion)
{
  const Case box = load_case(cases_dir + "kawamoto_brush_compression.yaml", {"populations.carrier.count=40"});
  dem::DemSystem system(box);
  system.insert_particles();
  system.initialize();
  EXPECT_FALSE(system.contact_table().adhesive());
  EXPECT_FALSE(system.contact_table().particles_adhesive());
  EXPECT_NE(system.contact_table().describe().find("adhesion: off (no pair of materials has a Hamaker constant)"),
            std::string::npos);
}

// What a user reads: the run's log lists the terms on, and each term off with its reason.
TEST(SceneNeeds, TheLogSaysWhatWasSkippedAndWhy)
{
  const fs::path dir = testing::test_temp_dir("scene_needs_log");
  const Case c = load_case(cases_dir + "kawamoto_brush_compression.yaml",
                           {"populations.carrier.count=40", "dem.duration=0.2us", "output.directory=" + dir.string(),
                            "dem.air_viscosity=0"});
  std::ostringstream log;
  dem::DemRun run(c, dem::RunOptions{}, log);
  run.run();
  const std::string text = log.str();
  for (const char *line : {"force terms on: contacts, gravity, magnetic dipoles\n",
                           "force term off: Stokes drag (dem.air_viscosity is zero)\n",
                           "force term off: applied electric field qE (the case has no enabled electric section)\n",
                           "force term off: Coulomb (no population is charged)\n",
                           "adhesion: off (no pair of materials has a Hamaker constant)",
                           "applied magnetic field: uniform, |B| up to 0.13 T, in closed form (no grid lookups)\n"})
    EXPECT_NE(text.find(line), std::string::npos) << "missing: " << line << "\n" << text;
}

} // namespace
} // namespace magbrush
