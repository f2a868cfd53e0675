// `magbrush design release`: the field criterion for release (design/release_criterion.h) for
// the case's layout, or for each value of one --vary key, ranked by how strongly the layout
// lets go in the release window (the case's dma.release_from → release_to, or --window).
#include "app/design_release_command.h"

#include "app/flux_tools.h"
#include "common/atomic_file.h"
#include "case/case_parser.h"
#include "case/units.h"
#include "design/release_criterion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace magbrush {
namespace {

namespace fs = std::filesystem;
constexpr double to_deg = 180.0 / M_PI;

struct Layout
{
  std::string label;            // "roller.poles.S2.angle=165deg" or "the case"
  ReleaseProfile profile;
  ReleaseVerdict verdict;
};

// "key=v1,v2,v3" → {"key=v1", "key=v2", "key=v3"}; none → {""} (the case as it is).
std::vector<std::string> variants(const std::string &vary)
{
  if (vary.empty())
    return {""};
  const auto eq = vary.find('=');
  if (eq == std::string::npos)
    throw cli::UsageError("--vary needs key=v1,v2,... (e.g. roller.poles.S2.angle=144deg,165deg)");
  std::vector<std::string> out;
  std::stringstream ss(vary.substr(eq + 1));
  for (std::string v; std::getline(ss, v, ',');)
    out.push_back(vary.substr(0, eq) + "=" + v);
  return out;
}

std::pair<double, double> window_of(const Case &c, const std::string &option)
{
  if (!option.empty())
  {
    const auto comma = option.find(',');
    if (comma == std::string::npos)
      throw cli::UsageError("--window needs FROM,TO (e.g. 140deg,234deg)");
    return {parse_quantity(option.substr(0, comma), Dimension::angle),
            parse_quantity(option.substr(comma + 1), Dimension::angle)};
  }
  if (c.dma.release_to != c.dma.release_from)
    return {c.dma.release_from, c.dma.release_to};
  return {0.0, 2 * M_PI};
}

std::string arcs_in_words(const ReleaseVerdict &v)
{
  if (v.arcs.empty())
    return "held all through";
  std::string s;
  for (const auto &a : v.arcs)
    s += (s.empty() ? "" : ", ") + fixed(a.from * to_deg, 1) + "–" + fixed(a.to * to_deg, 1) + "°";
  return "released over " + s;
}

void write_csv(const std::string &path, const std::vector<Layout> &layouts)
{
  std::ostringstream out;
  out << "# Field criterion for release: outward accelerations of a carrier bead at the sleeve [m/s^2]; "
         "held where net < 0\nlayout,angle_deg,B_mT,magnetic,centrifugal,gravity,net\n";
  for (const auto &l : layouts)
    for (size_t k = 0; k < l.profile.angle.size(); ++k)
      out << "\"" << l.label << "\"," << l.profile.angle[k] * to_deg << "," << l.profile.B[k] * 1e3 << ","
          << l.profile.magnetic[k] << "," << l.profile.centrifugal[k] << "," << l.profile.gravity[k] << ","
          << l.profile.net[k] << "\n";
  write_text_atomically(path, out.str());
}

} // namespace

int run_design_release(const cli::ParsedArguments &args)
{
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Layout> layouts;
  std::pair<double, double> window;
  std::string dir;
  ReleaseInputs in;
  for (const auto &variant : variants(args.value("--vary")))
  {
    auto overrides = args.values("--set");
    if (!variant.empty())
      overrides.push_back(variant);
    const Case c = load_case(args.positional(1), overrides);
    if (!c.roller)
      throw std::invalid_argument("the case has no roller");
    if (layouts.empty())
    {
      window = window_of(c, args.value("--window"));
      // The case's own run folder (with --set only): not the folder of the first --vary variant.
      dir = args.value("--output", load_case(args.positional(1), args.values("--set")).output.directory + "/design");
      in = ReleaseInputs::from(c);
    }
    Layout l;
    l.label = variant.empty() ? "the case's layout" : variant;
    l.profile = release_profile(MultipoleRing(*c.roller), ReleaseInputs::from(c), 0.25 / to_deg);
    l.verdict = release_in_window(l.profile, window.first, window.second);
    layouts.push_back(l);
  }
  const double g = std::hypot(in.gx, in.gy) > 0 ? std::hypot(in.gx, in.gy) : 9.81;
  std::cout << "magbrush design release: " << args.positional(1) << ", carrier bead of " << fixed(2e6 * in.bead_radius, 1)
            << " um diameter (mu_r " << fixed(in.bead_mu_r, 2) << ", " << fixed(in.bead_density, 0) << " kg/m^3) on the sleeve (r "
            << fixed(in.sleeve_radius * 1e3, 3) << " mm, centrifugal " << fixed(in.omega * in.omega * (in.sleeve_radius + in.bead_radius) / g, 2)
            << " g); window " << fixed(window.first * to_deg, 1) << "–" << fixed(window.second * to_deg, 1)
            << "°\n  held where a_net = a_mag + ω²r + g·r̂ < 0 (a_mag = 3β/(2μ0ρ) ∂B²/∂r, β = (μ−1)/(μ+2))\n\n";
  // The strongest release first: the largest net outward acceleration in the window.
  std::vector<size_t> order(layouts.size());
  for (size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return layouts[a].verdict.peak > layouts[b].verdict.peak; });
  char buf[512];
  std::snprintf(buf, sizeof buf, "  %-4s %-36s %-8s %-22s %s\n", "rank", "layout", "verdict", "largest a_net / g", "where");
  std::cout << buf;
  for (size_t r = 0; r < order.size(); ++r)
  {
    const Layout &l = layouts[order[r]];
    std::snprintf(buf, sizeof buf, "  %-4zu %-36s %-8s %+8.3f at %6.1f°      %s\n", r + 1, l.label.c_str(),
                  l.verdict.releases ? "RELEASES" : "holds", l.verdict.peak / g, l.verdict.at * to_deg,
                  arcs_in_words(l.verdict).c_str());
    std::cout << buf;
  }
  fs::create_directories(dir);
  write_csv(dir + "/release_criterion.csv", layouts);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "\n  profile     " << dir << "/release_criterion.csv\nTime: " << fixed(seconds, 2) << " s for "
            << layouts.size() << " layout(s)\n";
  return 0;
}

} // namespace magbrush
