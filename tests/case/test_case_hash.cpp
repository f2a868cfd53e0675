// Field hashes change when, and only when, an input of that field changes.
#include "case/case_hash.h"
#include "case/case_parser.h"

#include <gtest/gtest.h>

using namespace magbrush;

namespace {
const std::string full = std::string(MAGBRUSH_SOURCE_DIR) + "/tests/case/valid/full_roller.yaml";

struct Hashes
{
  std::string magnetic, electric;
};

Hashes hashes(const std::vector<std::string> &overrides = {})
{
  const Case c = load_case(full, overrides);
  return {field_hash(c, FieldKind::magnetic), field_hash(c, FieldKind::electric)};
}

// Which hashes an override changes: "", "magnetic", "electric" or "both".
std::string changed_by(const std::vector<std::string> &overrides)
{
  const Hashes a = hashes(), b = hashes(overrides);
  const bool m = a.magnetic != b.magnetic, e = a.electric != b.electric;
  return m && e ? "both" : m ? "magnetic" : e ? "electric" : "";
}
} // namespace

TEST(FieldHash, StableHexDigest)
{
  const Hashes a = hashes(), b = hashes();
  EXPECT_EQ(a.magnetic, b.magnetic);
  EXPECT_EQ(a.electric, b.electric);
  EXPECT_EQ(a.magnetic.size(), 16u);
  EXPECT_EQ(a.magnetic.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_NE(a.magnetic, a.electric);
}

TEST(FieldHash, ChangesOnlyWithTheInputsOfThatField)
{
  // run control, particles, materials, speeds: no field changes
  EXPECT_EQ(changed_by({"dem.time_step=5ns"}), "");
  EXPECT_EQ(changed_by({"dem.magnetic_cutoff=4"}), "");
  EXPECT_EQ(changed_by({"materials.carrier.mu_r=5"}), "");
  EXPECT_EQ(changed_by({"populations.toner.charge_to_mass=-20uC/g"}), "");
  EXPECT_EQ(changed_by({"sleeve.rpm=100rpm"}), "");
  EXPECT_EQ(changed_by({"drum.rpm=-10rpm"}), "");
  EXPECT_EQ(changed_by({"output.directory=elsewhere"}), "");
  EXPECT_EQ(changed_by({"field.output_dir=elsewhere"}), "");
  // roller: magnetic only
  EXPECT_EQ(changed_by({"roller.poles.N1.angle=5deg"}), "magnetic");
  EXPECT_EQ(changed_by({"roller.poles.S1.strength=-151kA/m"}), "magnetic");
  EXPECT_EQ(changed_by({"roller.magnet_mu_r=1.1"}), "magnetic");
  EXPECT_EQ(changed_by({"field.grid_radial_spacing=30um"}), "magnetic");
  EXPECT_EQ(changed_by({"field.probe_radius=10.5mm"}), "magnetic");
  // bias, image, drum, nip grid: electric only
  EXPECT_EQ(changed_by({"electric.bias=-600V"}), "electric");
  EXPECT_EQ(changed_by({"electric.image.period=2mm"}), "electric");
  EXPECT_EQ(changed_by({"drum.gap=0.4mm"}), "electric");
  EXPECT_EQ(changed_by({"drum.pc_eps_r=3.5"}), "electric");
  EXPECT_EQ(changed_by({"field.grid_electric_spacing=8um"}), "electric");
  // shared geometry and mesh: both
  EXPECT_EQ(changed_by({"sleeve.diameter=20.01mm"}), "both");
  EXPECT_EQ(changed_by({"field.element_degree=2"}), "both");
  // the magnetic doctor blade (mu_r 200) enters the roller field; the plain guide does not
  EXPECT_EQ(changed_by({"blades.doctor.gap=0.6mm"}), "magnetic");
  EXPECT_EQ(changed_by({"blades.guide.mu_r=1"}), "");
  EXPECT_EQ(changed_by({"blades.guide.material=carrier"}), "");
}

TEST(FieldHash, EquivalentSpellingsHashTheSame)
{
  EXPECT_EQ(changed_by({"sleeve.diameter=2 cm"}), "");
  EXPECT_EQ(changed_by({"drum.gap=0.35mm"}), "");
  EXPECT_EQ(changed_by({"roller.poles.N1.strength=0.15 MA/m"}), "");
  EXPECT_EQ(changed_by({"electric.bias=-0.5kV"}), "");
}

TEST(FieldHash, InputsAreListedWithFullPrecision)
{
  const Case c = load_case(full);
  bool found = false;
  for (const auto &[key, value] : field_inputs(c, FieldKind::electric))
    if (key == "drum.gap")
    {
      found = true;
      EXPECT_DOUBLE_EQ(std::stod(value), 350e-6);
    }
  EXPECT_TRUE(found);
  for (const auto &[key, value] : field_inputs(c, FieldKind::magnetic))
  {
    EXPECT_EQ(key.rfind("dem.", 0), std::string::npos) << key;
    EXPECT_EQ(key.rfind("blades.guide", 0), std::string::npos) << key;
  }
}
