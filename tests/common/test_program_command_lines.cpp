// The command lines of the built programs: every subcommand's --help exits 0, `magbrush run`
// offers the stages' options, and an option of another stage is an error where it does not
// belong (magbrush-dem rejects the field solver's -np like any unknown option), and a mistyped
// option or subcommand gets a did-you-mean.
#include "common/child_process.h"

#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;

struct Result
{
  int status;
  std::string output; // stdout and stderr together
};

Result run(const std::vector<std::string> &command)
{
  const fs::path log = magbrush::testing::test_temp_dir("cli") / "output.log"; // removed at exit
  magbrush::ChildOutput output;
  output.stdout_path = log.string();
  output.stderr_to_stdout = true;
  Result r{magbrush::run_program(command, output), {}};
  std::ifstream in(log);
  std::ostringstream text;
  text << in.rdbuf();
  r.output = text.str();
  fs::remove(log);
  return r;
}

const std::string bin = std::string(MAGBRUSH_BINARY_DIR) + "/bin/";
const std::string nip_case = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_nip.yaml";

TEST(ProgramCommandLines, EverySubcommandHelpExitsZero)
{
  for (const char *command : {"check", "mesh", "field", "flux", "design", "dem", "report", "compare", "run", "sweep"})
  {
    const Result r = run({bin + "magbrush", command, "--help"});
    EXPECT_EQ(r.status, 0) << command << "\n" << r.output;
    EXPECT_NE(r.output.find(std::string("Usage: magbrush ") + command), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--help"), std::string::npos) << r.output;
    // One help format: every command ends with its examples, then its exit status.
    const auto example = r.output.find("\nExample"), exit_status = r.output.find("\nExit status: ");
    EXPECT_NE(example, std::string::npos) << command << ": no example\n" << r.output;
    EXPECT_NE(exit_status, std::string::npos) << command << ": no exit status\n" << r.output;
    EXPECT_LT(example, exit_status) << command;
    EXPECT_NE(r.output.find(std::string("\n  magbrush ") + command + " "), std::string::npos)
        << command << ": the example is not a command line of its own";
  }
  EXPECT_EQ(run({bin + "magbrush-dem", "--help"}).status, 0);
}

TEST(ProgramCommandLines, RunOffersTheOptionsOfItsStages)
{
  const Result r = run({bin + "magbrush", "run", "--help"});
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char *option : {"--only STAGE", "--skip STAGE", "--set key=value", "-np, --np N", "--force", "--no-vtu",
                             "--threads N", "--restart FILE"})
    EXPECT_NE(r.output.find(option), std::string::npos) << option << "\n" << r.output;
}

TEST(ProgramCommandLines, DemRejectsTheFieldSolversOptions)
{
  const Result r = run({bin + "magbrush-dem", nip_case, "-np", "2"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("magbrush-dem: unknown option '-np'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Usage: magbrush-dem CASE"), std::string::npos) << r.output;
  const Result wrapped = run({bin + "magbrush", "dem", nip_case, "--no-vtu"});
  EXPECT_EQ(wrapped.status, 2) << wrapped.output;
  EXPECT_NE(wrapped.output.find("magbrush dem: unknown option '--no-vtu'"), std::string::npos) << wrapped.output;
}

TEST(ProgramCommandLines, RunHandsEachStageOnlyItsOwnOptions)
{
  // check declares neither -np (field) nor --threads (dem): it must not receive them.
  const std::string out = (magbrush::testing::test_temp_dir("cli") / "run").string();
  const Result r = run({bin + "magbrush", "run", nip_case, "--only", "check", "-np", "2", "--threads", "3", "--force",
                        "-q", "--set", "output.directory=" + out});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("stage 1/5: check"), std::string::npos) << r.output;
  fs::remove_all(out);
}

TEST(ProgramCommandLines, TyposGetASuggestion)
{
  const Result r = run({bin + "magbrush", "run", nip_case, "--thraeds", "2"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("magbrush run: unknown option '--thraeds' (did you mean '--threads'?)"), std::string::npos)
      << r.output;
  // A mistyped subcommand gets the nearest one, and the list of commands.
  const Result command = run({bin + "magbrush", "rnu", nip_case});
  EXPECT_EQ(command.status, 2) << command.output;
  EXPECT_NE(command.output.find("magbrush: unknown command 'rnu' (did you mean 'run'?)"), std::string::npos)
      << command.output;
  EXPECT_NE(command.output.find("Commands:"), std::string::npos) << command.output;
  EXPECT_NE(run({bin + "magbrush", "chekc"}).output.find("(did you mean 'check'?)"), std::string::npos);
  // A case file given without a command gets the command that runs it.
  const Result file_first = run({bin + "magbrush", nip_case});
  EXPECT_EQ(file_first.status, 2) << file_first.output;
  EXPECT_NE(file_first.output.find("a case file comes after the command: magbrush run " + nip_case), std::string::npos)
      << file_first.output;
  // Nothing near: no suggestion.
  EXPECT_EQ(run({bin + "magbrush", "frobnicate"}).output.find("did you mean"), std::string::npos);
}

} // namespace
