// Field inputs and their digest: the schema's `affects` marks select the resolved entries.
#include "case/case_hash.h"

#include "case/case_format.h"
#include "case/case_schema.h"

#include <cstdint>
#include <cstdio>

namespace magbrush {

std::vector<std::pair<std::string, std::string>> field_inputs(const Case &c, FieldKind k)
{
  // Blades that are not magnetic do not enter the magnetostatic problem.
  std::vector<std::string> inert_blades;
  for (const auto &b : c.blades)
    if (b.mu_r == 1.0)
      inert_blades.push_back("blades." + b.name + ".");

  std::vector<std::pair<std::string, std::string>> inputs;
  for (const auto &e : resolved_entries(c))
  {
    const KeySpec *spec = find_key_spec(e.pattern);
    const Affects a = spec ? spec->affects : Affects::none;
    const bool wanted = a == Affects::both || (k == FieldKind::magnetic && a == Affects::magnetic) ||
                        (k == FieldKind::electric && a == Affects::electric);
    if (!wanted)
      continue;
    bool inert = false;
    if (k == FieldKind::magnetic)
      for (const auto &prefix : inert_blades)
        inert = inert || e.path.rfind(prefix, 0) == 0;
    if (!inert)
      inputs.emplace_back(e.path, e.exact);
  }
  return inputs;
}

namespace {
// FNV-1a 64 of a tag line and "key=value" lines, as 16 hex digits.
std::string digest(const std::string &tag, const std::vector<std::pair<std::string, std::string>> &inputs)
{
  std::uint64_t h = 1469598103934665603ull; // FNV-1a 64 offset basis
  const auto feed = [&](const std::string &s) {
    for (unsigned char ch : s)
    {
      h ^= ch;
      h *= 1099511628211ull; // FNV prime
    }
  };
  feed(tag);
  for (const auto &[key, value] : inputs)
    feed(key + "=" + value + "\n");
  char b[17];
  std::snprintf(b, sizeof(b), "%016llx", static_cast<unsigned long long>(h));
  return b;
}
} // namespace

std::string field_hash(const Case &c, FieldKind k)
{
  return digest(k == FieldKind::magnetic ? "magnetic-v1\n" : "electric-v1\n", field_inputs(c, k));
}

std::string mesh_hash(const Case &c)
{
  std::vector<std::pair<std::string, std::string>> inputs;
  for (const auto &e : resolved_entries(c))
  {
    const KeySpec *spec = find_key_spec(e.pattern);
    if (spec && spec->affects != Affects::none)
      inputs.emplace_back(e.path, e.exact);
  }
  return digest("mesh-v1\n", inputs);
}

std::vector<std::pair<std::string, std::string>> case_inputs(const Case &c)
{
  std::vector<std::pair<std::string, std::string>> inputs;
  for (const auto &e : resolved_entries(c))
    inputs.emplace_back(e.path, e.exact);
  return inputs;
}

std::string case_hash(const Case &c) { return digest("case-v1\n", case_inputs(c)); }

} // namespace magbrush
