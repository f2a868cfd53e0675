// A private scratch directory for each test process.
//
// ctest runs the test executables (and, through gtest_discover_tests, each test case in its own
// process) in parallel, so a fixed name under the temporary directory is shared by concurrent
// runs: one can remove another's files mid-run. test_temp_dir(name) gives a directory that no
// other process uses (the process id is part of its name), empty at the first call for that
// name in this process (later calls return the same directory as it is), and removes it when
// the process ends, unless MAGBRUSH_KEEP_TEST_DIRS is set (to look at the files
// of a failing test).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <system_error>
#include <unistd.h>
#include <vector>

namespace magbrush::testing {

namespace detail {

// Removes the registered directories at exit (static destruction, after main returns).
class TempDirRegistry
{
public:
  ~TempDirRegistry()
  {
    if (std::getenv("MAGBRUSH_KEEP_TEST_DIRS") != nullptr)
      return;
    std::error_code ignored;
    for (const auto &dir : dirs_)
      std::filesystem::remove_all(dir, ignored);
  }
  // Creates `dir` empty the first time it is asked for; true if it was created now.
  bool add(const std::filesystem::path &dir)
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto &known : dirs_)
      if (known == dir)
      {
        // A test may have removed it to clean up after itself.
        std::filesystem::create_directories(dir);
        return false;
      }
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    dirs_.push_back(dir);
    return true;
  }

private:
  std::mutex mutex_;
  std::vector<std::filesystem::path> dirs_;
};

inline TempDirRegistry &temp_dir_registry()
{
  static TempDirRegistry registry;
  return registry;
}

} // namespace detail

// <temp>/magbrush_<name>_<pid>: created empty at the first call (whatever an earlier process
// with the same id left there is removed), the same directory at later calls; removed when the
// process ends.
inline std::filesystem::path test_temp_dir(const std::string &name)
{
  const std::filesystem::path dir =
    std::filesystem::temp_directory_path() / ("magbrush_" + name + "_" + std::to_string(::getpid()));
  detail::temp_dir_registry().add(dir);
  return dir;
}

} // namespace magbrush::testing
