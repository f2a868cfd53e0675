// The requirement-against-pole sensitivity table (see design_sensitivity.h).
#include "design/design_sensitivity.h"

#include "design/text_columns.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace magbrush {

namespace {
constexpr double deg = M_PI / 180.0;

std::vector<double> values(const RequirementSet &requirements, const RingProfile &ring,
                           const std::vector<Pole> &poles)
{
  std::vector<double> v;
  for (const auto &r : requirements.evaluate(poles, ring.of(poles)))
    v.push_back(r.value);
  return v;
}
} // namespace

SensitivityTable sensitivities(const RequirementSet &requirements, const RingProfile &ring,
                               const std::vector<Pole> &poles)
{
  SensitivityTable t;
  for (const auto &r : requirements.evaluate(poles, ring.of(poles)))
    t.requirements.push_back(r.name + " [" + r.unit + "]");
  t.d.resize(t.requirements.size(), 2 * poles.size());
  for (size_t i = 0; i < poles.size(); ++i)
    for (int kind = 0; kind < 2; ++kind)
    {
      const bool angle = kind == 0;
      // 0.05° and 1 kA/m: small against the tolerances, large against rounding.
      const double h = angle ? 0.05 * deg : 1e3;
      auto plus = poles, minus = poles;
      if (angle)
      {
        plus[i].angle += h;
        minus[i].angle -= h;
      }
      else
      {
        plus[i].strength += std::copysign(h, poles[i].strength);
        minus[i].strength -= std::copysign(h, poles[i].strength);
      }
      const auto vp = values(requirements, ring, plus), vm = values(requirements, ring, minus);
      const size_t column = 2 * i + kind;
      for (size_t k = 0; k < vp.size(); ++k)
        t.d(k, column) = (vp[k] - vm[k]) / (2 * h) * (angle ? deg : 1e4);
      t.parameters.push_back(poles[i].name + (angle ? " angle" : " |M|"));
      t.per_degree.push_back(angle);
    }
  return t;
}

std::string format_sensitivities(const SensitivityTable &t)
{
  std::ostringstream out;
  char buf[64];
  std::snprintf(buf, sizeof buf, "  %-42s", "requirement  \\  per +1° / +10 kA/m of");
  out << buf;
  for (const auto &p : t.parameters)
  {
    std::snprintf(buf, sizeof buf, " %9s", p.c_str());
    out << buf;
  }
  out << "\n";
  for (size_t k = 0; k < t.requirements.size(); ++k)
  {
    out << "  " << padded(t.requirements[k], 42);
    for (long j = 0; j < t.d.cols(); ++j)
    {
      std::snprintf(buf, sizeof buf, " %+9.2f", t.d(k, j));
      out << buf;
    }
    out << "\n";
  }
  return out.str();
}

std::string sensitivities_csv(const SensitivityTable &t)
{
  std::ostringstream out;
  out << "# d(requirement) per +1 deg of a pole's angle or per +10 kA/m of its |M|, central differences on the exact ring\n"
      << "requirement";
  for (size_t j = 0; j < t.parameters.size(); ++j)
    out << "," << t.parameters[j] << (t.per_degree[j] ? " per deg" : " per 10 kA/m");
  out << "\n";
  for (size_t k = 0; k < t.requirements.size(); ++k)
  {
    out << "\"" << t.requirements[k] << "\"";
    for (long j = 0; j < t.d.cols(); ++j)
      out << "," << t.d(k, j);
    out << "\n";
  }
  return out.str();
}

} // namespace magbrush
