// Starting another program and waiting for it, without a shell.
//
//   const int status = run_program({"python3", script, "--out", folder});
//
// The arguments are handed to the program as they are — a space, a quote, a `$` or a `;` in
// a file name is just a character — because no shell ever reads them. There is nothing to
// quote and nothing a file name could inject.
//
// Its output goes where the parent's goes, unless told otherwise:
//
//   ChildOutput to_log;
//   to_log.stdout_path = "solver.log";   // like `> solver.log`
//   to_log.stderr_to_stdout = true;      // like `2>&1`
//   run_program({solver, case_file}, to_log);
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace magbrush {

// Where the child's standard output and error go.
struct ChildOutput
{
  std::string stdout_path;       // empty: the parent's stdout; else this file (truncated)
  std::string stderr_path;       // empty: the parent's stderr; else this file (truncated)
  bool stderr_to_stdout = false; // stderr wherever stdout goes (overrides stderr_path)
};

// The program could not be started (not found, not executable, an output file that cannot
// be opened) or it did not exit by itself (killed by a signal). The message says which.
class ChildProcessError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

// Runs `command[0]` (looked up on the PATH when it has no '/') with the arguments
// `command[1..]`, waits for it and returns its exit code (0..255). Throws ChildProcessError
// when it cannot start or is killed by a signal. The parent's own buffered output is flushed
// first, so that the two appear in the order they were written.
int run_program(const std::vector<std::string> &command, const ChildOutput &output = {});

// The same for a caller that only reports a failure: "" when the program exited with 0, else
// why not ("exit 3", or the ChildProcessError's message).
std::string run_program_failure(const std::vector<std::string> &command, const ChildOutput &output = {});

// Is there an executable `name` (a path, or a program on the PATH)?
bool program_exists(const std::string &name);

} // namespace magbrush
