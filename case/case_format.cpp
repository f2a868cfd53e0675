// Printing a resolved case, its derived numbers, and the schema reference.
#include "case/case_format.h"

#include "case/case_schema.h"
#include "case/units.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

namespace magbrush {

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double mu0 = 4.0e-7 * pi;

std::string exact(double v)
{
  char b[40];
  std::snprintf(b, sizeof(b), "%.17g", v);
  return b;
}

// Collects entries, taking type and dimension from the schema pattern.
class Emitter
{
public:
  std::vector<ResolvedEntry> entries;

  void q(const std::string &path, const std::string &pattern, double si)
  {
    const Dimension d = spec(pattern).dimension;
    entries.push_back({path, pattern, exact(si), format_quantity(si, d)});
  }
  void i(const std::string &path, const std::string &pattern, long long v)
  {
    spec(pattern);
    entries.push_back({path, pattern, std::to_string(v), std::to_string(v)});
  }
  void b(const std::string &path, const std::string &pattern, bool v)
  {
    spec(pattern);
    entries.push_back({path, pattern, v ? "true" : "false", v ? "true" : "false"});
  }
  void s(const std::string &path, const std::string &pattern, const std::string &v)
  {
    spec(pattern);
    entries.push_back({path, pattern, v, v.empty() ? "\"\"" : v});
  }
  void v3(const std::string &path, const std::string &pattern, const Vec3 &v)
  {
    const Dimension d = spec(pattern).dimension;
    entries.push_back({path, pattern, "[" + exact(v[0]) + ", " + exact(v[1]) + ", " + exact(v[2]) + "]",
                       "[" + format_quantity(v[0], d) + ", " + format_quantity(v[1], d) + ", " +
                           format_quantity(v[2], d) + "]"});
  }
  void polygon(const std::string &path, const std::string &pattern, const std::vector<Vec2> &p)
  {
    spec(pattern);
    std::string e = "[", s = "[";
    for (size_t k = 0; k < p.size(); ++k)
    {
      e += std::string(k ? ", " : "") + "[" + exact(p[k][0]) + ", " + exact(p[k][1]) + "]";
      s += std::string(k ? ", " : "") + "[" + format_quantity(p[k][0], Dimension::length) + ", " +
           format_quantity(p[k][1], Dimension::length) + "]";
    }
    entries.push_back({path, pattern, e + "]", s + "]"});
  }

private:
  static const KeySpec &spec(const std::string &pattern)
  {
    const KeySpec *k = find_key_spec(pattern);
    if (!k)
      throw std::logic_error("case_format: '" + pattern + "' is not in the schema");
    return *k;
  }
};

} // namespace

std::vector<ResolvedEntry> resolved_entries(const Case &c)
{
  Emitter e;
  e.s("name", "name", c.name);
  e.s("scene", "scene", c.scene);
  e.s("measured_flux_file", "measured_flux_file", c.measured_flux_file);
  e.q("measured_flux_angle_origin", "measured_flux_angle_origin", c.measured_flux_angle_origin);
  if (c.roller)
  {
    const Roller &r = *c.roller;
    e.q("roller.shaft_radius", "roller.shaft_radius", r.shaft_radius);
    e.q("roller.shaft_mu_r", "roller.shaft_mu_r", r.shaft_mu_r);
    e.q("roller.magnet_radius", "roller.magnet_radius", r.magnet_radius);
    e.q("roller.magnet_mu_r", "roller.magnet_mu_r", r.magnet_mu_r);
    for (const auto &p : r.poles)
    {
      const std::string at = "roller.poles." + p.name;
      e.s(at + ".name", "roller.poles[].name", p.name);
      e.q(at + ".angle", "roller.poles[].angle", p.angle);
      e.q(at + ".strength", "roller.poles[].strength", p.strength);
      e.q(at + ".shape_factor", "roller.poles[].shape_factor", p.shape_factor);
    }
  }
  if (c.sleeve)
  {
    e.q("sleeve.radius", "sleeve.radius", c.sleeve->radius);
    e.q("sleeve.thickness", "sleeve.thickness", c.sleeve->thickness);
    e.q("sleeve.rpm", "sleeve.rpm", c.sleeve->omega());
    e.q("sleeve.spin_up_time", "sleeve.spin_up_time", c.sleeve->spin_up_time);
  }
  if (c.drum.present)
  {
    e.q("drum.radius", "drum.radius", c.drum.radius);
    e.q("drum.rpm", "drum.rpm", c.drum.omega());
    e.q("drum.spin_up_time", "drum.spin_up_time", c.drum.spin_up_time);
    e.q("drum.gap", "drum.gap", c.drum.gap);
    e.q("drum.angle", "drum.angle", c.drum.angle);
    e.q("drum.pc_thickness", "drum.pc_thickness", c.drum.pc_thickness);
    e.q("drum.pc_eps_r", "drum.pc_eps_r", c.drum.pc_eps_r);
  }
  for (const auto &b : c.blades)
  {
    const std::string at = "blades." + b.name;
    e.s(at + ".name", "blades[].name", b.name);
    e.s(at + ".kind", "blades[].kind", b.is_doctor_blade ? "doctor_blade" : "guide");
    e.polygon(at + ".profile", "blades[].profile", b.polygon);
    e.q(at + ".gap", "blades[].gap", b.gap);
    e.q(at + ".mu_r", "blades[].mu_r", b.mu_r);
    e.s(at + ".material", "blades[].material", b.material);
  }
  for (const auto &p : c.planes)
  {
    const std::string at = "planes." + p.name;
    e.s(at + ".name", "planes[].name", p.name);
    e.v3(at + ".point", "planes[].point", p.point);
    e.v3(at + ".normal", "planes[].normal", p.normal);
    e.s(at + ".material", "planes[].material", p.material);
    for (size_t k = 0; k < p.path.size(); ++k)
    {
      const std::string s = at + ".path[" + std::to_string(k) + "]";
      e.q(s + ".time", "planes[].path[].time", p.path[k].first);
      e.v3(s + ".displacement", "planes[].path[].displacement", p.path[k].second);
    }
  }
  for (const auto &m : c.materials)
  {
    const std::string at = "materials." + m.name;
    e.q(at + ".youngs_modulus", "materials.*.youngs_modulus", m.youngs_modulus);
    e.q(at + ".poisson_ratio", "materials.*.poisson_ratio", m.poisson_ratio);
    e.q(at + ".density", "materials.*.density", m.density);
    e.q(at + ".mu_r", "materials.*.mu_r", m.mu_r);
    e.q(at + ".saturation_magnetisation", "materials.*.saturation_magnetisation", m.saturation_magnetisation);
    e.q(at + ".friction", "materials.*.friction", m.friction);
    e.q(at + ".rolling_friction", "materials.*.rolling_friction", m.rolling_friction);
    e.i(at + ".polygon_angles", "materials.*.polygon_angles", m.polygon_angles);
    e.q(at + ".damping", "materials.*.damping", m.damping);
    e.q(at + ".restitution", "materials.*.restitution", m.restitution);
    e.q(at + ".hamaker", "materials.*.hamaker", m.hamaker);
    e.q(at + ".adhesion_radius", "materials.*.adhesion_radius", m.adhesion_radius);
  }
  for (const auto &p : c.populations)
  {
    const std::string at = "populations." + p.name;
    e.s(at + ".name", "populations[].name", p.name);
    e.s(at + ".kind", "populations[].kind", p.kind == ParticleKind::toner ? "toner" : "carrier");
    e.s(at + ".material", "populations[].material", p.material);
    e.q(at + ".diameter", "populations[].diameter", p.diameter_mean);
    e.q(at + ".diameter_std", "populations[].diameter_std", p.diameter_std);
    e.i(at + ".count", "populations[].count", p.count);
    e.q(at + ".mass", "populations[].mass", p.mass);
    e.q(at + ".concentration", "populations[].concentration", p.concentration);
    e.q(at + ".charge_to_mass", "populations[].charge_to_mass", p.charge_to_mass);
    e.q(at + ".charge_to_mass_std", "populations[].charge_to_mass_std", p.charge_to_mass_std);
    e.q(at + ".wrong_sign_fraction", "populations[].wrong_sign_fraction", p.wrong_sign_fraction);
    e.b(at + ".counter_charge", "populations[].counter_charge", p.counter_charge);
    e.b(at + ".attached", "populations[].attached", p.attached);
    e.q(at + ".carried_until_gap", "populations[].carried_until_gap", p.carried_until_gap);
    if (p.insert_box)
    {
      const auto &bx = *p.insert_box;
      std::string ex = "[", pr = "[";
      for (int k = 0; k < 2; ++k)
      {
        ex += std::string(k ? ", " : "") + "[" + exact(bx[k][0]) + ", " + exact(bx[k][1]) + ", " + exact(bx[k][2]) + "]";
        pr += std::string(k ? ", " : "") + "[" + format_quantity(bx[k][0], Dimension::length) + ", " +
              format_quantity(bx[k][1], Dimension::length) + ", " + format_quantity(bx[k][2], Dimension::length) + "]";
      }
      e.entries.push_back({at + ".insert_box", "populations[].insert_box", ex + "]", pr + "]"});
    }
    e.q(at + ".layer_thickness", "populations[].layer_thickness", p.layer_thickness);
  }
  for (std::size_t k = 0; k < c.adhesion_pairs.size(); ++k)
  {
    const AdhesionPair &a = c.adhesion_pairs[k];
    const std::string at = "adhesion_pairs[" + std::to_string(k) + "]";
    e.s(at + ".material_a", "adhesion_pairs[].material_a", a.material_a);
    e.s(at + ".material_b", "adhesion_pairs[].material_b", a.material_b);
    e.q(at + ".hamaker", "adhesion_pairs[].hamaker", a.hamaker);
  }
  e.b("electric.enabled", "electric.enabled", c.electric.enabled);
  e.q("electric.bias", "electric.bias", c.electric.bias);
  const auto &im = c.electric.image;
  if (im.kind == LatentImage::Kind::surface_potential)
  {
    e.q("electric.image.dark_potential", "electric.image.dark_potential", im.dark_value);
    e.q("electric.image.light_potential", "electric.image.light_potential", im.light_value);
  }
  else if (im.kind == LatentImage::Kind::surface_charge)
  {
    e.q("electric.image.dark_charge", "electric.image.dark_charge", im.dark_value);
    e.q("electric.image.light_charge", "electric.image.light_charge", im.light_value);
  }
  e.q("electric.image.period", "electric.image.period", im.period);
  e.q("electric.image.duty", "electric.image.duty", im.duty);
  e.b("electric.coulomb", "electric.coulomb", c.electric.coulomb);
  e.i("electric.coulomb_order", "electric.coulomb_order", c.electric.coulomb_order);
  e.q("electric.coulomb_cell", "electric.coulomb_cell", c.electric.coulomb_cell);
  e.q("electric.coulomb_refresh", "electric.coulomb_refresh", c.electric.coulomb_refresh);
  e.b("electric.conductor_images", "electric.conductor_images", c.electric.conductor_images);
  e.i("electric.pair_image_terms", "electric.pair_image_terms", c.electric.pair_image_terms);
  e.q("electric.hold_distance", "electric.hold_distance", c.electric.hold_distance);
  e.s("electric.coulomb_hold_frame", "electric.coulomb_hold_frame",
      c.electric.coulomb_hold_frame == Electric::HoldFrame::sleeve ? "sleeve" : "lab");
  e.q("electric.image.edge_width", "electric.image.edge_width", im.edge_width);

  const auto &f = c.applied_field;
  e.s("applied_field.kind", "applied_field.kind",
      f.kind == AppliedField::Kind::roller ? "roller" : f.kind == AppliedField::Kind::uniform ? "uniform" : "none");
  e.v3("applied_field.direction", "applied_field.direction", f.uniform_direction);
  if (f.schedule.empty())
  {
    e.q("applied_field.magnitude", "applied_field.magnitude", f.uniform_magnitude);
    e.q("applied_field.ramp_time", "applied_field.ramp_time", f.ramp_time);
  }
  for (std::size_t k = 0; k < f.schedule.size(); ++k)
  {
    const std::string s = "applied_field.schedule[" + std::to_string(k) + "]";
    e.q(s + ".time", "applied_field.schedule[].time", f.schedule[k].first);
    e.q(s + ".magnitude", "applied_field.schedule[].magnitude", f.schedule[k].second);
  }

  const auto &fs = c.field;
  e.q("field.mesh_size_far", "field.mesh_size_far", fs.mesh_size_far);
  e.q("field.mesh_size_sleeve", "field.mesh_size_sleeve", fs.mesh_size_sleeve);
  e.q("field.mesh_size_gap", "field.mesh_size_gap", fs.mesh_size_gap);
  e.i("field.element_degree", "field.element_degree", fs.element_degree);
  e.q("field.outer_radius_factor", "field.outer_radius_factor", fs.outer_radius_factor);
  e.q("field.grid_radial_spacing", "field.grid_radial_spacing", fs.grid_radial_spacing);
  e.q("field.grid_angular_spacing", "field.grid_angular_spacing", fs.grid_angular_spacing);
  e.q("field.grid_outer_radius", "field.grid_outer_radius", fs.grid_outer_radius);
  e.q("field.grid_electric_spacing", "field.grid_electric_spacing", fs.grid_electric_spacing);
  e.i("field.electric_phase_samples", "field.electric_phase_samples", fs.electric_phase_samples);
  e.q("field.probe_radius", "field.probe_radius", fs.probe_radius);
  e.s("field.output_dir", "field.output_dir", fs.output_dir);

  const auto &d = c.dem;
  e.q("dem.time_step", "dem.time_step", d.time_step);
  e.q("dem.time_step_safety", "dem.time_step_safety", d.time_step_safety);
  e.q("dem.duration", "dem.duration", d.duration);
  e.q("dem.output_interval", "dem.output_interval", d.output_interval);
  e.q("dem.checkpoint_interval", "dem.checkpoint_interval", d.checkpoint_interval);
  e.q("dem.checkpoint_wall_interval", "dem.checkpoint_wall_interval", d.checkpoint_wall_interval);
  e.q("dem.periodic_length", "dem.periodic_length", d.periodic_length);
  e.q("dem.periodic_length_x", "dem.periodic_length_x", d.periodic_length_x);
  e.q("dem.periodic_length_y", "dem.periodic_length_y", d.periodic_length_y);
  e.s("dem.magnetic_model", "dem.magnetic_model", d.magnetic_model);
  e.q("dem.magnetic_cutoff", "dem.magnetic_cutoff", d.magnetic_cutoff);
  e.q("dem.magnetic_refresh", "dem.magnetic_refresh", d.magnetic_refresh);
  e.q("dem.magnetic_tolerance", "dem.magnetic_tolerance", d.magnetic_tolerance);
  e.q("dem.verlet_skin", "dem.verlet_skin", d.verlet_skin);
  e.s("dem.magnetic_far_field", "dem.magnetic_far_field", d.magnetic_far_field);
  e.i("dem.magnetic_far_order", "dem.magnetic_far_order", d.magnetic_far_order);
  e.q("dem.magnetic_far_cell", "dem.magnetic_far_cell", d.magnetic_far_cell);
  e.q("dem.magnetic_staleness", "dem.magnetic_staleness", d.magnetic_staleness);
  e.s("dem.magnetic_staleness_mode", "dem.magnetic_staleness_mode", d.magnetic_staleness_mode);
  e.s("dem.magnetic_hold", "dem.magnetic_hold", d.magnetic_hold);
  e.q("dem.magnetic_skin", "dem.magnetic_skin", d.magnetic_skin);
  e.i("dem.magnetic_live_steps", "dem.magnetic_live_steps", d.magnetic_live_steps);
  e.q("dem.air_viscosity", "dem.air_viscosity", d.air_viscosity);
  e.v3("dem.gravity", "dem.gravity", d.gravity);
  e.i("dem.seed", "dem.seed", static_cast<long long>(d.seed));
  e.i("dem.threads", "dem.threads", d.threads);
  e.q("dem.max_overlap_fraction", "dem.max_overlap_fraction", d.max_overlap_fraction);
  e.s("dem.restitution_model", "dem.restitution_model", d.restitution_model);
  e.b("dem.leg", "dem.leg", d.leg);
  e.q("dem.settle_time", "dem.settle_time", d.settle_time);
  e.q("dem.max_kinetic_energy_growth", "dem.max_kinetic_energy_growth", d.max_kinetic_energy_growth);
  e.q("dem.adhesion_cutoff", "dem.adhesion_cutoff", d.adhesion_cutoff);
  e.q("dem.adhesion_range_fraction", "dem.adhesion_range_fraction", d.adhesion_range_fraction);
  e.q("dem.toner_stiffness_factor", "dem.toner_stiffness_factor", d.toner_stiffness_factor);
  e.i("dem.toner_substeps", "dem.toner_substeps", d.toner_substeps);

  const FlowSettings &flow = c.flow;
  e.s("inflow.population", "inflow.population", flow.inflow_population);
  e.q("inflow.areal_mass", "inflow.areal_mass", flow.inflow_areal_mass);
  e.q("inflow.angle", "inflow.angle", flow.inflow_angle);
  e.q("inflow.layer_height", "inflow.layer_height", flow.inflow_layer_height);
  e.s("inflow.supply", "inflow.supply", flow.inflow_supply);
  e.q("inflow.prefill_arc", "inflow.prefill_arc", flow.inflow_prefill_arc);
  e.s("inflow.prefill_where_no_room", "inflow.prefill_where_no_room", flow.inflow_prefill_no_room);
  e.q("inflow.sump_mass", "inflow.sump_mass", flow.inflow_sump_mass);
  e.q("inflow.interval", "inflow.interval", flow.interval);
  e.q("outflow.angle", "outflow.angle", flow.outflow_angle);
  e.q("outflow.width", "outflow.width", flow.outflow_width);
  e.q("outflow.outer_radius", "outflow.outer_radius", flow.outflow_radius);
  e.q("flow_report.sample_interval", "flow_report.sample_interval", flow.sample_interval);
  e.q("flow_report.flux_angle", "flow_report.flux_angle", flow.flux_angle);
  e.q("flow_report.density_window", "flow_report.density_window", flow.density_window);
  e.q("flow_report.average_from", "flow_report.average_from", flow.average_from);
  e.q("development.measure_from", "development.measure_from", c.development.measure_from);
  e.q("development.measure_to", "development.measure_to", c.development.measure_to);
  e.q("development.sample_interval", "development.sample_interval", c.development.sample_interval);
  e.q("development.average_from", "development.average_from", c.development.average_from);
  e.s("development.average_over", "development.average_over", c.development.average_over);
  e.i("development.phase_bins", "development.phase_bins", c.development.phase_bins);
  e.q("development.block_length", "development.block_length", c.development.block_length);
  e.q("dma.after_blade", "dma.after_blade", c.dma.after_blade);
  e.q("dma.window", "dma.window", c.dma.window);
  e.q("dma.height", "dma.height", c.dma.height);
  e.q("dma.front_window", "dma.front_window", c.dma.front_window);
  e.q("dma.release_from", "dma.release_from", c.dma.release_from);
  e.q("dma.release_to", "dma.release_to", c.dma.release_to);
  e.q("dma.sample_interval", "dma.sample_interval", c.dma.sample_interval);
  e.q("dma.average_from", "dma.average_from", c.dma.average_from);
  e.q("statistics.steady_drift", "statistics.steady_drift", c.statistics.steady_drift);
  e.i("statistics.blocks", "statistics.blocks", c.statistics.blocks);
  e.q("nip.average_from", "nip.average_from", c.nip.average_from);
  e.q("nip.sample_interval", "nip.sample_interval", c.nip.sample_interval);
  e.q("nip.bin_width", "nip.bin_width", c.nip.bin_width);
  e.q("nip.half_width", "nip.half_width", c.nip.half_width);
  e.q("nip.chain_bin_angle", "nip.chain_bin_angle", c.nip.chain_bin_angle);
  e.q("nip.chain_half_angle", "nip.chain_half_angle", c.nip.chain_half_angle);

  const auto &m = c.compression;
  e.s("compression.plate", "compression.plate", m.plate);
  e.s("compression.stage", "compression.stage", m.stage);
  e.q("compression.sample_interval", "compression.sample_interval", m.sample_interval);
  e.q("compression.average_window", "compression.average_window", m.average_window);
  e.q("compression.map_interval", "compression.map_interval", m.map_interval);

  e.s("output.directory", "output.directory", c.output.directory);
  e.b("output.vtu", "output.vtu", c.output.vtu);
  e.b("output.xdmf", "output.xdmf", c.output.xdmf);
  return e.entries;
}

std::string format_case(const Case &c)
{
  const auto entries = resolved_entries(c);
  size_t width = 0;
  for (const auto &e : entries)
    width = std::max(width, e.path.size());
  std::ostringstream out;
  for (const auto &e : entries)
    out << e.path << std::string(width - e.path.size() + 1, ' ') << "= " << e.pretty << "\n";
  return out.str();
}

namespace {

std::string fmt(const char *format, double v)
{
  char b[64];
  std::snprintf(b, sizeof(b), format, v);
  return b;
}

} // namespace

std::string format_derived(const Case &c)
{
  std::ostringstream out;
  const auto V = [](double v) { return format_quantity(v, Dimension::velocity); };
  if (c.sleeve)
    out << "sleeve surface speed        " << V(c.sleeve->surface_speed()) << "\n";
  if (c.drum.present)
  {
    out << "drum surface speed          " << V(std::abs(c.drum.omega()) * c.drum.radius) << "\n";
    if (c.sleeve)
    {
      // Tangential surface velocities at the nip along t = (-sin a, cos a): the sleeve point
      // R u moves at omega_s R, the drum point c - R_d u at -omega_d R_d.
      const double vs = c.sleeve->omega() * c.sleeve->radius;
      const double vd = -c.drum.omega() * c.drum.radius;
      out << "relative speed at the nip   " << V(std::abs(vs - vd)) << "  (surfaces move "
          << (vs * vd > 0 ? "in the same direction" : vs * vd < 0 ? "in opposite directions" : "-")
          << " at the nip)\n";
      const Vec2 centre = c.drum.center(c.sleeve->radius);
      out << "drum centre                 (" << format_quantity(centre[0], Dimension::length) << ", "
          << format_quantity(centre[1], Dimension::length) << ")\n";
    }
  }
  if (c.applied_field.kind == AppliedField::Kind::uniform)
  {
    const double b = c.applied_field.uniform_magnitude;
    out << "uniform field B^2/2mu0      " << format_quantity(b * b / (2.0 * mu0), Dimension::pressure) << "\n";
  }
  // Populations: mean sphere volume uses <d^3> = mu^3 + 3 mu sigma^2 (normal distribution).
  double carrier_mass = 0.0;
  std::vector<std::pair<double, double>> count_mass(c.populations.size());
  for (size_t i = 0; i < c.populations.size(); ++i)
  {
    const auto &p = c.populations[i];
    double rho = 0.0;
    for (const auto &m : c.materials)
      if (m.name == p.material)
        rho = m.density;
    const double d3 = std::pow(p.diameter_mean, 3) + 3.0 * p.diameter_mean * p.diameter_std * p.diameter_std;
    const double one = rho * pi / 6.0 * d3;
    double n = static_cast<double>(p.count), mass = p.mass;
    if (p.count > 0)
      mass = n * one;
    else if (p.mass > 0.0 && one > 0.0)
      n = p.mass / one;
    count_mass[i] = {n, mass};
    if (p.kind == ParticleKind::carrier)
      carrier_mass += mass;
  }
  // The populations' masses, then their charges: a wrong-sign fraction f reverses the charge
  // of that share, so the expected total is (1 − 2f) (q/m) m; counter-charged carriers carry
  // minus the sum of all the others.
  for (size_t i = 0; i < c.populations.size(); ++i)
  {
    const auto &p = c.populations[i];
    if (p.concentration > 0.0)
      count_mass[i].second = p.concentration * carrier_mass;
  }
  double charged_total = 0.0;
  for (size_t i = 0; i < c.populations.size(); ++i)
    charged_total += (1.0 - 2.0 * c.populations[i].wrong_sign_fraction) * c.populations[i].charge_to_mass *
                     count_mass[i].second;
  for (size_t i = 0; i < c.populations.size(); ++i)
  {
    const auto &p = c.populations[i];
    auto [n, mass] = count_mass[i];
    if (p.concentration > 0.0)
    {
      mass = p.concentration * carrier_mass;
      double rho = 0.0;
      for (const auto &m : c.materials)
        if (m.name == p.material)
          rho = m.density;
      const double d3 = std::pow(p.diameter_mean, 3) + 3.0 * p.diameter_mean * p.diameter_std * p.diameter_std;
      n = rho > 0.0 ? mass / (rho * pi / 6.0 * d3) : 0.0;
    }
    out << "population " << p.name << ": " << fmt("%.0f", n) << " particles, "
        << format_quantity(mass, Dimension::mass);
    const double charge = (1.0 - 2.0 * p.wrong_sign_fraction) * p.charge_to_mass * mass;
    if (p.charge_to_mass != 0.0)
      out << ", total charge " << format_quantity(charge, Dimension::charge) << ", mean particle charge "
          << format_quantity(n > 0 ? charge / n : 0.0, Dimension::charge);
    if (p.counter_charge)
      out << ", counter-charge of all counter-charged carriers " << format_quantity(-charged_total, Dimension::charge);
    out << "\n";
  }
  if (c.dem.time_step > 0.0 && c.dem.duration > 0.0)
    out << "time steps                  " << fmt("%.0f", c.dem.duration / c.dem.time_step) << "\n";
  return out.str();
}

std::string format_schema(bool markdown)
{
  std::ostringstream out;
  const auto affects = [](Affects a) {
    switch (a)
    {
    case Affects::magnetic: return "magnetic";
    case Affects::electric: return "electric";
    case Affects::both: return "magnetic, electric";
    default: return "";
    }
  };
  const auto default_of = [](const KeySpec &k) {
    if (k.required)
      return std::string("required");
    return k.default_text.empty() ? std::string("-") : k.default_text;
  };
  if (markdown)
  {
    out << "# Case file reference\n\n"
           "Generated by `magbrush check --explain --markdown` from the schema: the keys each module "
           "declares in `case/case_keys_<module>.cpp` (listed in `case/case_keys.h`); do not edit by hand.\n\n"
           "Values carry units (`25 mm`, `219 rpm`, `130 mT`, `-600 V`, `60 um`, `-30 uC/g`): a key with a unit "
           "in its type column needs one, and a bare number there is an error that suggests a unit from its "
           "magnitude (`gap: 0.3` is refused with \"0.3 mm?\"), in the file and in `--set` alike. A bare `0` "
           "is accepted for every key, since zero is zero in every unit; plain numbers (type `number`) are "
           "written bare. Units: m, s, g, rad, deg, rpm, Hz, N, Pa, J, C, V, T, G (gauss), A, %, "
           "with prefixes f p n u (or µ) m c k M G, combined with `*`, `/` and `^` (`kg/m^3`, `Pa*s`).\n"
           "List elements are addressed by name in key paths and overrides: "
           "`magbrush check case.yaml --set roller.poles.N1.angle=95deg`.\n\n"
           "## Conventions\n\n"
           "* Roller frame: the roller axis is z, the roller centre is the origin, angles are counter-clockwise "
           "from +x; a positive rpm turns counter-clockwise seen from +z. Sleeve and drum usually turn in "
           "opposite senses, so that their surfaces move the same way at the nip.\n"
           "* Poles: `{name, angle, strength}`; north = positive strength, south = negative, or an unsigned "
           "strength with `polarity: N|S`. `shape_factor` defaults to `roller.shape_factor`. Poles must be at "
           "least 10 deg apart.\n"
           "* Sleeve and drum: give `radius` or `diameter` (an override of one replaces the other).\n"
           "* Blades and guides: either a `profile` polygon in the roller frame, or `angle` + `gap` + "
           "`thickness` + `length` (a radial plate whose tip is `gap` from the sleeve). A profile's `gap`, if "
           "given, must match the polygon.\n"
           "* Walls touching particles take their contact properties from the materials `sleeve`, `drum` "
           "and (blades, planes) their `material`.\n"
           "* Populations: exactly one of `count`, `mass`, `concentration` (toner: toner mass / carrier mass); "
           "toner needs `charge_to_mass`; the size distribution must satisfy mean - 3 std >= 0.\n"
           "* Averaging windows: each measurement the scene has (`nip`, `development`, `dma`, `flow_report`) "
           "averages its samples from its `average_from` to the end of the run, `dem.duration`. A window that "
           "starts at or after the end, or is shorter than the measurement's `sample_interval` (the developed "
           "image over `image_periods`: shorter than one block of drum travel, an image period or, on a uniform "
           "image, `development.block_length`), is refused, as is a "
           "`compression.average_window` shorter than `compression.sample_interval`. A run that is the first leg "
           "of a longer one (continued with `--resume` or `--restart`; a sweep's spin-up) says so with "
           "`dem.leg: true`, and its windows may then lie after its end.\n\n"
           "## Checking and overriding\n\n"
           "`magbrush check CASE` validates the file and prints every resolved key as `path = value`; each "
           "line works as an override: `--set path=value` (list elements by name, or `[i]` for unnamed "
           "ones, e.g. `planes.plate.path[2].time=5ms`). Errors name `file:line:column` (or the override), "
           "the key path, what was expected and what was found; exit status 1 for an invalid case, 2 for a "
           "usage error.\n\n"
           "## Keys\n\n"
           "The `field` column says which stored field must be recomputed when the key changes "
           "(`field_hash` in `case/case_hash.h`; a non-magnetic blade does not change the magnetic field).\n\n"
           "| key | type | default | range | field | meaning |\n|---|---|---|---|---|---|\n";
    for (const auto &k : case_schema())
    {
      std::string doc = k.doc, type = k.type_description();
      for (auto *s : {&doc, &type})
        for (size_t p = 0; (p = s->find('|', p)) != std::string::npos; p += 2)
          s->replace(p, 1, "\\|");
      const std::string d = default_of(k);
      out << "| `" << k.path << "` | " << type << " | " << (d == "required" || d == "-" ? d : "`" + d + "`") << " | "
          << k.range_description()
          << " | " << affects(k.affects) << " | " << doc << " |\n";
    }
    return out.str();
  }
  for (const auto &k : case_schema())
  {
    const size_t depth = static_cast<size_t>(std::count(k.path.begin(), k.path.end(), '.'));
    out << std::string(2 * depth, ' ') << last_component(k.path) << (k.is_container() ? ":" : "")
        << "  [" << k.type_description();
    if (!k.is_container() || k.required)
      out << "; " << default_of(k);
    if (!k.range_description().empty())
      out << "; " << k.range_description();
    if (k.affects != Affects::none)
      out << "; affects " << affects(k.affects) << " field";
    out << "]\n" << std::string(2 * depth + 4, ' ') << k.doc << "\n";
  }
  return out.str();
}

} // namespace magbrush
