// The folder a run writes into when its case names none (case/run_folder.h): named after
// the case and a digest of its overrides, so that variants land side by side and never in
// each other's folder, while the stored fields stay shared by the variants that do not
// change them (the field stage then finds them by their input hash and solves nothing).
#include "case/case_parser.h"
#include "case/run_folder.h"

#include <gtest/gtest.h>

#include <string>

using namespace magbrush;

namespace {
const std::string minimal = std::string(MAGBRUSH_SOURCE_DIR) + "/tests/case/valid/minimal_roller.yaml";
} // namespace

TEST(RunFolder, TheCaseAloneWritesIntoAFolderNamedAfterIt)
{
  const Case c = load_case(minimal);
  EXPECT_TRUE(c.output.automatic);
  EXPECT_EQ(c.output.directory, "results/minimal_roller");
  EXPECT_EQ(c.field.output_dir, "results/minimal_roller/fields");
  EXPECT_TRUE(c.output.overrides.empty());
}

TEST(RunFolder, TwoVariantsLandInTwoFoldersAndTheSameOverridesInAnyOrderInOne)
{
  const Case a = load_case(minimal, {"dem.seed=2"});
  const Case b = load_case(minimal, {"dem.seed=3"});
  EXPECT_NE(a.output.directory, b.output.directory);
  EXPECT_NE(a.output.directory, load_case(minimal).output.directory);
  // results/minimal_roller-<6 hex digits>
  const std::string prefix = "results/minimal_roller-";
  ASSERT_EQ(a.output.directory.rfind(prefix, 0), 0u) << a.output.directory;
  const std::string digest = a.output.directory.substr(prefix.size());
  EXPECT_EQ(digest.size(), 6u);
  EXPECT_EQ(digest.find_first_not_of("0123456789abcdef"), std::string::npos) << digest;

  // Order and spaces around '=' do not make another variant; a repeated key counts once (the last).
  const Case ab = load_case(minimal, {"dem.seed=2", "drum.gap=0.3mm"});
  const Case ba = load_case(minimal, {"drum.gap= 0.3mm", "dem.seed=2"});
  const Case again = load_case(minimal, {"dem.seed=7", "drum.gap=0.3mm", "dem.seed=2"});
  EXPECT_EQ(ab.output.directory, ba.output.directory);
  EXPECT_EQ(ab.output.directory, again.output.directory);
  EXPECT_EQ(ab.output.overrides, (std::vector<std::string>{"dem.seed=2", "drum.gap=0.3mm"}));
}

TEST(RunFolder, AVariantOfDemKeysReadsItsBaselinesFieldsAFieldVariantItsOwn)
{
  const Case base = load_case(minimal);
  const Case seed = load_case(minimal, {"dem.seed=2"});
  EXPECT_EQ(seed.field.output_dir, base.field.output_dir) << "a DEM-only variant must find the stored fields";
  const Case gap = load_case(minimal, {"drum.gap=0.3mm"});
  EXPECT_NE(gap.field.output_dir, base.field.output_dir);
  EXPECT_EQ(gap.field.output_dir, gap.output.directory + "/fields");
  // Both kinds at once: the fields are the field variant's (named by the gap alone).
  const Case both = load_case(minimal, {"drum.gap=0.3mm", "dem.seed=2"});
  EXPECT_EQ(both.field.output_dir, gap.field.output_dir);
  EXPECT_NE(both.output.directory, gap.output.directory);
}

TEST(RunFolder, AFolderTheUserNamesIsTakenAsItIs)
{
  const Case c = load_case(minimal, {"output.directory=runs/mine", "dem.seed=2"});
  EXPECT_FALSE(c.output.automatic);
  EXPECT_EQ(c.output.directory, "runs/mine");
  EXPECT_EQ(c.field.output_dir, "runs/mine/fields");
}

TEST(RunFolder, VariantTextListsTheCaseAndTheOverrides)
{
  const std::string text = variant_text("cases/a.yaml", normalised_overrides({"b=2", "a = 1"}));
  EXPECT_NE(text.find("case cases/a.yaml\nset a=1\nset b=2\n"), std::string::npos) << text;
  EXPECT_EQ(overrides_digest({}), overrides_digest(normalised_overrides({})));
  EXPECT_NE(overrides_digest({"a=1"}), overrides_digest({"a=2"}));
}
