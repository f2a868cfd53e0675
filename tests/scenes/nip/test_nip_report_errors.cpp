// `magbrush report` and `magbrush sweep` refuse bad input with messages that say what was
// expected, what was found and what to do.
#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <sys/wait.h>

namespace {

struct Result
{
  int status = -1;
  std::string output;
};

Result run(const std::string &args)
{
  const std::string cmd = std::string("'") + MAGBRUSH_BINARY_DIR + "/bin/magbrush' " + args + " 2>&1";
  Result r;
  FILE *p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buffer{};
  while (p && fgets(buffer.data(), buffer.size(), p))
    r.output += buffer.data();
  const int raw = p ? pclose(p) : -1;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

const std::string nip_case = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_nip.yaml";

} // namespace

TEST(NipReport, MissingDemOutputsAreAClearError)
{
  const auto dir = magbrush::testing::test_temp_dir("report_missing_outputs") / "out";
  const Result r = run("report '" + nip_case + "' --set output.directory=" + dir.string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("no DEM results for case 'kawamoto_nip'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find((dir / "dem" / "time_series.csv").string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("magbrush run"), std::string::npos) << r.output;
}

TEST(NipReport, UsageErrors)
{
  EXPECT_EQ(run("report").status, 2);
  EXPECT_EQ(run("report '" + nip_case + "' --bogus").status, 2);
  const Result help = run("report --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("index.html"), std::string::npos);
}

TEST(NipSweep, UsageErrors)
{
  const Result no_vary = run("sweep '" + nip_case + "'");
  EXPECT_EQ(no_vary.status, 2);
  const Result bad = run("sweep '" + nip_case + "' --vary drum.gap");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("--vary expects key=v1,v2"), std::string::npos) << bad.output;
  // A bad value is reported by the case validation, naming the key.
  const Result value = run("sweep '" + nip_case + "' --vary drum.gap=-1mm --set output.directory=" +
                            (magbrush::testing::test_temp_dir("sweep_bad") / "out").string());
  EXPECT_NE(value.status, 0);
  EXPECT_NE(value.output.find("drum.gap"), std::string::npos) << value.output;
}
