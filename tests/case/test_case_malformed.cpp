// THE BAD-INPUT COLLECTION: every tests/case/malformed/*.yaml is given to the real
// `magbrush check` in a subprocess (with a time limit). Each must end with exit code 1 (no
// crash, no hang) and print the fragments listed in its "# expect: ..." lines (file:line:col,
// key path, expected/found). "# args: ..." lines add command-line arguments. A few inputs
// that cannot live in the repository (empty, binary, directory, missing, huge, deep) are
// generated here.
#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

const std::string binary = std::string(MAGBRUSH_BINARY_DIR) + "/bin/magbrush";
const std::string malformed_dir = std::string(MAGBRUSH_SOURCE_DIR) + "/tests/case/malformed";

struct CheckRun
{
  int exit_code = -1; // -1: killed by a signal
  int signal = 0;
  std::string output; // stdout + stderr
};

std::string quote(const std::string &s)
{
  std::string q = "'";
  for (char c : s)
    q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

CheckRun run_check(const std::vector<std::string> &args)
{
  const fs::path out = magbrush::testing::test_temp_dir("check") / "output.txt";
  std::string command = "timeout -s KILL 30 " + quote(binary) + " check";
  for (const auto &a : args)
    command += " " + quote(a);
  command += " > " + quote(out.string()) + " 2>&1";
  const int status = std::system(command.c_str());
  CheckRun r;
  if (WIFEXITED(status))
  {
    r.exit_code = WEXITSTATUS(status);
    // the shell reports a child killed by signal s as 128 + s
    if (r.exit_code > 128)
    {
      r.signal = r.exit_code - 128;
      r.exit_code = -1;
    }
  }
  else if (WIFSIGNALED(status))
    r.signal = WTERMSIG(status);
  std::ifstream in(out);
  std::stringstream s;
  s << in.rdbuf();
  r.output = s.str();
  fs::remove(out);
  return r;
}

void expect_invalid(const CheckRun &r, const std::vector<std::string> &fragments)
{
  EXPECT_EQ(r.signal, 0) << "killed by signal " << r.signal << " (9 = time limit)\n" << r.output;
  EXPECT_EQ(r.exit_code, 1) << r.output;
  for (const auto &f : fragments)
    EXPECT_NE(r.output.find(f), std::string::npos) << "missing '" << f << "' in:\n" << r.output;
}

fs::path scratch()
{
  return magbrush::testing::test_temp_dir("case_test");
}

} // namespace

TEST(MalformedCases, EveryFileFailsCleanlyWithItsMessages)
{
  ASSERT_TRUE(fs::exists(binary)) << binary;
  int n = 0;
  for (const auto &entry : fs::directory_iterator(malformed_dir))
  {
    if (entry.path().extension() != ".yaml")
      continue;
    ++n;
    SCOPED_TRACE(entry.path().filename().string());
    std::vector<std::string> args{entry.path().string()}, fragments;
    std::ifstream in(entry.path());
    for (std::string line; std::getline(in, line);)
    {
      if (line.rfind("# expect: ", 0) == 0)
        fragments.push_back(line.substr(10));
      if (line.rfind("# args: ", 0) == 0)
      {
        std::istringstream words(line.substr(8));
        for (std::string w; words >> w;)
          args.push_back(w);
      }
    }
    EXPECT_FALSE(fragments.empty()) << "no '# expect:' lines";
    expect_invalid(run_check(args), fragments);
  }
  EXPECT_GE(n, 50);
}

TEST(MalformedCases, GeneratedInputs)
{
  const fs::path dir = scratch();
  const auto write = [&](const std::string &name, const std::string &content) {
    std::ofstream(dir / name, std::ios::binary) << content;
    return (dir / name).string();
  };
  expect_invalid(run_check({write("empty.yaml", "")}), {"empty.yaml", "the file is empty"});
  expect_invalid(run_check({write("blank.yaml", "\n  \n# only a comment\n")}), {"blank.yaml"});

  std::mt19937 rng(42);
  std::string garbage(4096, '\0');
  for (auto &c : garbage)
    c = static_cast<char>(rng() & 0xFF);
  expect_invalid(run_check({write("garbage.yaml", garbage)}), {"garbage.yaml", "not a text file"});
  expect_invalid(run_check({write("latin1.yaml", "sleeve:\n  radius: 10 \xB5m\n")}),
                 {"latin1.yaml:2:14", "not UTF-8"});

  fs::create_directories(dir / "a_directory.yaml");
  expect_invalid(run_check({(dir / "a_directory.yaml").string()}), {"a_directory.yaml", "is a directory"});
  expect_invalid(run_check({(dir / "missing.yaml").string()}), {"missing.yaml", "no such file"});

  expect_invalid(run_check({write("deep.yaml", "a: " + std::string(100000, '[') + std::string(100000, ']') + "\n")}),
                 {"deep.yaml:1:", "nested"});
  expect_invalid(run_check({write("deep_map.yaml", "sleeve: " + std::string(5000, '{') + "\n")}), {"deep_map.yaml:"});

  std::string huge = "sleeve:\n  radius: 10 mm\n";
  while (huge.size() < (5u << 20))
    huge += "# padding padding padding padding padding padding padding padding padding\n";
  expect_invalid(run_check({write("huge.yaml", huge)}), {"huge.yaml", "limit"});

  std::string many_keys = "sleeve:\n  radius: 10 mm\n";
  for (int i = 0; i < 20000; ++i)
    many_keys += "k" + std::to_string(i) + ": 1\n";
  expect_invalid(run_check({write("many_keys.yaml", many_keys)}), {"many_keys.yaml:3:1", "unknown key 'k0'",
                                                                  "stopped after 50 errors"});
  fs::remove_all(dir);
}

TEST(MalformedCases, UsageErrorsExitWith2)
{
  EXPECT_EQ(run_check({}).exit_code, 2);
  EXPECT_EQ(run_check({"--bogus"}).exit_code, 2);
  EXPECT_EQ(run_check({"a.yaml", "b.yaml"}).exit_code, 2);
  EXPECT_EQ(run_check({"a.yaml", "--set"}).exit_code, 2);
  const CheckRun help = run_check({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("--set key=value"), std::string::npos);
}

TEST(MalformedCases, ValidCasesExitWith0AndPrintUnits)
{
  const CheckRun r = run_check({std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_nip.yaml"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("drum.gap"), std::string::npos);
  EXPECT_NE(r.output.find("= 400 um"), std::string::npos);
  EXPECT_NE(r.output.find("relative speed at the nip   0.134827 m/s"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("in the same direction"), std::string::npos);
  const CheckRun inputs = run_check({std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_nip.yaml", "--inputs", "electric"});
  EXPECT_EQ(inputs.exit_code, 0);
  EXPECT_NE(inputs.output.find("drum.gap = 0.000399999"), std::string::npos) << inputs.output;
  EXPECT_EQ(inputs.output.find("roller."), std::string::npos) << inputs.output;
  EXPECT_EQ(run_check({"x.yaml", "--inputs", "thermal"}).exit_code, 2);
}
