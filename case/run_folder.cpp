// Run folders named by the case and a digest of its overrides (run_folder.h).
#include "case/run_folder.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>

namespace magbrush {

namespace {
std::string trimmed(const std::string &s)
{
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string::npos)
    return "";
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}
} // namespace

std::vector<std::string> normalised_overrides(const std::vector<std::string> &overrides)
{
  std::map<std::string, std::string> by_key; // sorted by key; a later override of a key replaces it
  for (const auto &o : overrides)
  {
    const auto eq = o.find('=');
    const std::string key = trimmed(o.substr(0, eq));
    by_key[key] = eq == std::string::npos ? "" : trimmed(o.substr(eq + 1));
  }
  std::vector<std::string> out;
  for (const auto &[key, value] : by_key)
    out.push_back(key + "=" + value);
  return out;
}

std::string overrides_digest(const std::vector<std::string> &normalised)
{
  std::uint64_t h = 1469598103934665603ull; // FNV-1a 64 offset basis
  for (const auto &line : normalised)
    for (unsigned char ch : line + "\n")
    {
      h ^= ch;
      h *= 1099511628211ull; // FNV prime
    }
  // Six hex digits: 16.7 million names, so two variants of one case collide with a
  // probability of ~n²/3.4e7 (1e-5 for 20 variants); short enough to read and type.
  char b[17];
  std::snprintf(b, sizeof(b), "%06llx", static_cast<unsigned long long>(h & 0xffffffull));
  return b;
}

std::string automatic_run_folder(const std::string &case_name, const std::vector<std::string> &normalised)
{
  const std::filesystem::path root = results_root_directory;
  if (normalised.empty())
    return (root / case_name).string();
  return (root / (case_name + "-" + overrides_digest(normalised))).string();
}

std::string variant_text(const std::string &case_file, const std::vector<std::string> &normalised)
{
  std::string text = "# the case file and the --set overrides of the runs in this folder\ncase " + case_file + "\n";
  for (const auto &o : normalised)
    text += "set " + o + "\n";
  return text;
}

} // namespace magbrush
