// Runs one of the project's programs (bin/magbrush, bin/magbrush-dem) the way a user does, for
// the end-to-end tests: its exit code and everything it printed (stdout and stderr together).
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace magbrush::testing {

struct CliResult
{
  int code = -1;      // the exit status (-1: did not exit normally)
  std::string output; // stdout and stderr
};

// `program` from the build's bin/ folder with `args` (quoted by the caller where needed), in
// `working_dir` when one is given (for outputs named relative to it).
inline CliResult run_program(const std::string &program, const std::string &args, const std::string &working_dir = "")
{
  const std::string cd = working_dir.empty() ? "" : "cd '" + working_dir + "' && ";
  const std::string cmd = cd + "'" + MAGBRUSH_BINARY_DIR + "/bin/" + program + "' " + args + " 2>&1";
  CliResult r;
  FILE *p = popen(cmd.c_str(), "r");
  if (!p)
    return r;
  char buf[4096];
  while (fgets(buf, sizeof buf, p))
    r.output += buf;
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

} // namespace magbrush::testing
