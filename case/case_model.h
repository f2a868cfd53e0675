// The resolved case: what one YAML case file describes, after parsing, unit conversion
// and validation. Every stage (geometry, field solver, DEM, tools) reads this struct and
// never the YAML itself, so there is one meaning for every key.
//
// Conventions (the same everywhere in magbrush):
//  * SI units throughout: m, s, T, A/m, V, Pa, kg, C. Angles in radians.
//  * The roller axis is z. The cross-section is the x-y plane with the roller centre at the
//    origin. Angles are measured counter-clockwise from +x (the sleeve-scan convention).
//  * A positive rpm turns counter-clockwise seen from +z.
//
// The parser (case_parser.h) fills this struct; the schema (case_schema.h, the keys each module
// declares in case_keys_<module>.cpp) is the single place where each key's type, dimension,
// default, range and documentation live. The member initialisers below repeat the schema's
// defaults, so that a struct built in code is what a default case gives;
// tests/case/test_module_defaults.cpp fails when they disagree.
// Fields are only ever added to this header, never renamed, so that all stages stay in step.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace magbrush {

using Vec2 = std::array<double, 2>;
using Vec3 = std::array<double, 3>;

// ---------------------------------------------------------------------------------------
// Magnet roller (Kweon eq. 9–10): radial magnetisation in R_shaft < r < R_magnet,
//   M_r(θ) = Σ_i M_i exp(−α_i wrap(θ − φ_i)²)
// with the pole's sign carried by M_i (north pole: M_i > 0, pointing outward).
struct Pole
{
  std::string name;        // e.g. "N1" (development pole), "S1", ...
  double angle = 0.0;      // φ_i [rad], in [0, 2π)
  double strength = 0.0;   // M_i [A/m], signed: > 0 north (outward), < 0 south
  double shape_factor = 10.0; // α_i [1/rad²]
};

struct Roller
{
  double shaft_radius = 0.0;   // R_shaft [m]; 0 = no shaft
  double shaft_mu_r = 1000.0;  // iron shaft relative permeability (large = ideal iron)
  double magnet_radius = 0.0;  // R_magnet [m], outer radius of the magnet annulus
  double magnet_mu_r = 1.0;    // recoil permeability of the magnet material
  std::vector<Pole> poles;
};

struct Sleeve
{
  double radius = 0.0;     // outer radius [m]
  double thickness = 0.0;  // wall thickness [m] (non-magnetic, e.g. aluminium)
  double rpm = 0.0;        // signed rotation speed [rev/min]; > 0 counter-clockwise
  double spin_up_time = 0.0; // linear ramp of the speed from rest from t = 0 [s] (0 = at once)
  double omega() const;    // angular velocity [rad/s]
  double surface_speed() const; // |ω| R [m/s]
  double turned(double t) const; // the angle turned by time t, the ramp included (0 for t <= 0) [rad]
};

struct Drum
{
  bool present = false;
  double radius = 0.0;             // outer radius of the photoconductor surface [m]
  double rpm = 0.0;                // signed [rev/min]
  double spin_up_time = 0.0;       // linear ramp of the speed from rest from t = 0 [s] (0 = at once)
  double gap = 0.0;                // development gap: sleeve surface to drum surface [m]
  double angle = 0.0;              // direction of the drum centre seen from the roller centre [rad]
  double pc_thickness = 0.0;       // photoconductor layer thickness [m]
  double pc_eps_r = 3.0;           // photoconductor relative permittivity
  Vec2 center(double sleeve_radius) const; // drum centre [m]
  double omega() const;
  double turned(double t) const; // the angle turned by time t, the ramp included (0 for t <= 0) [rad]
};

// A doctor blade or a guide wall: a polygon in the x-y plane extruded along the roller axis.
struct BladeOrGuide
{
  std::string name;
  std::vector<Vec2> polygon;   // closed polygon (counter-clockwise), in the roller frame [m]
  double mu_r = 1.0;           // > 1: soft-magnetic blade (enters the magnetostatic problem)
  std::string material = "wall"; // contact material name (key in Case::materials)
  bool is_doctor_blade = false;
  double gap = 0.0;            // doctor blades: nearest distance to the sleeve surface [m]
};

// Contact and bulk properties of one material (Kawamoto A2–A7).
struct Material
{
  std::string name;
  double youngs_modulus = 0.0;  // E [Pa]
  double poisson_ratio = 0.3;   // ν
  double density = 0.0;         // ρ [kg/m³] (walls: unused)
  double mu_r = 1.0;            // relative permeability (carrier beads)
  double saturation_magnetisation = 0.0; // M_s [A/m]; 0 = linear (no saturation)
  double friction = 0.0;        // sliding friction coefficient μ
  double rolling_friction = 0.0;// rolling friction coefficient μ_r (0 = derive from polygon_angles)
  int polygon_angles = 0;       // Kawamoto's polygon rule (0 = use rolling_friction as given)
  double damping = 0.0;         // Kawamoto's Voigt damping constant α (c_n = α √(m* k_n) δ^¼)
  double restitution = -1.0;    // coefficient of restitution e (LIGGGHTS ln e form); < 0 = unused
  double hamaker = 0.0;         // Hamaker constant A [J] for van der Waals adhesion
  bool hamaker_given = false;   // `hamaker` was written (an explicit 0 J means: no adhesion)
  double adhesion_radius = 0.0; // asperity radius where it touches [m]; 0 = the particle radius
                                // (walls: 0 = flat)
};

// A Hamaker constant for one pair of materials, overriding the combining rule √(A₁ A₂).
struct AdhesionPair
{
  std::string material_a, material_b;
  double hamaker = 0.0;         // A₁₂ [J]
};

enum class ParticleKind { carrier, toner };

// One particle population. Diameters follow a normal distribution truncated to positive
// values. Exactly one of count / mass / concentration fixes how many are made.
struct Population
{
  std::string name;
  ParticleKind kind = ParticleKind::carrier;
  std::string material;          // key in Case::materials
  double diameter_mean = 0.0;    // [m]
  double diameter_std = 0.0;     // [m]
  long count = 0;                // number of particles (0 = derive from mass or concentration)
  double mass = 0.0;             // total mass [kg] (0 = unused)
  double concentration = 0.0;    // toner only: toner mass / carrier mass (0 = unused)
  double charge_to_mass = 0.0;   // mean q/m [C/kg]
  double charge_to_mass_std = 0.0; // spread of q/m between particles [C/kg]
  double wrong_sign_fraction = 0.0; // share of particles charged against the sign of q/m
  bool counter_charge = false;   // carrier: carries minus the charge of all other particles
  bool attached = false;         // toner with a concentration: placed touching the carriers
  // Toner on carriers (attached or fed by the inflow) rides them as mass and charge until the
  // carrier's surface is this close to the drum, then becomes particles (0 = always
  // particles; dem/carried_toner.h) [m].
  double carried_until_gap = 0.0;
  // Where they are inserted: a box (min, max corners) in the scene frame, or, when
  // layer_thickness > 0, a layer of this thickness on the sleeve surface.
  std::optional<std::array<Vec3, 2>> insert_box;
  double layer_thickness = 0.0;  // [m]
};

// Latent image on the photoconductor: strips along the drum surface.
struct LatentImage
{
  enum class Kind { none, surface_charge, surface_potential } kind = Kind::none;
  double dark_value = 0.0;       // C/m² or V, in the unexposed (dark) areas
  double light_value = 0.0;      // C/m² or V, in the exposed (image) areas
  double period = 0.0;           // strip period along the drum surface [m] (0 = uniform)
  double duty = 0.5;             // exposed fraction of one period (1: a solid area, whatever the period)
  double edge_width = 0.0;       // width of the raised-cosine transition at each strip edge [m] (0 = sharp)

  // A printer's TMA patch is a solid exposed area; a uniform image is the same everywhere on
  // the drum, so its field does not move with the drum. Exposed everywhere at duty 1, dark
  // everywhere at duty 0 or without a period; strips otherwise.
  bool solid() const { return duty >= 1.0; }
  bool striped() const { return period > 0.0 && duty > 0.0 && duty < 1.0; }
};

struct Electric
{
  bool enabled = false;
  double bias = 0.0;             // sleeve potential against the grounded drum substrate [V]
  LatentImage image;
  // Coulomb between the particles' charges and their images in the drum and the sleeve
  // (docs/electrostatics.md, "Coulomb and the conductors' images"; DEM only).
  bool coulomb = true;           // on when some population is charged
  int coulomb_order = 4;         // Taylor order of the Coulomb far field
  double coulomb_cell = 25e-6;   // fine cell size of the far field [m] (near pairs: ±2 cells)
  double coulomb_refresh = 2e-6; // far-field refresh interval [s] (0 = every step)
  bool conductor_images = true;  // false: Kweon's assumption, Φ unchanged by the toner
  int pair_image_terms = 2;      // explicit drum images per charge acting on the others (0 = none)
  // The electric forces are evaluated again when a particle or the latent image has moved
  // this far since the last evaluation, held in between (0 = every step; dem/force_terms/held_forces.h).
  double hold_distance = 20e-9;  // [m]
  // The frame Coulomb's moves are measured in: the lab's, or the one turning with the sleeve
  // (the developer riding the sleeve then changes no pair and renews nothing).
  enum class HoldFrame { lab, sleeve } coulomb_hold_frame = HoldFrame::lab;
};

// Applied magnetic field: from the roller (field solver grid) or uniform (the compression test).
struct AppliedField
{
  enum class Kind { none, roller, uniform } kind = Kind::none;
  Vec3 uniform_direction{{0.0, 0.0, 1.0}};
  double uniform_magnitude = 0.0; // |B| [T] at the end of the ramp
  double ramp_time = 0.0;         // linear ramp 0 → |B| over this time [s] (0 = on at once)
  // Added for Kawamoto's compression study (field sweep at a held plate): an optional
  // piecewise-linear schedule of the uniform field's magnitude, (t [s], |B| [T]) samples with
  // increasing times, held at the first value before it and at the last after it. When given
  // it replaces magnitude + ramp_time, and uniform_magnitude is the schedule's peak |B|.
  std::vector<std::pair<double, double>> schedule;
};

// Explicit walls for scenes without a roller (Kawamoto's compression test: stage and plate).
struct PlaneWall
{
  std::string name;
  Vec3 point{{0, 0, 0}};
  Vec3 normal{{0, 0, 1}};        // particles live on the side the normal points to
  std::string material = "wall";
  // Prescribed motion: piecewise-linear path of the point, (t, displacement) samples.
  std::vector<std::pair<double, Vec3>> path;
};

struct FieldSettings
{
  double mesh_size_far = 2.0e-3;     // element size away from the sleeve [m]
  double mesh_size_sleeve = 0.25e-3; // element size at the sleeve surface [m]
  double mesh_size_gap = 20e-6;      // element size in the development gap [m]
  int element_degree = 3;
  double outer_radius_factor = 2.0;  // open-boundary shell starts at this × sleeve radius
  double grid_radial_spacing = 50e-6;   // polar magnetic grid Δr [m]
  double grid_angular_spacing = 0.25 * 3.14159265358979323846 / 180.0; // Δθ [rad]
  double grid_outer_radius = 0.0;       // polar grid outer radius [m] (0 = sleeve + 3 mm)
  double grid_electric_spacing = 10e-6; // Cartesian nip grid spacing [m]
  int electric_phase_samples = 16;      // latent-image phases stored per image period
  double probe_radius = 0.0;            // sleeve-profile probe radius [m] (0 = sleeve radius)
  std::string output_dir = "results/fields"; // <output.directory>/fields: the parser makes an empty key so
};

struct DemSettings
{
  double time_step = 0.0;            // [s]; 0 = automatic (Rayleigh/Hertz criterion)
  double time_step_safety = 0.2;     // auto step = safety × Rayleigh time
  double duration = 0.0;             // simulated time [s]
  double output_interval = 0.0;      // snapshot interval [s]
  double checkpoint_interval = 250e-6; // simulated time between checkpoints [s] (0 = only at the end)
  double checkpoint_wall_interval = 600.0; // wall-clock time between checkpoints [s] (0 = none)
  double periodic_length = 0.0;      // slab length along the roller axis z [m] (0 = none)
  double periodic_length_x = 0.0;    // optional periodic length along x [m]
  double periodic_length_y = 0.0;    // optional periodic length along y [m]
  std::string magnetic_model = "corrected"; // "point_dipole" | "mutual_dipole" | "corrected"
  double magnetic_cutoff = 12.0;     // cutoff radius in mean carrier diameters (docs/magnetics.md)
  double magnetic_refresh = 0.0;     // refresh interval [s] (0 = every step)
  double magnetic_tolerance = 1e-4;  // mutual-induction relative tolerance (force error ~1e-5)
  double verlet_skin = 0.3;          // skin as a fraction of the mean diameter
  // Magnetic far field (docs/magnetics.md): "cell_multipole" (no cutoff: exact pairs in
  // neighbouring cells, the rest of the domain and all periodic images by cell multipoles)
  // or "none" (hard cutoff at magnetic_cutoff).
  std::string magnetic_far_field = "cell_multipole";
  int magnetic_far_order = 2;        // Taylor order of the cell multipoles
  double magnetic_far_cell = 1.5;    // fine cell size in mean carrier diameters
  double magnetic_staleness = 0.05;  // refresh early when a bead moved this × its radius
  // What makes held magnetic forces stale early, and what it triggers (docs/magnetics.md):
  // "relative" (close pairs whose vector changed by magnetic_staleness × the mean radius, or
  // beads that moved 5× that in the applied field: a local refresh around them), "local"
  // (beads that moved magnetic_staleness × their radius: a local refresh) or "absolute"
  // (the same trigger, a full refresh: the papers' behaviour).
  std::string magnetic_staleness_mode = "relative";
  // What the magnetics hold between evaluations: "forces", or "dipoles" (the close pairs'
  // forces follow the beads; docs/magnetics.md "Holding the dipoles instead of the forces").
  std::string magnetic_hold = "forces";
  double magnetic_skin = 0.0;        // magnetic lists' skin in mean diameters (0 = verlet_skin)
  int magnetic_live_steps = 20;      // hold dipoles: the close pairs' forces every this many steps
  double air_viscosity = 1.81e-5;    // η [Pa s] for Stokes drag (0 = no drag)
  Vec3 gravity{{0.0, -9.81, 0.0}};    // [m/s²]
  unsigned long seed = 1;
  int threads = 0;                   // 0 = OpenMP default
  double max_overlap_fraction = 0.1; // stability guard: overlap / radius
  // Added by the DEM engine:
  std::string restitution_model = "ln_e"; // materials with `restitution`: "ln_e" (LIGGGHTS/LAMMPS
                                          // form, inexact for Hertz) | "hertz_exact" (damping
                                          // fitted so that Hertz gives exactly e)
  bool leg = false;                  // a first leg: averaging windows may lie after dem.duration
  double settle_time = 0.0;          // after insertion, settle this long with walls at rest [s]
  double max_kinetic_energy_growth = 1e3; // stability guard: KE may not grow by more than this
                                          // factor between two guard checks (100 steps)
  // Van der Waals adhesion (dem/contact_law.h, HamakerAdhesion):
  double adhesion_cutoff = 0.4e-9;   // z0: the gap is floored here (contact distance) [m]
  double adhesion_range_fraction = 0.01; // the force is cut where it has fallen to this × F0
  double toner_stiffness_factor = 1.0;   // toner contacts use E × this (time step, dem/README.md)
  int toner_substeps = 1;                // toner in this many substeps of the step (0 = as many as the carriers allow)
};

// The development-nip measurements (dem/measurements/nip_profile.h, chain_inclination.h,
// nip_time_series.h): what they sample and how they bin. Taken when the scene has a sleeve and
// a drum. Positions along the nip are x, the distance from the gap centre along the common
// tangent of sleeve and drum (positive downstream, the way the sleeve surface moves).
struct NipSettings
{
  double average_from = 0.0;        // time-average the profiles over t >= this [s]
  double sample_interval = 2e-6;    // time between samples [s]
  double bin_width = 0.25e-3;       // bin width along the nip (x) [m]
  double half_width = 4e-3;         // profiles cover -half_width <= x <= half_width [m]
  double chain_bin_angle = 2.0 * 3.14159265358979323846 / 180.0;   // chain bins in sleeve angle [rad]
  double chain_half_angle = 30.0 * 3.14159265358979323846 / 180.0; // chain profile extent [rad]
};

// Kawamoto's compression test (dem/measurements/plate_compression.h): what the plate
// measurement samples. It is taken when a box scene has both named planes.
struct CompressionSettings
{
  std::string plate = "plate";      // name of the moving plane (the pseudo-photoreceptor)
  std::string stage = "stage";      // name of the plane the brush stands on
  double sample_interval = 1e-6;    // time between samples of the plate contacts [s]
  double average_window = 20e-6;    // one output row = the mean of the samples in this window [s]
  double map_interval = 0.0;        // time between per-bead contact maps [s] (0 = one at the end)
};

// Toner development onto the drum (dem/measurements/toner_development.h): the measuring window
// downstream of the nip, in nip coordinate x (see NipSettings).
struct DevelopmentSettings
{
  double measure_from = 1e-3;     // [m]
  double measure_to = 4e-3;       // [m]
  double sample_interval = 2e-6;  // [s]
  double average_from = 0.0;      // [s]
  // "samples": the means average the window's samples; "image_periods": over whole periods of
  // the latent image, each drum element counted once as it crosses measure_to
  // (dem/measurements/developed_line.h).
  std::string average_over = "samples";
  int phase_bins = 40; // bins of the developed profile per image period
  // The drum length of one block of the developed line on a uniform image (solid or dark),
  // which has no period to close its blocks [m]; 0: the image period.
  double block_length = 0.0;
};

// The developer on the sleeve after the doctor blade (dem/measurements/developer_mass_per_area.h):
// the developer mass per area (DMA) in a window downstream of the blade, the same from the
// flux through the window's centre line, the blade's load, the developer held in front of the
// blade and, when a release sector is given, the fraction of the developer that leaves the
// sleeve there. Angles are roller angles; offsets count in the direction the sleeve turns.
struct DmaSettings
{
  double after_blade = 10.0 * 3.14159265358979323846 / 180.0;  // window centre: this far past the blade tip [rad]
  double window = 10.0 * 3.14159265358979323846 / 180.0;       // angular width of the window [rad]
  double height = 2e-3;              // only particles within this of the sleeve surface count [m]
  double front_window = 20.0 * 3.14159265358979323846 / 180.0; // sector before the blade weighed [rad]
  double release_from = 0.0;         // release: flux line before the release [rad]
  double release_to = 0.0;           // and after it [rad] (equal: not measured)
  double sample_interval = 10e-6;    // [s]
  double average_from = 0.0;         // [s]
};

// How the measurements' summaries judge their means (dem/measurements/sample_series.h).
struct StatisticsSettings
{
  double steady_drift = 0.02; // steady: halves of the averaging window within this fraction
  int blocks = 10;            // blocks of the block-averaged standard error
};

// Particles entering and leaving a roller scene (dem/particle_source.h, dem/particle_sink.h):
// developer fed onto the sleeve just downstream of an entry angle at the developer mass per
// area `areal_mass` (DMA), carried in at the sleeve speed, so that the mass flux is
// DMA × v_sleeve × slab length; toner populations with a concentration come attached to the
// carriers in that proportion. Particles in the outflow sector (or beyond outer_radius) are
// removed. Angles are roller angles (counter-clockwise from +x); sectors extend from their
// angle in the direction the sleeve turns.
struct FlowSettings
{
  std::string inflow_population;     // the carrier population fed ("" = the first carrier)
  double inflow_areal_mass = 0.0;    // developer (carrier + toner) mass per sleeve area [kg/m²] (0 = no inflow)
  double inflow_angle = 0.0;         // entry angle [rad]
  double inflow_layer_height = 0.5e-3; // the new particles are placed within this of the sleeve surface [m]
  // "fixed": exactly areal_mass is fed (an error when it finds no room); "sump": areal_mass is
  // offered, and what finds no room in the entry arc stays in the sump (the pick-up is measured).
  std::string inflow_supply = "fixed";
  double inflow_prefill_arc = 0.0;   // the sleeve carries the layer over this arc downstream of the entry at the start [rad]
  // Where the prefilled layer finds no room (a drum nearer the sleeve than the layer): "refuse"
  // (an error naming the angle) or "thin" (what fits is placed, and the layer downstream keeps
  // only the fraction that passed the narrowest place, as a layer squeezed through a gap).
  std::string inflow_prefill_no_room = "refuse";
  // A finite sump (supply "sump" only): the developer in it per length along the roller axis
  // [kg/m] (0 = unlimited). The inflow draws on it, the outflow returns to it.
  double inflow_sump_mass = 0.0;
  double interval = 1e-6;            // time between exchanges [s]
  double outflow_angle = 0.0;        // start of the removal sector [rad]
  double outflow_width = 0.0;        // its angular extent [rad] (0 = no outflow sector)
  double outflow_radius = 0.0;       // remove particles farther than this from the roller axis [m] (0 = none)
  double sample_interval = 2e-6;     // flow report: time between samples [s]
  double flux_angle = 0.0;           // flow report: the radial line the flux is counted through [rad]
  double density_window = 10.0 * 3.14159265358979323846 / 180.0; // flow report: angular window of the areal mass [rad]
  double average_from = 0.0;         // flow report: its summary's means over t >= this [s]
  bool inflow() const { return inflow_areal_mass > 0.0; }
  bool outflow() const { return outflow_width > 0.0 || outflow_radius > 0.0; }
};

struct OutputSettings
{
  // The run's folder. The key empty (the default): results/<name>[-<digest of the overrides>],
  // automatic = true (case/run_folder.h).
  std::string directory = "results";
  bool automatic = false;
  std::vector<std::string> overrides; // the --set overrides, normalised (run_folder.h): variant.txt
  bool vtu = false;
  bool xdmf = true;
};

struct Case
{
  std::string name;             // scene name (defaults to the file stem)
  std::string source_file;      // path of the YAML file it came from
  std::string scene = "roller"; // "roller" (sleeve, optional drum/blade) | "box" (walls only)

  std::optional<Roller> roller;
  std::optional<Sleeve> sleeve;
  Drum drum;
  std::vector<BladeOrGuide> blades;   // doctor blade and guides
  std::vector<PlaneWall> planes;      // explicit plane walls (box scenes)
  std::vector<Material> materials;    // by name: "carrier", "toner", "wall", "drum", ...
  std::vector<Population> populations;
  std::vector<AdhesionPair> adhesion_pairs; // per-pair Hamaker constants (dem/contact_parameters)
  Electric electric;
  AppliedField applied_field;
  FieldSettings field;
  DemSettings dem;
  NipSettings nip;                    // added by the nip measurements
  CompressionSettings compression; // added by the compression study
  StatisticsSettings statistics;   // standard errors and the steady-state test of every summary
  DevelopmentSettings development; // the toner-development measurement
  DmaSettings dma;                    // the developer on the sleeve after the doctor blade
  FlowSettings flow;                  // particles entering and leaving (inflow, outflow, flow report)
  OutputSettings output;
  std::string measured_flux_file;     // optional gaussmeter scan to overlay in the report
  double measured_flux_angle_origin = 0.0; // [rad] roller angle = scan angle + this (the encoder offset)

  const Material &material(const std::string &name) const; // throws if absent
  // Some population is charged (a non-zero mean q/m): the electric force terms are needed.
  bool has_charged_population() const;
};

} // namespace magbrush
