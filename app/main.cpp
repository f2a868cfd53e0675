// magbrush — the user-facing driver. `magbrush <subcommand> --help` explains each step.
#include "app/subcommand.h"
#include "case/case_schema.h"

#include <cstdlib>
#include <filesystem>
#include <vector>
#include <algorithm>
#include <climits>
#include <cstdio>
#include <exception>
#include <iostream>
#include <unistd.h>

namespace magbrush {

namespace {
std::vector<Subcommand> &table()
{
  static std::vector<Subcommand> commands;
  return commands;
}
} // namespace

bool register_subcommand(const Subcommand &command)
{
  table().push_back(command);
  std::stable_sort(table().begin(), table().end(),
                   [](const Subcommand &a, const Subcommand &b) { return a.order < b.order; });
  return true;
}

const std::vector<Subcommand> &subcommands() { return table(); }

const Subcommand *find_subcommand(const std::string &name)
{
  for (const auto &c : table())
    if (c.name == name)
      return &c;
  return nullptr;
}

std::string executable_dir()
{
  char buffer[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buffer, sizeof(buffer) - 1);
  if (n <= 0)
    return ".";
  std::string path(buffer, static_cast<size_t>(n));
  return path.substr(0, path.find_last_of('/'));
}

std::string find_tool_script(const std::string &name)
{
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char *env = std::getenv("MAGBRUSH_TOOLS"))
    candidates.push_back(fs::path(env) / name);
  candidates.push_back(fs::path(MAGBRUSH_SOURCE_TOOLS_DIR) / name);
  const fs::path exe = executable_dir();
  candidates.push_back(exe / ".." / ".." / "tools" / name);
  candidates.push_back(exe / ".." / "tools" / name);
  candidates.push_back(exe / ".." / "share" / "magbrush" / "tools" / name);
  for (const auto &c : candidates)
  {
    std::error_code ec;
    if (fs::is_regular_file(c, ec))
      return fs::weakly_canonical(c, ec).string();
  }
  return "";
}

} // namespace magbrush

static void print_usage()
{
  std::cout << "magbrush " << MAGBRUSH_VERSION
            << " — magnetic-brush development simulator\n\n"
               "Usage: magbrush <command> [options]   (magbrush <command> --help for details)\n\n"
               "Commands:\n";
  for (const auto &c : magbrush::subcommands())
    std::printf("  %-8s %s\n", c.name.c_str(), c.summary.c_str());
}

int main(int argc, char **argv)
{
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")
  {
    print_usage();
    return argc < 2 ? 2 : 0;
  }
  if (std::string(argv[1]) == "--version")
  {
    std::cout << "magbrush " << MAGBRUSH_VERSION << "\n";
    return 0;
  }
  const std::string name = argv[1];
  for (const auto &c : magbrush::subcommands())
    if (c.name == name)
    {
      std::vector<std::string> args(argv + 1, argv + argc);
      try
      {
        return c.run(args);
      }
      catch (const std::exception &e)
      {
        std::cerr << "magbrush " << name << ": error: " << e.what() << "\n";
        return 1;
      }
    }
  // A mistyped command gets the nearest one; a case file given first gets the command that runs it.
  std::vector<std::string> names;
  for (const auto &c : magbrush::subcommands())
    names.push_back(c.name);
  const std::string suggestion = magbrush::did_you_mean(name, names);
  const bool case_file = name.size() > 5 && (name.compare(name.size() - 5, 5, ".yaml") == 0 ||
                                             name.compare(name.size() - 4, 4, ".yml") == 0);
  std::cerr << "magbrush: unknown command '" << name << "'"
            << (!suggestion.empty() ? " (did you mean '" + suggestion + "'?)"
                : case_file         ? " (a case file comes after the command: magbrush run " + name + ")"
                                    : std::string())
            << "\n\n";
  print_usage();
  return 2;
}
