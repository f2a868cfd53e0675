// Consistency checks on a resolved case. Each check is about one thing a designer can get
// wrong, and its message says what is wrong, by how much, and what would be right.
#include "case/case_validation.h"

#include "case/case_schema.h"
#include "case/units.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace magbrush {

namespace {

constexpr double pi = 3.14159265358979323846;

std::string L(double v) { return format_quantity(v, Dimension::length); }
std::string deg(double v) { return format_quantity(v, Dimension::angle); }

double cross(const Vec2 &o, const Vec2 &a, const Vec2 &b)
{
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

bool segments_intersect(const Vec2 &a, const Vec2 &b, const Vec2 &c, const Vec2 &d)
{
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

double segment_distance(const Vec2 &a, const Vec2 &b, const Vec2 &p)
{
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
}

std::string material_suggestion(const Case &c, const std::string &name)
{
  std::vector<std::string> names;
  for (const auto &m : c.materials)
    names.push_back(m.name);
  const std::string s = did_you_mean(name, names);
  if (!s.empty())
    return " (did you mean '" + s + "'?)";
  std::string list;
  for (const auto &n : names)
    list += (list.empty() ? "" : ", ") + n;
  return names.empty() ? " (the case has no 'materials' section)" : " (materials: " + list + ")";
}

// ---- the checks, one per part of the scene ----------------------------------------------

void check_scene(const Case &c, std::vector<CaseIssue> &out)
{
  if (c.scene == "roller")
  {
    if (!c.sleeve)
      out.push_back({"sleeve", "a roller scene needs a 'sleeve' section (radius or diameter, rpm)"});
    if (!c.roller && c.applied_field.kind == AppliedField::Kind::roller)
      out.push_back({"roller", "a roller scene needs a 'roller' section (magnet_radius, poles)"});
  }
  else // box
  {
    if (c.roller)
      out.push_back({"roller", "a box scene has plane walls only; remove 'roller' or set 'scene: roller'"});
    if (c.sleeve)
      out.push_back({"sleeve", "a box scene has plane walls only; remove 'sleeve' or set 'scene: roller'"});
    if (c.drum.present)
      out.push_back({"drum", "a box scene has plane walls only; remove 'drum' or set 'scene: roller'"});
    if (!c.blades.empty())
      out.push_back({"blades", "a box scene has plane walls only; remove 'blades' or set 'scene: roller'"});
    if (c.planes.empty())
      out.push_back({"planes", "a box scene needs at least one plane wall in 'planes'"});
  }
}

void check_roller(const Case &c, std::vector<CaseIssue> &out)
{
  if (!c.roller)
    return;
  const Roller &r = *c.roller;
  if (r.shaft_radius >= r.magnet_radius)
    out.push_back({"roller.shaft_radius", "the shaft (radius " + L(r.shaft_radius) +
                                              ") must be smaller than the magnet (radius " + L(r.magnet_radius) + ")"});
  if (c.sleeve)
  {
    const double inner = c.sleeve->radius - c.sleeve->thickness;
    if (c.sleeve->thickness >= c.sleeve->radius)
      out.push_back({"sleeve.thickness", "the sleeve wall (" + L(c.sleeve->thickness) +
                                             ") must be thinner than its radius (" + L(c.sleeve->radius) + ")"});
    else if (r.magnet_radius >= inner)
      out.push_back({"roller.magnet_radius", "the magnet (radius " + L(r.magnet_radius) +
                                                 ") must fit inside the sleeve (inner radius " + L(inner) +
                                                 " = radius " + L(c.sleeve->radius) + " - thickness " +
                                                 L(c.sleeve->thickness) + ")"});
  }
  if (r.poles.empty())
    out.push_back({"roller.poles", "the roller needs at least one pole"});
  const double min_sep = min_pole_separation_deg * pi / 180.0;
  for (size_t i = 0; i < r.poles.size(); ++i)
  {
    const Pole &p = r.poles[i];
    const std::string path = "roller.poles." + p.name;
    if (p.strength == 0.0)
      out.push_back({path + ".strength", "a pole needs a non-zero strength (e.g. 170 kA/m, or -170 kA/m for a south pole)"});
    for (size_t j = 0; j < i; ++j)
    {
      const Pole &q = r.poles[j];
      double d = std::fmod(std::abs(p.angle - q.angle), 2.0 * pi);
      d = std::min(d, 2.0 * pi - d);
      if (d < min_sep)
        out.push_back({path + ".angle", "pole " + p.name + " at " + deg(p.angle) + " is " + deg(d) + " from pole " +
                                            q.name + " at " + deg(q.angle) + "; poles must be at least " +
                                            deg(min_sep) + " apart"});
    }
  }
}

void check_drum(const Case &c, std::vector<CaseIssue> &out)
{
  if (!c.drum.present)
    return;
  if (c.drum.gap <= 0.0)
    out.push_back({"drum.gap", "expected a development gap > 0, found " + L(c.drum.gap) +
                                   ": the drum would touch or cut into the sleeve"});
  if (c.drum.pc_thickness >= c.drum.radius)
    out.push_back({"drum.pc_thickness", "the photoconductor layer (" + L(c.drum.pc_thickness) +
                                            ") must be thinner than the drum radius (" + L(c.drum.radius) + ")"});
}

void check_blades(const Case &c, std::vector<CaseIssue> &out)
{
  const double R = c.sleeve ? c.sleeve->radius : 0.0;
  for (const auto &b : c.blades)
  {
    const std::string path = "blades." + b.name;
    if (b.polygon.size() < 3)
      continue; // already reported by the parser
    if (!polygon_is_simple(b.polygon))
    {
      out.push_back({path + ".profile", "the polygon crosses itself; list its corners in order around it"});
      continue;
    }
    if (std::abs(polygon_signed_area(b.polygon)) <= 0.0)
    {
      out.push_back({path + ".profile", "the polygon has zero area"});
      continue;
    }
    if (c.sleeve)
    {
      const double distance = polygon_distance_to_point(b.polygon, {0.0, 0.0});
      bool all_inside = true;
      for (const auto &v : b.polygon)
        all_inside = all_inside && std::hypot(v[0], v[1]) < R;
      if (all_inside)
        out.push_back({path + ".profile", "the blade lies inside the sleeve (radius " + L(R) +
                                              "); blade coordinates are in the roller frame, centre at the origin"});
      else if (distance <= R)
        out.push_back({path + ".profile", "the blade crosses the sleeve surface: its nearest point is " + L(distance) +
                                              " from the roller centre, inside the sleeve radius " + L(R)});
      else
      {
        const double polygon_gap = distance - R;
        if (b.gap < 0.0)
          ; // derived
        else if (std::abs(polygon_gap - b.gap) > std::max(1e-6, 0.01 * b.gap))
          out.push_back({path + ".gap", "the stated gap " + L(b.gap) + " does not match the profile, whose nearest point is " +
                                            L(polygon_gap) + " from the sleeve surface (tolerance max(1 um, 1 %))"});
      }
      if (b.gap == 0.0 && b.is_doctor_blade)
        out.push_back({path + ".gap", "a doctor blade needs a gap > 0"});
    }
    if (c.drum.present && c.sleeve)
    {
      const Vec2 centre = c.drum.center(R);
      if (polygon_distance_to_point(b.polygon, centre) <= c.drum.radius)
        out.push_back({path + ".profile", "the blade cuts into the drum (drum centre at (" + L(centre[0]) + ", " +
                                              L(centre[1]) + "), radius " + L(c.drum.radius) + ")"});
    }
    if (!c.populations.empty() && !c.materials.empty())
    {
      bool found = false;
      for (const auto &m : c.materials)
        found = found || m.name == b.material;
      if (!found)
        out.push_back({path + ".material", "no material named '" + b.material + "'" + material_suggestion(c, b.material)});
    }
  }
  if (!c.sleeve && !c.blades.empty() && c.scene == "roller")
    out.push_back({"blades", "blades are placed relative to the sleeve; add a 'sleeve' section"});
}

void check_planes(const Case &c, std::vector<CaseIssue> &out)
{
  for (const auto &p : c.planes)
  {
    const std::string path = "planes." + p.name;
    if (p.normal == Vec3{0, 0, 0})
      out.push_back({path + ".normal", "expected a non-zero normal, found [0, 0, 0]"});
    for (size_t i = 1; i < p.path.size(); ++i)
      if (p.path[i].first <= p.path[i - 1].first)
        out.push_back({path + ".path[" + std::to_string(i) + "].time",
                       "path times must increase; found " + format_quantity(p.path[i].first, Dimension::time) +
                           " after " + format_quantity(p.path[i - 1].first, Dimension::time)});
    bool found = false;
    for (const auto &m : c.materials)
      found = found || m.name == p.material;
    if (!found && !c.populations.empty())
      out.push_back({path + ".material", "no material named '" + p.material + "'" + material_suggestion(c, p.material)});
  }
}

const Population *first_carrier(const Case &c)
{
  for (const auto &p : c.populations)
    if (p.kind == ParticleKind::carrier)
      return &p;
  return nullptr;
}

void check_populations(const Case &c, std::vector<CaseIssue> &out)
{
  bool has_carrier = false;
  for (const auto &p : c.populations)
    has_carrier = has_carrier || p.kind == ParticleKind::carrier;
  bool carried_seen = false;
  for (const auto &p : c.populations)
  {
    const std::string path = "populations." + p.name;
    const Material *m = nullptr;
    for (const auto &mm : c.materials)
      if (mm.name == p.material)
        m = &mm;
    if (!m)
      out.push_back({path + ".material", "no material named '" + p.material + "'" + material_suggestion(c, p.material)});
    else if (m->density <= 0.0)
      out.push_back({"materials." + m->name + ".density", "particles of population '" + p.name +
                                                              "' are made of this material, so it needs a density > 0"});
    if (p.diameter_mean - 3.0 * p.diameter_std < 0.0)
      out.push_back({path + ".diameter_std", "the size distribution reaches negative diameters: mean - 3 std = " +
                                                 L(p.diameter_mean - 3.0 * p.diameter_std) +
                                                 " (mean " + L(p.diameter_mean) + ", std " + L(p.diameter_std) +
                                                 "); expected std <= mean / 3"});
    const int given = (p.count > 0) + (p.mass > 0.0) + (p.concentration > 0.0);
    // The carrier population the inflow feeds may start empty: all of it comes with the sleeve.
    const bool fed_from_empty = given == 0 && c.flow.inflow() && p.kind == ParticleKind::carrier &&
                                (c.flow.inflow_population.empty() ? &p == first_carrier(c) : c.flow.inflow_population == p.name);
    if (given != 1 && !fed_from_empty)
      out.push_back({path, "give exactly one of count, mass, concentration (found " + std::to_string(given) + ")"});
    if (p.concentration > 0.0 && p.kind != ParticleKind::toner)
      out.push_back({path + ".concentration", "concentration (toner mass / carrier mass) is for toner populations only"});
    if (p.concentration > 0.0 && !has_carrier)
      out.push_back({path + ".concentration", "a toner concentration needs a carrier population to be relative to"});
    if (p.kind == ParticleKind::toner && p.charge_to_mass == 0.0)
      out.push_back({path + ".charge_to_mass", "toner needs a charge-to-mass ratio q/m (e.g. -30 uC/g)"});
    if (p.counter_charge && p.kind != ParticleKind::carrier)
      out.push_back({path + ".counter_charge", "the counter-charge is the carriers' (toner is charged from its q/m)"});
    if (p.counter_charge && (p.charge_to_mass != 0.0 || p.charge_to_mass_std > 0.0 || p.wrong_sign_fraction > 0.0))
      out.push_back({path + ".counter_charge", "a counter-charged carrier takes its charge from the toner: "
                                               "give either counter_charge or charge_to_mass (with its spread), not both"});
    if (p.charge_to_mass == 0.0 && (p.charge_to_mass_std > 0.0 || p.wrong_sign_fraction > 0.0))
      out.push_back({path + ".charge_to_mass", "a q/m spread or wrong-sign fraction needs a mean q/m"});
    if (p.charge_to_mass_std > 0.0 && p.charge_to_mass_std > std::abs(p.charge_to_mass))
      out.push_back({path + ".charge_to_mass_std", "the q/m spread exceeds the mean q/m; the truncated distribution "
                                                   "would no longer have that mean (expected std <= |mean|)"});
    if (p.insert_box)
      for (int k = 0; k < 3; ++k)
        if ((*p.insert_box)[0][k] >= (*p.insert_box)[1][k])
        {
          out.push_back({path + ".insert_box", "the box's first corner must be below its second in x, y and z"});
          break;
        }
    if (p.attached && (p.kind != ParticleKind::toner || p.concentration <= 0.0))
      out.push_back({path + ".attached", "only toner given by a concentration is attached to the carriers "
                                         "(each carrier carries the concentration times its own mass)"});
    if (p.attached && p.kind == ParticleKind::toner && (p.insert_box || p.layer_thickness > 0.0))
      out.push_back({path + ".attached", "attached toner sits on the carriers: give no insert_box or layer_thickness"});
    if (p.carried_until_gap > 0.0)
    {
      if (p.kind != ParticleKind::toner || p.concentration <= 0.0)
        out.push_back({path + ".carried_until_gap", "only toner given by a concentration rides the carriers"});
      else if (!p.attached && !c.flow.inflow())
        out.push_back({path + ".carried_until_gap", "carried toner is the toner on the carriers: set attached: true, "
                                                    "or feed the developer with an inflow"});
      if (!c.drum.present)
        out.push_back({path + ".carried_until_gap", "carried toner is released near the drum, and the case has no drum"});
      if (carried_seen)
        out.push_back({path + ".carried_until_gap", "only one toner population may ride the carriers"});
      carried_seen = true;
    }
    if (!p.insert_box && p.layer_thickness <= 0.0 && !fed_from_empty && !p.attached)
      out.push_back({path, "say where the particles go: insert_box or layer_thickness"});
    if (p.layer_thickness > 0.0 && !c.sleeve)
      out.push_back({path + ".layer_thickness", "a layer on the sleeve needs a sleeve"});
  }
  // The rotating walls take their contact properties from materials named after them.
  if (!c.populations.empty())
    for (const auto &[wall, present] : {std::pair<std::string, bool>{"sleeve", c.sleeve.has_value()},
                                        std::pair<std::string, bool>{"drum", c.drum.present}})
    {
      bool found = false;
      for (const auto &m : c.materials)
        found = found || m.name == wall;
      if (present && !found)
        out.push_back({"materials", "particles touch the " + wall + ", whose contact properties come from a material named '" +
                                        wall + "'; add it, e.g. " + wall +
                                        ": {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35}"});
    }
  for (const auto &m : c.materials)
    if (m.polygon_angles != 0 && m.polygon_angles < 3)
      out.push_back({"materials." + m.name + ".polygon_angles", "expected 0 (off) or >= 3 polygon angles, found " +
                                                                     std::to_string(m.polygon_angles)});
}

void check_fields(const Case &c, std::vector<CaseIssue> &out)
{
  if (c.electric.enabled && c.scene == "roller" && !c.drum.present)
    out.push_back({"electric", "the nip field needs a drum; add a 'drum' section or set electric.enabled: false"});
  const auto &f = c.applied_field;
  if (f.kind == AppliedField::Kind::roller && !c.roller)
    out.push_back({"applied_field.kind", "the applied field comes from the roller, but the case has no 'roller' section"});
  if (f.kind == AppliedField::Kind::uniform && f.uniform_magnitude <= 0.0)
    out.push_back({f.schedule.empty() ? "applied_field.magnitude" : "applied_field.schedule",
                   f.schedule.empty() ? "a uniform applied field needs a magnitude > 0 (e.g. 130 mT)"
                                      : "a uniform field schedule needs at least one magnitude > 0"});
  if (!f.schedule.empty() && f.kind != AppliedField::Kind::uniform)
    out.push_back({"applied_field.schedule", "a schedule is for the uniform field (applied_field.kind: uniform); "
                                             "a roller field is ramped with ramp_time"});
  for (size_t i = 1; i < f.schedule.size(); ++i)
    if (f.schedule[i].first <= f.schedule[i - 1].first)
      out.push_back({"applied_field.schedule[" + std::to_string(i) + "].time",
                     "schedule times must increase; found " + format_quantity(f.schedule[i].first, Dimension::time) +
                         " after " + format_quantity(f.schedule[i - 1].first, Dimension::time)});
  if (c.roller && c.field.probe_radius > 0.0 && c.field.probe_radius <= c.roller->magnet_radius)
    out.push_back({"field.probe_radius", "the probe radius " + L(c.field.probe_radius) +
                                             " lies inside the magnet (radius " + L(c.roller->magnet_radius) + ")"});
  if (c.sleeve && c.field.grid_outer_radius > 0.0 && c.field.grid_outer_radius <= c.sleeve->radius)
    out.push_back({"field.grid_outer_radius", "the grid must reach beyond the sleeve (radius " + L(c.sleeve->radius) +
                                                  "), found " + L(c.field.grid_outer_radius)});
  if (c.field.mesh_size_sleeve > c.field.mesh_size_far)
    out.push_back({"field.mesh_size_sleeve", "the sleeve mesh size should not exceed the far-field size " +
                                                 L(c.field.mesh_size_far)});
}

void check_dem(const Case &c, std::vector<CaseIssue> &out)
{
  const auto &d = c.dem;
  const auto T = [](double t) { return format_quantity(t, Dimension::time); };
  if (d.time_step > 0.0 && d.magnetic_refresh > 0.0 && d.magnetic_refresh < d.time_step)
    out.push_back({"dem.magnetic_refresh", "the refresh interval " + T(d.magnetic_refresh) +
                                               " is shorter than the time step " + T(d.time_step)});
  if (d.time_step > 0.0 && d.duration > 0.0 && d.duration < d.time_step)
    out.push_back({"dem.duration", "the duration " + T(d.duration) + " is shorter than one time step " + T(d.time_step)});
  if (d.time_step > 0.0 && d.output_interval > 0.0 && d.output_interval < d.time_step)
    out.push_back({"dem.output_interval", "the output interval " + T(d.output_interval) +
                                              " is shorter than the time step " + T(d.time_step)});
}

// The averaging windows of the measurements a run makes: each averages its samples from its
// average_from to the end of the run, dem.duration, so a window that starts at or after the end,
// or holds less than one sample interval (or, for the developed image, less than one block: an
// image period of drum travel), would report a mean of nothing. Only the measurements the scene
// has are checked: the conditions are those of the measurements' applies() in dem/measurements/.
void check_averaging_windows(const Case &c, std::vector<CaseIssue> &out)
{
  const double duration = c.dem.duration;
  if (!(duration > 0.0) || c.dem.leg)
    return; // no run, or a first leg: the windows may open after it, in the run that continues it
  const auto T = [](double t) { return format_quantity(t, Dimension::time); };
  const bool slab = c.sleeve && c.dem.periodic_length > 0.0;
  const bool nip = slab && c.drum.present;
  const bool toner = std::any_of(c.populations.begin(), c.populations.end(),
                                 [](const Population &p) { return p.kind == ParticleKind::toner; });
  const bool doctor_blade = std::any_of(c.blades.begin(), c.blades.end(),
                                        [](const BladeOrGuide &b) { return b.is_doctor_blade; });
  struct Window
  {
    bool applies;
    const char *section; // "nip": keys nip.average_from, nip.sample_interval
    const char *what;    // "the nip profiles"
    double from, interval;
  };
  const Window windows[] = {
      {nip, "nip", "the nip profiles", c.nip.average_from, c.nip.sample_interval},
      {nip && c.electric.enabled && toner, "development", "the developed toner", c.development.average_from,
       c.development.sample_interval},
      {slab && (doctor_blade || c.dma.release_from != c.dma.release_to), "dma", "the developer on the sleeve",
       c.dma.average_from, c.dma.sample_interval},
      {c.flow.inflow() || c.flow.outflow(), "flow_report", "the flow report", c.flow.average_from,
       c.flow.sample_interval},
  };
  for (const Window &w : windows)
  {
    if (!w.applies)
      continue;
    const std::string section = w.section, from_key = section + ".average_from",
                      interval_key = section + ".sample_interval";
    const std::string from = from_key + " = " + T(w.from), end = "dem.duration = " + T(duration);
    if (w.from >= duration)
      out.push_back({from_key, "the averaging window of " + std::string(w.what) + " starts at or after the end of the run (" +
                                   from + ", " + end + "): its means would average no sample; set " + from_key +
                                   " below dem.duration, or run longer (a first leg of a run to be continued: "
                                   "dem.leg: true)"});
    else if (duration - w.from < w.interval)
      out.push_back({from_key, "the averaging window of " + std::string(w.what) + " (" + from + " to " + end + ": " +
                                   T(duration - w.from) + ") is shorter than one sample interval (" + interval_key +
                                   " = " + T(w.interval) + "): its means would average at most one sample"});
  }
  // The developed image averaged in blocks fixed to the drum (development.average_over:
  // image_periods): a striped image's blocks are its periods, a uniform image's (solid or dark)
  // development.block_length. The window must let the drum carry at least one block past the
  // measuring line, or no whole block is averaged.
  const LatentImage &image = c.electric.image;
  const bool striped = image.striped();
  const double block = striped ? image.period : c.development.block_length;
  const double drum_speed = std::abs(c.drum.omega()) * c.drum.radius;
  if (nip && c.electric.enabled && toner && c.development.average_over == "image_periods" && block > 0.0 &&
      c.development.average_from < duration && drum_speed > 0.0)
  {
    const double block_time = block / drum_speed;
    if (duration - c.development.average_from < block_time)
      out.push_back({"development.average_from",
                     "the averaging window (development.average_from = " + T(c.development.average_from) +
                         " to dem.duration = " + T(duration) + ": " + T(duration - c.development.average_from) +
                         ") is shorter than one block of the developed image's means (" +
                         (striped ? "one image period, electric.image.period = " : "development.block_length = ") +
                         format_quantity(block, Dimension::length) + " of drum surface at " +
                         format_quantity(drum_speed, Dimension::velocity) + ": " + T(block_time) +
                         "): no whole block would be averaged"});
  }
  // A plate-compression row is the mean of the samples in its window.
  if (c.scene == "box" && c.compression.average_window < c.compression.sample_interval)
    out.push_back({"compression.average_window", "the averaging window compression.average_window = " +
                                                     T(c.compression.average_window) +
                                                     " is shorter than one sample interval (compression.sample_interval = " +
                                                     T(c.compression.sample_interval) + "): a row would average at most one sample"});
}

void check_flow(const Case &c, std::vector<CaseIssue> &out)
{
  const FlowSettings &f = c.flow;
  if (f.inflow_sump_mass > 0.0 && f.inflow_supply != "sump")
    out.push_back({"inflow.sump_mass", "a finite sump needs inflow.supply: sump (a fixed supply feeds exactly "
                                       "inflow.areal_mass and has no stock to run out of)"});
  if (f.inflow_prefill_no_room != "refuse" && f.inflow_prefill_arc <= 0.0)
    out.push_back({"inflow.prefill_where_no_room", "applies to the prefilled layer: set inflow.prefill_arc"});
  if (f.inflow_prefill_arc > 0.0 && !f.inflow())
    out.push_back({"inflow.prefill_arc", "the prefill is the inflow's layer: set inflow.areal_mass"});
}

void check_measurements(const Case &c, std::vector<CaseIssue> &out)
{
  const auto L = [](double x) { return format_quantity(x, Dimension::length); };
  if (c.development.measure_to <= c.development.measure_from)
    out.push_back({"development.measure_to", "the measuring window ends at " + L(c.development.measure_to) +
                                                 ", not downstream of its start " + L(c.development.measure_from)});
  const LatentImage &image = c.electric.image;
  if (c.development.average_over == "image_periods" && !image.striped() && !(c.development.block_length > 0.0))
    out.push_back({"development.average_over",
                   std::string("image_periods on a uniform image (") + (image.solid() ? "solid: duty 1" : "dark") +
                       ") needs the drum length of a block: set development.block_length, or strips "
                       "(electric.image.period > 0 and 0 < duty < 1)"});
  if (c.development.block_length > 0.0 && image.striped())
    out.push_back({"development.block_length", "the blocks of a striped image are its periods (electric.image.period); "
                                               "block_length is for a uniform image (duty 1 or 0)"});
}

} // namespace

double polygon_signed_area(const std::vector<Vec2> &p)
{
  double a = 0.0;
  for (size_t i = 0; i < p.size(); ++i)
  {
    const Vec2 &u = p[i], &v = p[(i + 1) % p.size()];
    a += u[0] * v[1] - v[0] * u[1];
  }
  return 0.5 * a;
}

bool polygon_is_simple(const std::vector<Vec2> &p)
{
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
    {
      if (j == i + 1 || (i == 0 && j == n - 1))
        continue; // neighbours share a corner
      if (segments_intersect(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]))
        return false;
    }
  return true;
}

bool polygon_contains(const std::vector<Vec2> &p, const Vec2 &q)
{
  bool inside = false;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    if (((p[i][1] > q[1]) != (p[j][1] > q[1])) &&
        q[0] < (p[j][0] - p[i][0]) * (q[1] - p[i][1]) / (p[j][1] - p[i][1]) + p[i][0])
      inside = !inside;
  return inside;
}

double polygon_distance_to_point(const std::vector<Vec2> &p, const Vec2 &q)
{
  if (polygon_contains(p, q))
    return 0.0;
  double d = std::numeric_limits<double>::max();
  for (size_t i = 0; i < p.size(); ++i)
    d = std::min(d, segment_distance(p[i], p[(i + 1) % p.size()], q));
  return d;
}

std::vector<Vec2> generated_blade_polygon(double R, double angle, double gap, double thickness, double length)
{
  const Vec2 u{std::cos(angle), std::sin(angle)}, n{-std::sin(angle), std::cos(angle)};
  const double r0 = R + gap, r1 = R + gap + length, h = 0.5 * thickness;
  auto at = [&](double r, double s) { return Vec2{r * u[0] + s * n[0], r * u[1] + s * n[1]}; };
  return {at(r0, -h), at(r1, -h), at(r1, h), at(r0, h)};
}

std::vector<CaseIssue> validate_case(const Case &c)
{
  std::vector<CaseIssue> out;
  check_scene(c, out);
  check_roller(c, out);
  check_drum(c, out);
  check_blades(c, out);
  check_planes(c, out);
  check_populations(c, out);
  check_fields(c, out);
  check_dem(c, out);
  check_averaging_windows(c, out);
  check_flow(c, out);
  check_measurements(c, out);
  return out;
}

} // namespace magbrush
