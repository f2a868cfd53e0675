// Reads a magbrush CSV ('#' comment lines skipped) as rows of cells, or into columns by header
// name: what the nip regression test, the nip benchmark, the sweep tests and the flux
// command's test read back.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace magbrush::testing {

using CsvColumns = std::map<std::string, std::vector<std::string>>;
using CsvRows = std::vector<std::vector<std::string>>;

// Every non-empty, non-comment line split at the commas (the header is row 0).
inline CsvRows read_csv_rows(const std::filesystem::path &path)
{
  std::ifstream in(path);
  std::string line;
  CsvRows rows;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');)
      cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

inline CsvColumns read_csv_columns(const std::filesystem::path &path)
{
  const CsvRows rows = read_csv_rows(path);
  CsvColumns cols;
  for (std::size_t r = 1; r < rows.size(); ++r)
    for (std::size_t k = 0; k < rows[0].size() && k < rows[r].size(); ++k)
      cols[rows[0][k]].push_back(rows[r][k]);
  return cols;
}

} // namespace magbrush::testing
