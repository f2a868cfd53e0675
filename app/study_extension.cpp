// One more point of a finished study (see study_extension.h).
#include "app/study_extension.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace magbrush {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> cells_of(const std::string &line)
{
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');)
  {
    while (!cell.empty() && (cell.back() == '\r' || cell.back() == '"'))
      cell.pop_back();
    if (!cell.empty() && cell.front() == '"')
      cell.erase(cell.begin());
    out.push_back(cell);
  }
  return out;
}

std::string key_of(const std::string &assignment)
{
  return assignment.substr(0, assignment.find('='));
}

} // namespace

FinishedSweep read_finished_sweep(const fs::path &dir, const std::string &key)
{
  FinishedSweep s;
  s.dir = fs::absolute(dir).lexically_normal();
  if (s.dir.filename().empty())
    s.dir = s.dir.parent_path();
  s.key = key;
  const std::string folder = s.dir.filename().string();
  if (folder.rfind("sweep_", 0) != 0)
    throw std::invalid_argument(dir.string() + " is not a study folder (magbrush sweep writes sweep_<NAME>/)");
  s.name = folder.substr(6);
  if (fs::exists(s.dir / "spin_up"))
    throw std::invalid_argument("the study forks its points from a spin-up: run the extra point by hand (magbrush sweep "
                                "... --spin-up) and merge it");
  std::ifstream in(s.dir / "sweep_summary.csv");
  if (!in)
    throw std::invalid_argument("cannot read " + (s.dir / "sweep_summary.csv").string());
  std::string line;
  std::vector<std::string> header;
  while (std::getline(in, line))
  {
    const std::string mark = "# magbrush sweep of ";
    if (line.rfind(mark, 0) == 0)
      s.case_path = line.substr(mark.size());
    else if (!line.empty() && line[0] != '#')
    {
      header = cells_of(line);
      break;
    }
  }
  // The values as given: the columns between "point" and the first "<key> [unit]".
  std::vector<std::string> given;
  for (size_t j = 1; j < header.size() && header[j].find(" [") == std::string::npos; ++j)
    given.push_back(header[j]);
  const bool seeded = std::find(given.begin(), given.end(), "dem.seed") != given.end();
  if (std::find(given.begin(), given.end(), key) == given.end() || given.size() != 1u + (seeded ? 1 : 0))
  {
    std::string listed;
    for (const auto &g : given)
      listed += (listed.empty() ? "" : ", ") + g;
    throw std::invalid_argument("the study varies " + listed + ": an extra point is run for a study over " + key +
                                " alone (with or without --repeats)");
  }
  const size_t key_column = size_t(std::find(header.begin(), header.end(), key) - header.begin());
  std::string first_label;
  size_t rows = 0;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    const auto c = cells_of(line);
    if (c.size() <= key_column)
      continue;
    if (first_label.empty())
      first_label = c[0];
    if (std::find(s.values.begin(), s.values.end(), c[key_column]) == s.values.end())
      s.values.push_back(c[key_column]);
    ++rows;
  }
  if (s.values.empty())
    throw std::invalid_argument((s.dir / "sweep_summary.csv").string() + " has no points");
  if (seeded)
  {
    if (!fs::exists(s.dir / "sweep_mean.csv") || rows % s.values.size() != 0)
      throw std::invalid_argument("the study varies dem.seed by hand, not by --repeats: run the extra point by hand");
    s.repeats = rows / s.values.size();
  }
  // The sweep's --set: a point's, less what the sweep set for that point alone. A population's
  // diameter also brings the count, spread and step the sweep derives per point to keep the
  // layer; they are derived again for the new point.
  std::ifstream variant(s.dir / first_label / "variant.txt");
  if (!variant)
    throw std::invalid_argument("cannot read " + (s.dir / first_label / "variant.txt").string() +
                                " (the overrides of the study's runs)");
  std::vector<std::string> own = {"output.directory", "field.output_dir", key, "dem.seed"};
  if (key.rfind("populations.", 0) == 0 && key.size() > 9 && key.substr(key.size() - 9) == ".diameter")
  {
    const std::string population = key.substr(0, key.size() - 9);
    own.insert(own.end(), {population + ".count", population + ".diameter_std", "dem.time_step"});
  }
  while (std::getline(variant, line))
  {
    if (line.rfind("case ", 0) == 0 && s.case_path.empty())
      s.case_path = line.substr(5);
    if (line.rfind("set ", 0) != 0)
      continue;
    const std::string o = line.substr(4);
    if (std::find(own.begin(), own.end(), key_of(o)) == own.end())
      s.overrides.push_back(o);
  }
  // Its folder: the sweep puts sweep_<NAME>/ under output.directory.
  s.overrides.push_back("output.directory=" + s.dir.parent_path().string());
  if (s.case_path.empty())
    throw std::invalid_argument("the study does not say which case it ran");
  return s;
}

std::vector<std::vector<std::string>> extended_sweep_commands(const FinishedSweep &sweep, const std::string &value,
                                                              const std::vector<std::string> &stage_options)
{
  if (std::find(sweep.values.begin(), sweep.values.end(), value) != sweep.values.end())
    throw std::invalid_argument("the study has run " + sweep.key + "=" + value + " already");
  std::string list;
  for (const auto &v : sweep.values)
    list += v + ",";
  std::vector<std::string> words = {"sweep", sweep.case_path, "--vary", sweep.key + "=" + list + value, "--name",
                                    sweep.name};
  for (const auto &o : sweep.overrides)
    words.insert(words.end(), {"--set", o});
  if (sweep.repeats > 1)
    words.insert(words.end(), {"--repeats", std::to_string(sweep.repeats)});
  words.insert(words.end(), stage_options.begin(), stage_options.end());
  std::vector<std::vector<std::string>> commands;
  for (size_t r = 0; r < sweep.repeats; ++r)
  {
    commands.push_back(words);
    commands.back().insert(commands.back().end(),
                           {"--point", std::to_string(sweep.values.size() * sweep.repeats + r)});
  }
  commands.push_back(words);
  commands.back().push_back("--merge");
  return commands;
}

} // namespace magbrush
