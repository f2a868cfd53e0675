// The case-file schema table. Sections follow coupling/case_model.h; each leaf says what it
// means in one line, and which stored field (magnetic, electric) has to be recomputed when it
// changes. Defaults are written as in a case file and parsed by the same code as user input.
#include "case_schema.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace magbrush {

namespace {

constexpr double pi = 3.14159265358979323846;

// Small builder so that the table below reads like a reference card.
struct Key
{
  KeySpec spec;
  Key(std::string path, KeyType type, std::string doc)
  {
    spec.path = std::move(path);
    spec.type = type;
    spec.doc = std::move(doc);
  }
  Key &dim(Dimension d) { spec.dimension = d; return *this; }
  Key &def(std::string text) { spec.default_text = std::move(text); return *this; }
  Key &required() { spec.required = true; return *this; }
  Key &min(double v, bool inclusive = true) { spec.min = v; spec.min_inclusive = inclusive; return *this; }
  Key &max(double v, bool inclusive = true) { spec.max = v; spec.max_inclusive = inclusive; return *this; }
  Key &positive() { return min(0.0, false); }
  Key &non_negative() { return min(0.0, true); }
  Key &choices(std::vector<std::string> c) { spec.choices = std::move(c); return *this; }
  Key &affects(Affects a) { spec.affects = a; return *this; }
  operator KeySpec() const { return spec; }
};

Key section(std::string path, std::string doc) { return Key(std::move(path), KeyType::section, std::move(doc)); }
Key list(std::string path, std::string doc) { return Key(std::move(path), KeyType::list, std::move(doc)); }
Key map(std::string path, std::string doc) { return Key(std::move(path), KeyType::map, std::move(doc)); }
Key quantity(std::string path, Dimension d, std::string doc)
{
  return Key(std::move(path), KeyType::quantity, std::move(doc)).dim(d);
}
Key number(std::string path, std::string doc) { return quantity(std::move(path), Dimension::dimensionless, std::move(doc)); }
Key integer(std::string path, std::string doc) { return Key(std::move(path), KeyType::integer, std::move(doc)); }
Key boolean(std::string path, std::string doc) { return Key(std::move(path), KeyType::boolean, std::move(doc)); }
Key text(std::string path, std::string doc) { return Key(std::move(path), KeyType::string, std::move(doc)); }
Key choice(std::string path, std::vector<std::string> c, std::string doc)
{
  return Key(std::move(path), KeyType::choice, std::move(doc)).choices(std::move(c));
}
Key vector3(std::string path, Dimension d, std::string doc)
{
  return Key(std::move(path), KeyType::vector3, std::move(doc)).dim(d);
}

using D = Dimension;
using A = Affects;

std::vector<KeySpec> build_schema()
{
  return {
      text("name", "Scene name used in output file names.").def("<file stem>"),
      choice("scene", {"roller", "box"},
             "roller: sleeve with magnet roller (optional drum, blades); box: plane walls only "
             "(Kawamoto's compression test).")
          .def("roller"),
      text("measured_flux_file", "Optional gaussmeter scan (CSV: angle_deg, Bn_mT, Bt_mT) overlaid in the report; relative to the case file.")
          .def(""),
      quantity("measured_flux_angle_origin", D::angle,
               "Roller angle (counter-clockwise from +x) at which the scan's angle reads 0: roller angle = scan angle + this. "
               "`magbrush flux --fit` writes the fitted encoder offset here; every comparison with the scan applies it. About the scan only: changes no field.")
          .def("0 deg").min(-pi).max(pi),

      section("roller", "The magnet roller: a magnetised annulus on an optional soft-iron shaft (Kweon eq. 9-10)."),
      quantity("roller.shaft_radius", D::length, "Radius of the soft-iron shaft (0 = none).")
          .def("0 mm").non_negative().affects(A::magnetic),
      number("roller.shaft_mu_r", "Relative permeability of the shaft (large = ideal iron).")
          .def("1000").min(1.0).affects(A::magnetic),
      quantity("roller.magnet_radius", D::length, "Outer radius of the magnet annulus.")
          .required().positive().affects(A::magnetic),
      number("roller.magnet_mu_r", "Recoil permeability of the magnet material.")
          .def("1").min(1.0).affects(A::magnetic),
      quantity("roller.shape_factor", D::inverse_angle_squared,
               "Default Gaussian shape factor alpha of the poles, M(theta) ~ exp(-alpha (theta-phi)^2).")
          .def("10").positive().affects(A::magnetic),
      list("roller.poles", "The poles: name, angle, strength (sign or polarity gives N/S), shape factor.")
          .required().affects(A::magnetic),
      text("roller.poles[].name", "Pole name, e.g. N1 (address it in overrides: roller.poles.N1.angle).")
          .required().affects(A::magnetic),
      quantity("roller.poles[].angle", D::angle, "Pole centre, counter-clockwise from +x.")
          .required().min(0.0).max(2.0 * pi, false).affects(A::magnetic),
      quantity("roller.poles[].strength", D::magnetisation,
               "Peak radial magnetisation M_i; > 0 north (outward), < 0 south, or give polarity.")
          .required().affects(A::magnetic),
      choice("roller.poles[].polarity", {"N", "S"},
             "Optional: N or S; the strength's sign must agree or the strength is unsigned.")
          .affects(A::magnetic),
      quantity("roller.poles[].shape_factor", D::inverse_angle_squared, "Shape factor alpha of this pole.")
          .def("<roller.shape_factor>").positive().affects(A::magnetic),

      section("sleeve", "The non-magnetic rotating sleeve around the roller (give radius or diameter)."),
      quantity("sleeve.radius", D::length, "Outer radius.").positive().affects(A::both),
      quantity("sleeve.diameter", D::length, "Outer diameter (alternative to radius).")
          .positive().affects(A::both),
      quantity("sleeve.thickness", D::length, "Wall thickness (the magnet must fit inside).")
          .def("0 mm").non_negative().affects(A::both),
      quantity("sleeve.rpm", D::angular_velocity, "Rotation speed; > 0 counter-clockwise seen from +z.")
          .def("0 rpm"),
      quantity("sleeve.spin_up_time", D::time,
               "DEM: the sleeve starts from rest at t = 0 and reaches its speed linearly over this time (0 = at once).")
          .def("0 s").non_negative(),

      section("drum", "The photoreceptor drum facing the sleeve across the development gap (give radius or diameter)."),
      quantity("drum.radius", D::length, "Outer radius of the photoconductor surface.")
          .positive().affects(A::electric),
      quantity("drum.diameter", D::length, "Outer diameter (alternative to radius).")
          .positive().affects(A::electric),
      quantity("drum.rpm", D::angular_velocity, "Rotation speed; > 0 counter-clockwise seen from +z.")
          .def("0 rpm"),
      quantity("drum.spin_up_time", D::time,
               "DEM: the drum starts from rest at t = 0 and reaches its speed linearly over this time (0 = at once).")
          .def("0 s").non_negative(),
      quantity("drum.gap", D::length, "Development gap: sleeve surface to drum surface along the line of centres.")
          .required().affects(A::electric),
      quantity("drum.angle", D::angle, "Direction of the drum centre seen from the roller centre.")
          .def("0 deg").min(0.0).max(2.0 * pi, false).affects(A::electric),
      quantity("drum.pc_thickness", D::length, "Photoconductor layer thickness (0 = bare conductor).")
          .def("0 um").non_negative().affects(A::electric),
      number("drum.pc_eps_r", "Photoconductor relative permittivity.").def("3").min(1.0).affects(A::electric),

      list("blades", "Doctor blade and guide walls: either a profile polygon, or angle + gap + thickness + length "
                     "(a radial plate whose tip is `gap` from the sleeve)."),
      text("blades[].name", "Wall name.").required(),
      choice("blades[].kind", {"doctor_blade", "guide"}, "A doctor blade meters the developer; a guide only walls it.")
          .def("guide"),
      Key("blades[].profile", KeyType::polygon, "Counter-clockwise polygon [[x, y], ...] in the roller frame.")
          .dim(D::length).affects(A::magnetic),
      quantity("blades[].angle", D::angle, "Generated blade: direction of its centre line from the roller centre.")
          .min(0.0).max(2.0 * pi, false).affects(A::magnetic),
      quantity("blades[].gap", D::length,
               "Nearest distance to the sleeve surface (required for generated blades; checked against a profile).")
          .affects(A::magnetic),
      quantity("blades[].thickness", D::length, "Generated blade: thickness across the centre line.")
          .positive().affects(A::magnetic),
      quantity("blades[].length", D::length, "Generated blade: radial length from the tip outward.")
          .positive().affects(A::magnetic),
      number("blades[].mu_r", "Relative permeability; > 1 makes a magnetic blade (enters the magnetostatic problem).")
          .def("1").min(1.0).affects(A::magnetic),
      text("blades[].material", "Contact material (key in materials).").def("wall"),

      list("planes", "Explicit plane walls (box scenes): point, normal into the particle side, optional path."),
      text("planes[].name", "Wall name.").required(),
      vector3("planes[].point", D::length, "A point on the plane at t = 0.").def("[0, 0, 0]"),
      vector3("planes[].normal", D::dimensionless, "Normal pointing into the particle side (normalised).")
          .def("[0, 0, 1]"),
      text("planes[].material", "Contact material (key in materials).").def("wall"),
      list("planes[].path", "Prescribed motion: piecewise-linear (time, displacement) samples, times increasing."),
      quantity("planes[].path[].time", D::time, "Sample time.").required().non_negative(),
      vector3("planes[].path[].displacement", D::length, "Displacement of the plane point at that time.")
          .required(),

      map("materials", "Contact and bulk properties by name (carrier, toner, sleeve, drum, wall, ...)."),
      quantity("materials.*.youngs_modulus", D::pressure, "Young's modulus E.").required().positive(),
      number("materials.*.poisson_ratio", "Poisson's ratio.").def("0.3").min(-1.0, false).max(0.5, false),
      quantity("materials.*.density", D::density, "Density (particles; unused for walls).")
          .def("0 kg/m^3").non_negative(),
      number("materials.*.mu_r", "Relative permeability (carrier beads).").def("1").min(1.0),
      quantity("materials.*.saturation_magnetisation", D::magnetisation, "Saturation magnetisation (0 = linear).")
          .def("0 kA/m").non_negative(),
      number("materials.*.friction", "Sliding friction coefficient.").def("0").non_negative(),
      number("materials.*.rolling_friction", "Rolling friction coefficient (0 = from polygon_angles).")
          .def("0").non_negative(),
      integer("materials.*.polygon_angles", "Kawamoto's polygon rule for rolling resistance (0 = off, else >= 3).")
          .def("0").non_negative(),
      number("materials.*.damping", "Kawamoto's Voigt damping constant alpha.").def("0").non_negative(),
      number("materials.*.restitution", "Coefficient of restitution (LIGGGHTS form); -1 = unused.")
          .def("-1").min(-1.0).max(1.0),
      quantity("materials.*.hamaker", D::energy, "Hamaker constant for van der Waals adhesion.")
          .def("0 J").non_negative(),

      list("populations", "Particle populations (carrier, toner)."),
      text("populations[].name", "Population name.").required(),
      choice("populations[].kind", {"carrier", "toner"}, "Particle kind.").def("carrier"),
      text("populations[].material", "Material (key in materials).").def("<kind>"),
      quantity("populations[].diameter", D::length, "Mean diameter.").required().positive(),
      quantity("populations[].diameter_std", D::length, "Standard deviation of the diameter (normal, truncated).")
          .def("0 um").non_negative(),
      integer("populations[].count", "Number of particles (give exactly one of count, mass, concentration).")
          .def("0").non_negative(),
      quantity("populations[].mass", D::mass, "Total mass of the population.").def("0 kg").non_negative(),
      number("populations[].concentration", "Toner only: toner mass / carrier mass (e.g. 7 %).")
          .def("0").non_negative().max(1.0, false),
      quantity("populations[].charge_to_mass", D::charge_to_mass, "Charge-to-mass ratio q/m (toner: required).")
          .def("0 uC/g"),
      Key("populations[].insert_box", KeyType::box, "Insertion box [[xmin, ymin, zmin], [xmax, ymax, zmax]].")
          .dim(D::length),
      quantity("populations[].layer_thickness", D::length, "Insert as a layer of this thickness on the sleeve.")
          .def("0 mm").non_negative(),

      section("electric", "Nip electrostatics: sleeve bias against the grounded drum substrate, latent image."),
      boolean("electric.enabled", "Solve the nip field (default: true when this section is present).")
          .def("true").affects(A::electric),
      quantity("electric.bias", D::voltage, "Sleeve potential against the drum substrate (DC).")
          .def("0 V").affects(A::electric),
      section("electric.image", "Latent image strips: give dark/light potentials OR dark/light charges."),
      quantity("electric.image.dark_potential", D::voltage, "Surface potential of the unexposed areas.")
          .affects(A::electric),
      quantity("electric.image.light_potential", D::voltage, "Surface potential of the exposed (image) areas.")
          .affects(A::electric),
      quantity("electric.image.dark_charge", D::surface_charge, "Surface charge of the unexposed areas.")
          .affects(A::electric),
      quantity("electric.image.light_charge", D::surface_charge, "Surface charge of the exposed (image) areas.")
          .affects(A::electric),
      quantity("electric.image.period", D::length, "Strip period along the drum surface (0 = uniform dark).")
          .def("0 mm").non_negative().affects(A::electric),
      number("electric.image.duty", "Exposed fraction of one period.").def("0.5").min(0.0).max(1.0).affects(A::electric),

      section("applied_field", "Where the magnetic field comes from: the roller (field solver grid) or uniform."),
      choice("applied_field.kind", {"auto", "none", "roller", "uniform"}, "auto: roller if a roller is given, else none.")
          .def("auto"),
      vector3("applied_field.direction", D::dimensionless, "Uniform field direction (normalised).").def("[0, 0, 1]"),
      quantity("applied_field.magnitude", D::magnetic_flux_density, "Uniform |B| at the end of the ramp.")
          .def("0 mT").non_negative(),
      quantity("applied_field.ramp_time", D::time, "Linear ramp 0 -> |B| over this time (0 = on at once).")
          .def("0 s").non_negative(),
      list("applied_field.schedule",
           "Uniform field only: piecewise-linear |B|(t) as (time, magnitude) samples, times increasing, held "
           "before the first and after the last (replaces magnitude and ramp_time; e.g. a field sweep at a held plate)."),
      quantity("applied_field.schedule[].time", D::time, "Sample time.").required().non_negative(),
      quantity("applied_field.schedule[].magnitude", D::magnetic_flux_density, "|B| at that time.")
          .required().non_negative(),

      section("field", "Field solver: meshes, element degree, exported grids."),
      quantity("field.mesh_size_far", D::length, "Element size away from the sleeve.").def("2 mm").positive().affects(A::both),
      quantity("field.mesh_size_sleeve", D::length, "Element size at the sleeve surface (with degree 3: 3e-4 max B error on the sleeve, measured).").def("0.25 mm").positive().affects(A::both),
      quantity("field.mesh_size_gap", D::length, "Element size in the development gap.").def("20 um").positive().affects(A::both),
      integer("field.element_degree", "Finite-element degree (3: the cheapest for 1e-3 in B, tests/field_solver bench).").def("3").min(1).max(4).affects(A::both),
      number("field.outer_radius_factor", "Open-boundary shell starts at this x sleeve radius.")
          .def("2").min(1.0, false).affects(A::both),
      quantity("field.grid_radial_spacing", D::length, "Polar magnetic grid radial spacing.").def("50 um").positive().affects(A::magnetic),
      quantity("field.grid_angular_spacing", D::angle, "Polar magnetic grid angular spacing.").def("0.25 deg").positive().affects(A::magnetic),
      quantity("field.grid_outer_radius", D::length, "Polar grid outer radius (0 = sleeve + 3 mm).").def("0 mm").non_negative().affects(A::magnetic),
      quantity("field.grid_electric_spacing", D::length, "Cartesian nip grid spacing.").def("10 um").positive().affects(A::electric),
      quantity("field.probe_radius", D::length, "Radius of the exported sleeve flux profile (0 = sleeve radius).")
          .def("0 mm").non_negative().affects(A::magnetic),
      text("field.output_dir", "Directory of the stored field files.").def("fields"),

      section("dem", "Discrete-element run control."),
      quantity("dem.time_step", D::time, "Time step (0 = automatic from the Rayleigh/Hertz criterion).").def("0 s").non_negative(),
      number("dem.time_step_safety", "Automatic step = this x Rayleigh time.").def("0.2").positive().max(1.0),
      quantity("dem.duration", D::time, "Simulated time.").def("0 s").non_negative(),
      quantity("dem.output_interval", D::time, "Snapshot interval (0 = only at the end).").def("0 s").non_negative(),
      quantity("dem.checkpoint_interval", D::time, "Checkpoint interval (0 = only at the end).").def("0 s").non_negative(),
      quantity("dem.periodic_length", D::length, "Periodic slab length along the roller axis z (0 = none).").def("0 mm").non_negative(),
      quantity("dem.periodic_length_x", D::length, "Periodic length along x (0 = none).").def("0 mm").non_negative(),
      quantity("dem.periodic_length_y", D::length, "Periodic length along y (0 = none).").def("0 mm").non_negative(),
      choice("dem.magnetic_model", {"point_dipole", "mutual_dipole", "corrected"},
             "Carrier magnetics: fixed point dipoles, mutual induction, or mutual + exact two-sphere correction.")
          .def("corrected"),
      number("dem.magnetic_cutoff", "Hard cutoff radius in mean carrier diameters, used only with magnetic_far_field: none (12: ~1 % force error in a brush with the slab tail, 5 % in the nip slab, docs/magnetics.md; the papers used 4).").def("12").positive(),
      quantity("dem.magnetic_refresh", D::time, "Magnetic force refresh interval (0 = every step).").def("0 s").non_negative(),
      number("dem.magnetic_tolerance", "Mutual-induction relative tolerance (1e-4: force error ~1e-5, docs/magnetics.md).").def("1e-4").positive(),
      number("dem.verlet_skin", "Neighbour-list skin as a fraction of the mean diameter.").def("0.3").positive(),
      choice("dem.magnetic_far_field", {"none", "cell_multipole"},
             "Magnetic far field: cell_multipole (no cutoff: exact pairs within 2 fine cells, the whole rest of the domain and every periodic image by cell multipoles, docs/magnetics.md) or none (hard cutoff at magnetic_cutoff).")
          .def("cell_multipole"),
      integer("dem.magnetic_far_order", "Taylor order of the cell multipoles (error vs cost in docs/magnetics.md).").def("2").non_negative().max(6),
      number("dem.magnetic_staleness", "Refresh the magnetic forces early when some carrier moved more than this fraction of its radius since the last refresh (held-force error ~0.37 x this, RMS, at the refresh; half of it on average, docs/magnetics.md).").def("0.05").positive(),
      choice("dem.magnetic_staleness_mode", {"relative", "local", "absolute"},
             "What makes held magnetic forces stale before magnetic_refresh elapses, and what it triggers: relative (a pair closer than 4 radii whose vector changed by magnetic_staleness x its mean radius, or a carrier that moved 5 x magnetic_staleness x its radius in the applied field: a local refresh around them; a rigidly carried brush triggers nothing), local (a carrier that moved magnetic_staleness x its radius: a local refresh around it) or absolute (the same trigger, a full refresh: the behaviour before; docs/magnetics.md).")
          .def("relative"),
      number("dem.magnetic_far_cell", "Fine cell size of the magnetic far field in mean carrier diameters (1.5 with order 2: <= 0.7 % RMS force error in brushes, docs/magnetics.md).").def("1.5").positive().max(10.0),
      quantity("dem.air_viscosity", D::viscosity, "Air viscosity for Stokes drag (0 = no drag).").def("1.81e-5 Pa*s").non_negative(),
      vector3("dem.gravity", D::acceleration, "Gravitational acceleration.").def("[0, -9.81 m/s^2, 0]"),
      integer("dem.seed", "Random seed (insertion, size distribution).").def("1").non_negative(),
      integer("dem.threads", "OpenMP threads (0 = default).").def("0").non_negative(),
      number("dem.max_overlap_fraction", "Stop when an overlap exceeds this fraction of a radius.").def("0.1").positive().max(1.0),
      choice("dem.restitution_model", {"ln_e", "hertz_exact"},
             "Materials with restitution: ln_e (LIGGGHTS/LAMMPS form) or hertz_exact (damping fitted to give e exactly).")
          .def("ln_e"),
      quantity("dem.settle_time", D::time, "After insertion, settle this long with the walls at rest.").def("0 s").non_negative(),
      number("dem.max_kinetic_energy_growth", "Stability guard: kinetic energy may not grow by more than this factor between checks.")
          .def("1000").min(1.0, false),

      section("nip", "Development-nip measurements (a scene with sleeve and drum): profiles along the gap of the beads "
                     "touching the drum, chain inclination, bead counts (docs/nip.md)."),
      quantity("nip.average_from", D::time, "Time-average the nip profiles over the samples at t >= this (the steady state).")
          .def("0 s").non_negative(),
      quantity("nip.sample_interval", D::time, "Time between samples of the nip measurements.").def("2 us").positive(),
      quantity("nip.bin_width", D::length, "Bin width along the nip (x: distance from the gap centre along the common tangent).")
          .def("0.25 mm").positive(),
      quantity("nip.half_width", D::length, "The drum profiles cover -half_width <= x <= half_width.").def("4 mm").positive(),
      quantity("nip.chain_bin_angle", D::angle, "Bin width of the chain-inclination profile in sleeve angle.")
          .def("2 deg").positive(),
      quantity("nip.chain_half_angle", D::angle, "The chain-inclination profile covers sleeve angles within this of the gap centre.")
          .def("30 deg").positive().max(180.0 * pi / 180.0),

      section("compression", "Kawamoto's compression test: the plate measurement of a box scene with a moving "
                             "plate and a stage (forces, touching beads, chain spacing, contact maps; docs/compression_study.md)."),
      text("compression.plate", "Name of the moving plane wall (the pseudo-photoreceptor plate).").def("plate"),
      text("compression.stage", "Name of the plane wall the brush stands on.").def("stage"),
      quantity("compression.sample_interval", D::time, "Time between samples of the beads touching the plate.")
          .def("1 us").positive(),
      quantity("compression.average_window", D::time, "One output row is the mean of the samples in this window.")
          .def("20 us").positive(),
      quantity("compression.map_interval", D::time, "Time between per-bead contact maps (0 = one map at the end).")
          .def("0 s").non_negative(),

      section("output", "Results."),
      text("output.directory", "Results directory.").def("results"),
      boolean("output.vtu", "Write VTU particle snapshots.").def("true"),
      boolean("output.xdmf", "Write HDF5/XDMF particle snapshots.").def("true"),
  };
}

std::string lower(std::string s)
{
  for (auto &c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Optimal string alignment distance (Damerau–Levenshtein with adjacent transpositions).
size_t edit_distance(const std::string &a, const std::string &b)
{
  const size_t n = a.size(), m = b.size();
  std::vector<std::vector<size_t>> d(n + 1, std::vector<size_t>(m + 1));
  for (size_t i = 0; i <= n; ++i)
    d[i][0] = i;
  for (size_t j = 0; j <= m; ++j)
    d[0][j] = j;
  for (size_t i = 1; i <= n; ++i)
    for (size_t j = 1; j <= m; ++j)
    {
      const size_t cost = (a[i - 1] == b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

std::string format_bound(double v, Dimension d) { return format_quantity(v, d); }

// "a length" -> "length"
std::string without_article(const std::string &s)
{
  if (s.rfind("a ", 0) == 0)
    return s.substr(2);
  if (s.rfind("an ", 0) == 0)
    return s.substr(3);
  return s;
}

} // namespace

const std::vector<KeySpec> &case_schema()
{
  static const std::vector<KeySpec> schema = build_schema();
  return schema;
}

const KeySpec *find_key_spec(const std::string &pattern)
{
  for (const auto &k : case_schema())
    if (k.path == pattern)
      return &k;
  return nullptr;
}

std::string parent_pattern(const std::string &pattern)
{
  const auto dot = pattern.find_last_of('.');
  if (dot == std::string::npos)
    return "";
  std::string parent = pattern.substr(0, dot);
  // "a.b[]" is the element of list "a.b"; "materials.*" is the entry of map "materials":
  // both are the section whose keys we list.
  return parent;
}

std::string last_component(const std::string &pattern)
{
  const auto dot = pattern.find_last_of('.');
  return dot == std::string::npos ? pattern : pattern.substr(dot + 1);
}

std::vector<const KeySpec *> child_key_specs(const std::string &section_pattern)
{
  std::vector<const KeySpec *> children;
  for (const auto &k : case_schema())
    if (parent_pattern(k.path) == section_pattern)
      children.push_back(&k);
  return children;
}

std::string did_you_mean(const std::string &word, const std::vector<std::string> &candidates)
{
  std::string best;
  size_t best_distance = std::string::npos;
  for (const auto &c : candidates)
  {
    const size_t d = edit_distance(lower(word), lower(c));
    if (d < best_distance)
    {
      best_distance = d;
      best = c;
    }
  }
  // Plausible typo: at most a third of the word wrong (at least 1, at most 3 edits), or the
  // word is a prefix/extension of the key ("diam" for "diameter").
  const size_t allowed = std::min<size_t>(3, std::max<size_t>(1, word.size() / 3));
  if (best_distance <= allowed)
    return best;
  for (const auto &c : candidates)
    if (word.size() >= 3 && (lower(c).rfind(lower(word), 0) == 0 || lower(word).rfind(lower(c), 0) == 0))
      return c;
  return "";
}

std::string KeySpec::type_description() const
{
  switch (type)
  {
  case KeyType::section: return "section";
  case KeyType::list: return "list";
  case KeyType::map: return "map of name -> section";
  case KeyType::quantity:
    return dimension == Dimension::dimensionless ? "number"
                                                 : without_article(dimension_description(dimension)) + " [" + si_unit(dimension) + "]";
  case KeyType::integer: return "integer";
  case KeyType::boolean: return "true/false";
  case KeyType::string: return "text";
  case KeyType::choice:
  {
    std::string s = "one of:";
    for (size_t i = 0; i < choices.size(); ++i)
      s += (i ? ", " : " ") + choices[i];
    return s;
  }
  case KeyType::vector3:
    return "[x, y, z]" + (dimension == Dimension::dimensionless ? std::string() : " of " + without_article(dimension_description(dimension)) + "s");
  case KeyType::polygon: return "polygon [[x, y], ...] of lengths";
  case KeyType::box: return "box [[x, y, z], [x, y, z]] of lengths";
  }
  return "";
}

std::string KeySpec::range_description() const
{
  auto bound = [&](double v) {
    return type == KeyType::integer ? std::to_string(static_cast<long long>(std::llround(v)))
                                    : format_bound(v, dimension);
  };
  if (min && max)
    return std::string("in ") + (min_inclusive ? "[" : "(") + bound(*min) + ", " + bound(*max) +
           (max_inclusive ? "]" : ")");
  if (min)
    return (min_inclusive ? ">= " : "> ") + bound(*min);
  if (max)
    return (max_inclusive ? "<= " : "< ") + bound(*max);
  return "";
}

} // namespace magbrush
