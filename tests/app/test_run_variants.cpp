// `magbrush run` as a first-hour user meets it (check stage only: a second):
//  * two variants of one case land in two folders, named after the case and a digest of the
//    overrides, each with its variant.txt and the whole resolved case;
//  * --quick scales the run's duration and every averaging window and spin-up by one factor,
//    says what it changed, and the shortened case still passes `check`;
//  * the case is printed in ten lines, not the ~230 of the resolved case.
#include "app/quick_preset.h"
#include "case/case_parser.h"
#include "tests/cli_run.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace magbrush;

namespace {
const std::string fed_case = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_nip_fed.yaml";

// `magbrush run CASE <args> --only check` in `dir`: its exit status and what it printed.
magbrush::testing::CliResult run_check_stage(const fs::path &dir, const std::string &args)
{
  return magbrush::testing::run_program("magbrush", "run '" + fed_case + "' --only check " + args, dir.string());
}

std::string file_text(const fs::path &path)
{
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

int count_lines(const std::string &s, const std::string &from, const std::string &to)
{
  const auto a = s.find(from), b = s.find(to, a);
  if (a == std::string::npos || b == std::string::npos)
    return -1;
  int n = 0;
  for (auto k = a; k < b; ++k)
    n += s[k] == '\n';
  return n;
}
} // namespace

TEST(RunVariants, TwoVariantsLandInTwoFoldersEachSayingWhatItHolds)
{
  const fs::path dir = magbrush::testing::test_temp_dir("run_variants");
  const magbrush::testing::CliResult base = run_check_stage(dir, "");
  const magbrush::testing::CliResult seed = run_check_stage(dir, "--set dem.seed=2");
  const magbrush::testing::CliResult gap = run_check_stage(dir, "--set drum.gap=0.5mm");
  ASSERT_EQ(base.code, 0) << base.output;
  ASSERT_EQ(seed.code, 0) << seed.output;
  ASSERT_EQ(gap.code, 0) << gap.output;

  const Case c_seed = load_case(fed_case, {"dem.seed=2"}), c_gap = load_case(fed_case, {"drum.gap=0.5mm"});
  const fs::path f_base = dir / "results" / "kawamoto_nip_fed", f_seed = dir / c_seed.output.directory,
                 f_gap = dir / c_gap.output.directory;
  EXPECT_NE(f_seed, f_gap);
  for (const fs::path &f : {f_base, f_seed, f_gap})
  {
    EXPECT_TRUE(fs::exists(f / "case_resolved.txt")) << f;
    EXPECT_TRUE(fs::exists(f / "variant.txt")) << f;
  }
  EXPECT_NE(file_text(f_seed / "variant.txt").find("set dem.seed=2\n"), std::string::npos);
  EXPECT_NE(file_text(f_gap / "variant.txt").find("set drum.gap=0.5mm\n"), std::string::npos);
  EXPECT_NE(file_text(f_gap / "case_resolved.txt").find("drum.gap"), std::string::npos);
  // A DEM-only variant reads the baseline's stored fields; a field variant has its own.
  EXPECT_EQ(c_seed.field.output_dir, "results/kawamoto_nip_fed/fields");
  EXPECT_EQ(c_gap.field.output_dir, c_gap.output.directory + "/fields");

  // The terminal gets ten lines of the case, and where the rest is.
  EXPECT_EQ(count_lines(seed.output, "  case ", "== magbrush run: done"), 11) << seed.output; // 10 + the blank line
  EXPECT_NE(seed.output.find("full case  " + c_seed.output.directory + "/case_resolved.txt"), std::string::npos)
      << seed.output;
  EXPECT_EQ(seed.output.find("materials.carrier.youngs_modulus"), std::string::npos) << "the whole case was printed";
}

TEST(RunQuick, ScalesTheDurationAndEveryWindowTogetherAndSaysSo)
{
  const Case c = load_case(fed_case);
  const auto changes = quick_preset(c);
  ASSERT_FALSE(changes.empty());
  const double f = quick_duration / c.dem.duration;
  bool duration = false, nip = false, flow = false;
  for (const auto &q : changes)
  {
    EXPECT_NEAR(q.to, q.from * f, 1e-15) << q.key;
    duration = duration || q.key == "dem.duration";
    nip = nip || q.key == "nip.average_from";
    flow = flow || q.key == "flow_report.average_from";
  }
  EXPECT_TRUE(duration && nip && flow);

  // The shortened case is valid: every window still inside the run.
  std::vector<std::string> overrides;
  for (const auto &q : changes)
    overrides.push_back(q.override_text());
  const Case quick = load_case(fed_case, overrides);
  EXPECT_NEAR(quick.dem.duration, quick_duration, 1e-12);
  EXPECT_NEAR(quick.nip.average_from / quick.dem.duration, c.nip.average_from / c.dem.duration, 1e-5);
  // A case already as short is left alone.
  EXPECT_TRUE(quick_preset(quick).empty());

  // On the command line: what it changed, then the run in its own folder.
  const fs::path dir = magbrush::testing::test_temp_dir("run_quick");
  const magbrush::testing::CliResult o = run_check_stage(dir, "--quick");
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_NE(o.output.find("dem.duration               75 ms -> 5 ms"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("nip.average_from           25 ms -> 1.66667 ms"), std::string::npos) << o.output;
  EXPECT_TRUE(fs::exists(dir / quick.output.directory / "variant.txt")) << quick.output.directory;
  EXPECT_NE(quick.output.directory, c.output.directory);
}

TEST(RunQuick, SaysThatAPlatesProtocolIsNotScaled)
{
  const Case c = load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_brush_compression.yaml");
  const auto changes = quick_preset(c);
  ASSERT_FALSE(changes.empty());
  EXPECT_NE(quick_caveats(c, changes).find("is not scaled"), std::string::npos) << quick_caveats(c, changes);
  EXPECT_EQ(quick_caveats(load_case(fed_case), quick_preset(load_case(fed_case))), "");
}

TEST(RunQuick, AWindowBeyondTheRunIsStillRefused)
{
  // Without --quick a short duration leaves the case's windows beyond the run: `run` stops at
  // `check`, naming both keys, before any stage spends time.
  const fs::path dir = magbrush::testing::test_temp_dir("run_quick_refused");
  const magbrush::testing::CliResult o = run_check_stage(dir, "--set dem.duration=0.5ms");
  EXPECT_EQ(o.code, 1) << o.output;
  EXPECT_NE(o.output.find("nip.average_from"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("dem.duration"), std::string::npos) << o.output;
}

TEST(RunQuick, TheFoldersTheReadmeNamesAreTheOnesTheRunsWriteTo)
{
  // README's first hour compares two quick runs by their folders: the digests of the quick
  // preset's overrides (and a 0.5 mm gap), and a moved pole's flux by the folder named after
  // its variant. A change of the preset or the digest changes them.
  std::vector<std::string> quick;
  for (const auto &q : quick_preset(load_case(fed_case)))
    quick.push_back(q.override_text());
  std::vector<std::string> gap = quick;
  gap.push_back("drum.gap=0.5mm");
  const std::string base = load_case(fed_case, quick).output.directory, wide = load_case(fed_case, gap).output.directory;
  std::ifstream in(std::string(MAGBRUSH_SOURCE_DIR) + "/README.md");
  std::ostringstream readme;
  readme << in.rdbuf();
  EXPECT_NE(readme.str().find("magbrush compare " + base + " " + wide), std::string::npos)
      << "README's compare line should read: magbrush compare " << base << " " << wide;
  EXPECT_NE(readme.str().find(base + "/report/index.html"), std::string::npos) << base;
  // And the folder `flux --compare` writes the moved pole's comparison into.
  const Case moved = load_case(fed_case, {"roller.poles.S1.angle=5deg"});
  const std::string flux = load_case(fed_case).output.directory + "/flux/compare_" +
                           fs::path(moved.output.directory).filename().string() + "/";
  EXPECT_NE(readme.str().find(flux), std::string::npos) << "README should name " << flux;
}
