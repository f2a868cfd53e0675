// Reads a magbrush CSV (header row, '#' comment lines skipped) into columns by header name:
// what the nip regression test, the nip benchmark and the flux command's test read back.
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

inline CsvColumns read_csv_columns(const std::filesystem::path &path)
{
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> header;
  CsvColumns cols;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');)
      cells.push_back(c);
    if (header.empty())
    {
      header = cells;
      continue;
    }
    for (std::size_t k = 0; k < header.size() && k < cells.size(); ++k)
      cols[header[k]].push_back(cells[k]);
  }
  return cols;
}

} // namespace magbrush::testing
