// run_program() of common/child_process.h: arguments arrive verbatim (no shell reads them),
// exit codes come back, output can go to a file, and failures say what happened.
#include "common/child_process.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using magbrush::ChildOutput;
using magbrush::ChildProcessError;
using magbrush::run_program;

class ChildProcess : public ::testing::Test
{
protected:
  fs::path dir = fs::temp_directory_path() / ("magbrush_child_process_" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }

  static std::string read(const fs::path &path)
  {
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }
};

TEST_F(ChildProcess, ArgumentsArriveVerbatim)
{
  // The shell here only prints its arguments; the words themselves never pass through one.
  const std::vector<std::string> words = {"two words", "it's \"quoted\"", "$HOME and $(ls)", "a; rm -rf x",
                                          "line one\nline two", "back\\slash", "*", ""};
  std::vector<std::string> command = {"/bin/sh", "-c", "for a in \"$@\"; do printf '[%s]\\n' \"$a\"; done", "sh"};
  command.insert(command.end(), words.begin(), words.end());
  ChildOutput output;
  output.stdout_path = (dir / "out.txt").string();
  EXPECT_EQ(run_program(command, output), 0);
  std::string expected;
  for (const auto &w : words)
    expected += "[" + w + "]\n";
  EXPECT_EQ(read(dir / "out.txt"), expected);
}

TEST_F(ChildProcess, ExitCodesComeBack)
{
  EXPECT_EQ(run_program({"/bin/sh", "-c", "exit 0"}), 0);
  EXPECT_EQ(run_program({"/bin/sh", "-c", "exit 3"}), 3);
  EXPECT_EQ(run_program({"false"}), 1); // found on the PATH
}

TEST_F(ChildProcess, StdoutAndStderrToFiles)
{
  ChildOutput both;
  both.stdout_path = (dir / "both.log").string();
  both.stderr_to_stdout = true;
  EXPECT_EQ(run_program({"/bin/sh", "-c", "echo out; echo err >&2"}, both), 0);
  EXPECT_EQ(read(dir / "both.log"), "out\nerr\n");

  ChildOutput apart;
  apart.stdout_path = (dir / "out.log").string();
  apart.stderr_path = (dir / "err.log").string();
  EXPECT_EQ(run_program({"/bin/sh", "-c", "echo out; echo err >&2; exit 4"}, apart), 4);
  EXPECT_EQ(read(dir / "out.log"), "out\n");
  EXPECT_EQ(read(dir / "err.log"), "err\n");
}

TEST_F(ChildProcess, AMissingProgramIsAClearError)
{
  try
  {
    run_program({"/no/such/program", "x"});
    FAIL() << "no error";
  }
  catch (const ChildProcessError &e)
  {
    EXPECT_EQ(std::string(e.what()), "cannot run '/no/such/program': No such file or directory");
  }
  EXPECT_THROW(run_program({"magbrush-no-such-program-on-the-path"}), ChildProcessError);
  EXPECT_FALSE(magbrush::program_exists("magbrush-no-such-program-on-the-path"));
  EXPECT_TRUE(magbrush::program_exists("sh"));
  EXPECT_TRUE(magbrush::program_exists("/bin/sh"));
}

TEST_F(ChildProcess, AnUnwritableOutputFileIsNamed)
{
  ChildOutput output;
  output.stdout_path = (dir / "no_such_folder" / "out.log").string();
  try
  {
    run_program({"/bin/true"}, output);
    FAIL() << "no error";
  }
  catch (const ChildProcessError &e)
  {
    EXPECT_NE(std::string(e.what()).find(output.stdout_path), std::string::npos) << e.what();
  }
}

TEST_F(ChildProcess, KilledBySignalIsAnError)
{
  try
  {
    run_program({"/bin/sh", "-c", "kill -TERM $$"});
    FAIL() << "no error";
  }
  catch (const ChildProcessError &e)
  {
    EXPECT_NE(std::string(e.what()).find("killed by signal 15"), std::string::npos) << e.what();
  }
}

// For callers that only report a failure: the reason as text, empty on success.
TEST_F(ChildProcess, AFailureComesBackAsItsReason)
{
  EXPECT_EQ(magbrush::run_program_failure({"/bin/sh", "-c", "exit 0"}), "");
  EXPECT_EQ(magbrush::run_program_failure({"/bin/sh", "-c", "exit 3"}), "exit 3");
  EXPECT_EQ(magbrush::run_program_failure({"/no/such/program"}),
            "cannot run '/no/such/program': No such file or directory");
  EXPECT_NE(magbrush::run_program_failure({"/bin/sh", "-c", "kill -TERM $$"}).find("killed by signal 15"),
            std::string::npos);
}

} // namespace
