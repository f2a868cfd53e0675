// The ten-line summary of a case (case_at_a_glance.h).
#include "app/case_at_a_glance.h"

#include "case/units.h"

#include <cmath>
#include <sstream>

namespace magbrush {

namespace {
std::string q(double v, Dimension d) { return format_quantity(v, d); }

std::string line(const std::string &label, const std::string &text)
{
  std::string padded = label;
  padded.resize(11, ' ');
  return "  " + padded + text + "\n";
}
} // namespace

std::string case_at_a_glance(const Case &c, const std::string &resolved_file)
{
  std::ostringstream o;
  o << line("case", c.name + " (" + c.source_file + ", scene " + c.scene + ")");
  std::string variant = c.output.overrides.empty() ? "the case as its file gives it"
                                                   : std::to_string(c.output.overrides.size()) + " override" +
                                                         (c.output.overrides.size() == 1 ? "" : "s") + ":";
  for (const auto &set : c.output.overrides)
    variant += " " + set;
  o << line("variant", variant);
  o << line("folder", c.output.directory + "/ (stored fields: " + c.field.output_dir + "/)");

  if (c.sleeve)
  {
    std::string roller = "sleeve " + q(2.0 * c.sleeve->radius, Dimension::length) + " at " +
                         q(c.sleeve->rpm * 2.0 * M_PI / 60.0, Dimension::angular_velocity);
    if (c.roller)
    {
      roller += ", " + std::to_string(c.roller->poles.size()) + " poles:";
      for (const auto &p : c.roller->poles)
        roller += " " + p.name + " " + q(p.angle, Dimension::angle);
    }
    o << line("roller", roller);
  }
  else
    o << line("roller", "none");
  if (c.drum.present)
    o << line("drum", q(2.0 * c.drum.radius, Dimension::length) + " at " +
                          q(c.drum.rpm * 2.0 * M_PI / 60.0, Dimension::angular_velocity) + ", gap " +
                          q(c.drum.gap, Dimension::length));
  else
    o << line("drum", "none");
  if (c.electric.enabled)
    o << line("electric", "bias " + q(c.electric.bias, Dimension::voltage) +
                              (c.electric.image.kind == LatentImage::Kind::none
                                   ? std::string(", no latent image")
                                   : c.electric.image.solid()     ? std::string(", a solid exposed area")
                                     : c.electric.image.striped() ? ", strips of period " +
                                                                        q(c.electric.image.period, Dimension::length)
                                                                  : std::string(", a dark drum")));
  else
    o << line("electric", "off");

  std::string particles;
  for (const auto &p : c.populations)
  {
    particles += (particles.empty() ? "" : "; ") + p.name + " " + q(p.diameter_mean, Dimension::length);
    if (p.count > 0)
      particles += ", " + std::to_string(p.count) + " placed";
    else if (p.mass > 0.0)
      particles += ", " + q(p.mass, Dimension::mass) + " placed";
  }
  if (c.flow.inflow())
    particles += "; inflow " + q(c.flow.inflow_areal_mass, Dimension::areal_mass);
  if (c.dem.periodic_length > 0.0)
    particles += "; slab " + q(c.dem.periodic_length, Dimension::length);
  o << line("particles", particles.empty() ? "none" : particles);

  std::string time = q(c.dem.duration, Dimension::time) + " simulated";
  time += c.dem.time_step > 0.0 ? ", step " + q(c.dem.time_step, Dimension::time)
                                : std::string(", step automatic");
  if (c.dem.time_step > 0.0 && c.dem.duration > 0.0)
    time += " (" + std::to_string(std::lround(c.dem.duration / c.dem.time_step)) + " steps)";
  if (c.dem.settle_time > 0.0)
    time += ", settling " + q(c.dem.settle_time, Dimension::time) + " first";
  o << line("time", time);

  // The windows the key numbers are averaged over (0: from the start; a window of a
  // measurement the scene does not make is listed too, which is harmless).
  std::string windows;
  const auto window = [&](const char *name, double from) {
    if (from > 0.0)
      windows += (windows.empty() ? "" : ", ") + std::string(name) + " from " + q(from, Dimension::time);
  };
  window("nip", c.nip.average_from);
  window("development", c.development.average_from);
  window("dma", c.dma.average_from);
  window("flow report", c.flow.average_from);
  o << line("averaging", windows.empty() ? "over the whole run" : windows + " to the end");
  o << line("full case", resolved_file + " (every key with its unit and default)");
  return o.str();
}

} // namespace magbrush
