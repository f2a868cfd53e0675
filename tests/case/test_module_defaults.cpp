// One parameter story: every module's keys are declared once (case/case_keys_<module>.cpp),
// the schema is the union of those declarations, and the settings a default case produces are
// the settings a module builds on its own.
//
// The defaults physically appear twice: in the key declarations (what a user's case file gets)
// and in the member initialisers of the settings structs (what a test or a bench gets when it
// builds the struct by hand). This test is what keeps them equal: it loads cases that give only
// the keys a valid case must give, and compares every field that has a case key with the
// default-constructed struct. A test that builds a struct therefore runs the physics of a
// user's default case unless it says otherwise.
#include "case/case_keys.h"
#include "case/case_model.h"
#include "case/case_parser.h"
#include "case/run_folder.h"
#include "case/case_schema.h"
#include "magnetics/magnetic_settings.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

using namespace magbrush;

namespace {

// A roller scene with only what a valid case must give: the magnet radius and poles, the sleeve
// and drum sizes and the gap, one generated guide blade, the Young's moduli, the carrier's
// density (a particle material needs one), and how many carriers go where.
const char *roller_case = R"(
roller:
  magnet_radius: 9 mm
  poles:
    - {name: N1, angle: 0 deg, strength: 150 kA/m}
    - {name: S1, angle: 180 deg, strength: -150 kA/m}
sleeve:
  radius: 10 mm
drum:
  radius: 15 mm
  gap: 0.4 mm
blades:
  - {name: guide, angle: 90 deg, gap: 1 mm, thickness: 1 mm, length: 5 mm}
materials:
  carrier: {youngs_modulus: 1 GPa, density: 4.8 g/cm^3}
  wall: {youngs_modulus: 50 GPa}
  sleeve: {youngs_modulus: 50 GPa}
  drum: {youngs_modulus: 50 GPa}
populations:
  - name: carrier
    diameter: 50 um
    count: 1000
    layer_thickness: 0.3 mm
)";

// A box scene (plane walls; the roller scene has none) with the same economy.
const char *box_case = R"(
scene: box
planes:
  - {name: stage}
materials:
  carrier: {youngs_modulus: 1 GPa, density: 4.8 g/cm^3}
  wall: {youngs_modulus: 50 GPa}
populations:
  - name: carrier
    diameter: 50 um
    count: 1000
    insert_box: [[0, 0, 0], [1 mm, 1 mm, 1 mm]]
)";

Case roller_defaults() { return parse_case_text(roller_case, "roller_defaults.yaml"); }
Case box_defaults() { return parse_case_text(box_case, "box_defaults.yaml"); }

// Defaults given with units ("0.25 deg", "2 us") are converted, so compare to a few ulp.
#define EXPECT_SAME(from_case, built, field) EXPECT_DOUBLE_EQ((from_case).field, (built).field) << #field
#define EXPECT_SAME_EXACT(from_case, built, field) EXPECT_EQ((from_case).field, (built).field) << #field

void expect_same_vec3(const Vec3 &from_case, const Vec3 &built, const char *what)
{
  for (int i = 0; i < 3; ++i)
    EXPECT_DOUBLE_EQ(from_case[i], built[i]) << what << "[" << i << "]";
}

} // namespace

// The schema is exactly the modules' declarations, in the order of key_declarations(): no
// module's keys are lost or reordered on the way, and every module declares something.
TEST(ModuleKeys, SchemaIsTheUnionOfTheModuleDeclarations)
{
  const auto &schema = case_schema();
  std::size_t next = 0;
  for (const auto &module : key_declarations())
  {
    const auto keys = module.declare();
    EXPECT_FALSE(keys.empty()) << module.module << " declares no keys";
    for (const auto &key : keys)
    {
      ASSERT_LT(next, schema.size()) << key.path << " (" << module.file << ") is not in the schema";
      EXPECT_EQ(schema[next].path, key.path) << "declared in " << module.file;
      EXPECT_EQ(schema[next].default_text, key.default_text) << key.path;
      ++next;
    }
  }
  EXPECT_EQ(next, schema.size()) << "the schema holds keys no module declares";

  std::set<std::string> modules;
  for (const auto &module : key_declarations())
    EXPECT_TRUE(modules.insert(module.module).second) << module.module << " listed twice";
}

// The magnetics: MagneticSettings{} is what a default case runs (cutoff, tolerance, far field,
// staleness mode, ...), so a test that builds the struct runs a user's physics.
TEST(ModuleDefaults, MagneticSettingsOfADefaultCaseAreTheStructDefaults)
{
  using namespace magnetics;
  const MagneticSettings from_case = MagneticSettings::from_case(roller_defaults().dem);
  const MagneticSettings built;
  EXPECT_EQ(to_string(from_case.model), to_string(built.model));
  EXPECT_SAME_EXACT(from_case, built, torque);
  EXPECT_SAME(from_case, built, cutoff_diameters);
  EXPECT_SAME(from_case, built, cutoff_length);
  EXPECT_SAME(from_case, built, skin_fraction);
  EXPECT_SAME(from_case, built, tolerance);
  EXPECT_SAME_EXACT(from_case, built, max_sweeps);
  EXPECT_SAME(from_case, built, refresh_interval);
  EXPECT_SAME(from_case, built, staleness_fraction);
  EXPECT_EQ(to_string(from_case.staleness_mode), to_string(built.staleness_mode));
  EXPECT_SAME(from_case, built, local_region_limit);
  EXPECT_SAME(from_case, built, local_region_radius);
  EXPECT_SAME(from_case, built, local_batch_fraction);
  EXPECT_SAME(from_case, built, local_dipole_change);
  EXPECT_SAME(from_case, built, relative_check_radius);
  EXPECT_SAME(from_case, built, absolute_factor);
  EXPECT_SAME(from_case, built, switch_begin);
  EXPECT_SAME(from_case, built, switch_end);
  EXPECT_SAME_EXACT(from_case, built, slab_tail_correction);
  EXPECT_EQ(to_string(from_case.far_field), to_string(built.far_field));
  EXPECT_SAME(from_case, built, far_cell_diameters);
  EXPECT_SAME_EXACT(from_case, built, far_order);
  EXPECT_SAME_EXACT(from_case, built, far_near_reach);
  EXPECT_SAME_EXACT(from_case, built, far_passes);
  EXPECT_SAME_EXACT(from_case, built, far_single_precision);
}

// The DEM engine's run control (and the dem.magnetic_* strings the magnetics parses).
TEST(ModuleDefaults, DemSettingsOfADefaultCaseAreTheStructDefaults)
{
  const DemSettings from_case = roller_defaults().dem;
  const DemSettings built;
  EXPECT_SAME(from_case, built, time_step);
  EXPECT_SAME(from_case, built, time_step_safety);
  EXPECT_SAME(from_case, built, duration);
  EXPECT_SAME(from_case, built, output_interval);
  EXPECT_SAME(from_case, built, checkpoint_interval);
  EXPECT_SAME(from_case, built, checkpoint_wall_interval);
  EXPECT_SAME(from_case, built, periodic_length);
  EXPECT_SAME(from_case, built, periodic_length_x);
  EXPECT_SAME(from_case, built, periodic_length_y);
  EXPECT_SAME_EXACT(from_case, built, magnetic_model);
  EXPECT_SAME(from_case, built, magnetic_cutoff);
  EXPECT_SAME(from_case, built, magnetic_refresh);
  EXPECT_SAME(from_case, built, magnetic_tolerance);
  EXPECT_SAME(from_case, built, verlet_skin);
  EXPECT_SAME_EXACT(from_case, built, magnetic_far_field);
  EXPECT_SAME_EXACT(from_case, built, magnetic_far_order);
  EXPECT_SAME(from_case, built, magnetic_far_cell);
  EXPECT_SAME(from_case, built, magnetic_staleness);
  EXPECT_SAME_EXACT(from_case, built, magnetic_staleness_mode);
  EXPECT_SAME_EXACT(from_case, built, magnetic_hold);
  EXPECT_SAME(from_case, built, magnetic_skin);
  EXPECT_SAME_EXACT(from_case, built, magnetic_live_steps);
  EXPECT_SAME(from_case, built, air_viscosity);
  expect_same_vec3(from_case.gravity, built.gravity, "gravity");
  EXPECT_SAME_EXACT(from_case, built, seed);
  EXPECT_SAME_EXACT(from_case, built, threads);
  EXPECT_SAME(from_case, built, max_overlap_fraction);
  EXPECT_SAME_EXACT(from_case, built, restitution_model);
  EXPECT_SAME(from_case, built, settle_time);
  EXPECT_SAME_EXACT(from_case, built, leg);
  EXPECT_SAME(from_case, built, max_kinetic_energy_growth);
  EXPECT_SAME(from_case, built, adhesion_cutoff);
  EXPECT_SAME(from_case, built, adhesion_range_fraction);
  EXPECT_SAME(from_case, built, toner_stiffness_factor);
}

// The field solver (field section) and the nip electrostatics (electric section).
TEST(ModuleDefaults, FieldSolverSettingsOfADefaultCaseAreTheStructDefaults)
{
  const Case c = roller_defaults();
  const FieldSettings built;
  EXPECT_SAME(c.field, built, mesh_size_far);
  EXPECT_SAME(c.field, built, mesh_size_sleeve);
  EXPECT_SAME(c.field, built, mesh_size_gap);
  EXPECT_SAME_EXACT(c.field, built, element_degree);
  EXPECT_SAME(c.field, built, outer_radius_factor);
  EXPECT_SAME(c.field, built, grid_radial_spacing);
  EXPECT_SAME(c.field, built, grid_angular_spacing);
  EXPECT_SAME(c.field, built, grid_outer_radius);
  EXPECT_SAME(c.field, built, grid_electric_spacing);
  EXPECT_SAME(c.field, built, probe_radius);
  // A case from a file stores its fields in its run folder, named after it
  // (case/run_folder.h); a Case built by hand in the struct's results/fields.
  EXPECT_EQ(c.field.output_dir, std::string(results_root_directory) + "/" + c.name + "/fields");
  EXPECT_EQ(built.output_dir, std::string(results_root_directory) + "/fields");

  // No electric section: the nip field is off, and the rest is the struct's.
  const Electric electric;
  EXPECT_SAME_EXACT(c.electric, electric, enabled);
  EXPECT_SAME(c.electric, electric, bias);
  EXPECT_SAME_EXACT(c.electric.image, electric.image, kind);
  EXPECT_SAME(c.electric.image, electric.image, dark_value);
  EXPECT_SAME(c.electric.image, electric.image, light_value);
  EXPECT_SAME(c.electric.image, electric.image, period);
  EXPECT_SAME(c.electric.image, electric.image, duty);
  EXPECT_SAME_EXACT(c.electric, electric, coulomb);
  EXPECT_SAME_EXACT(c.electric, electric, coulomb_order);
  EXPECT_SAME(c.electric, electric, coulomb_cell);
  EXPECT_SAME(c.electric, electric, coulomb_refresh);
  EXPECT_SAME_EXACT(c.electric, electric, conductor_images);
  EXPECT_SAME_EXACT(c.electric, electric, pair_image_terms);
  EXPECT_SAME(c.electric, electric, hold_distance);
}

// The geometry: roller, poles, sleeve, drum, blades, plane walls.
TEST(ModuleDefaults, GeometryOfADefaultCaseIsTheStructDefaults)
{
  const Case c = roller_defaults();
  EXPECT_SAME_EXACT(c, Case{}, scene);
  EXPECT_SAME_EXACT(c, Case{}, measured_flux_file);

  ASSERT_TRUE(c.roller);
  const Roller roller;
  EXPECT_SAME(*c.roller, roller, shaft_radius);
  EXPECT_SAME(*c.roller, roller, shaft_mu_r);
  EXPECT_SAME(*c.roller, roller, magnet_mu_r);
  EXPECT_SAME(c.roller->poles.at(0), Pole{}, shape_factor);

  ASSERT_TRUE(c.sleeve);
  const Sleeve sleeve;
  EXPECT_SAME(*c.sleeve, sleeve, thickness);
  EXPECT_SAME(*c.sleeve, sleeve, rpm);
  EXPECT_SAME(*c.sleeve, sleeve, spin_up_time);

  const Drum drum;
  EXPECT_SAME(c.drum, drum, rpm);
  EXPECT_SAME(c.drum, drum, spin_up_time);
  EXPECT_SAME(c.drum, drum, angle);
  EXPECT_SAME(c.drum, drum, pc_thickness);
  EXPECT_SAME(c.drum, drum, pc_eps_r);

  ASSERT_EQ(c.blades.size(), 1u);
  const BladeOrGuide blade;
  EXPECT_SAME(c.blades[0], blade, mu_r);
  EXPECT_SAME_EXACT(c.blades[0], blade, material);
  EXPECT_SAME_EXACT(c.blades[0], blade, is_doctor_blade);

  const Case box = box_defaults();
  ASSERT_EQ(box.planes.size(), 1u);
  const PlaneWall plane;
  expect_same_vec3(box.planes[0].point, plane.point, "point");
  expect_same_vec3(box.planes[0].normal, plane.normal, "normal");
  EXPECT_SAME_EXACT(box.planes[0], plane, material);
  EXPECT_TRUE(box.planes[0].path.empty());
}

// The particles: materials and populations (read by the DEM's contacts and insertion).
TEST(ModuleDefaults, ParticlesOfADefaultCaseAreTheStructDefaults)
{
  const Case c = roller_defaults();
  const Material m;
  const Material &wall = c.material("wall"); // only its Young's modulus given
  EXPECT_SAME(wall, m, poisson_ratio);
  EXPECT_SAME(wall, m, density);
  EXPECT_SAME(wall, m, mu_r);
  EXPECT_SAME(wall, m, saturation_magnetisation);
  EXPECT_SAME(wall, m, friction);
  EXPECT_SAME(wall, m, rolling_friction);
  EXPECT_SAME_EXACT(wall, m, polygon_angles);
  EXPECT_SAME(wall, m, damping);
  EXPECT_SAME(wall, m, restitution);
  EXPECT_SAME(wall, m, hamaker);
  EXPECT_SAME_EXACT(wall, m, hamaker_given);
  EXPECT_SAME(wall, m, adhesion_radius);

  ASSERT_EQ(c.populations.size(), 1u);
  const Population p;
  EXPECT_SAME_EXACT(c.populations[0], p, kind);
  EXPECT_SAME(c.populations[0], p, diameter_std);
  EXPECT_SAME(c.populations[0], p, mass);
  EXPECT_SAME(c.populations[0], p, concentration);
  EXPECT_SAME(c.populations[0], p, charge_to_mass);
  EXPECT_FALSE(c.populations[0].insert_box);
  // The population's material defaults to its kind (derived, no struct default to compare).
  EXPECT_EQ(c.populations[0].material, "carrier");
  const Case box = box_defaults();
  EXPECT_SAME(box.populations.at(0), p, layer_thickness);
}

// The applied field (a uniform field's direction, magnitude and ramp; the kind is derived:
// auto = the roller's field when there is a roller, else none).
TEST(ModuleDefaults, AppliedFieldOfADefaultCaseIsTheStructDefaults)
{
  const AppliedField built;
  const Case box = box_defaults();
  EXPECT_SAME_EXACT(box.applied_field, built, kind);
  expect_same_vec3(box.applied_field.uniform_direction, built.uniform_direction, "uniform_direction");
  EXPECT_SAME(box.applied_field, built, uniform_magnitude);
  EXPECT_SAME(box.applied_field, built, ramp_time);
  EXPECT_TRUE(box.applied_field.schedule.empty());
  EXPECT_EQ(roller_defaults().applied_field.kind, AppliedField::Kind::roller);
}

// The measurements (nip, compression) and the output.
TEST(ModuleDefaults, MeasurementAndOutputSettingsOfADefaultCaseAreTheStructDefaults)
{
  const Case c = roller_defaults();
  const NipSettings nip;
  EXPECT_SAME(c.nip, nip, average_from);
  EXPECT_SAME(c.nip, nip, sample_interval);
  EXPECT_SAME(c.nip, nip, bin_width);
  EXPECT_SAME(c.nip, nip, half_width);
  EXPECT_SAME(c.nip, nip, chain_bin_angle);
  EXPECT_SAME(c.nip, nip, chain_half_angle);

  const DevelopmentSettings development;
  EXPECT_SAME(c.development, development, measure_from);
  EXPECT_SAME(c.development, development, measure_to);
  EXPECT_SAME(c.development, development, sample_interval);
  EXPECT_SAME(c.development, development, average_from);

  const CompressionSettings compression;
  EXPECT_SAME_EXACT(c.compression, compression, plate);
  EXPECT_SAME_EXACT(c.compression, compression, stage);
  EXPECT_SAME(c.compression, compression, sample_interval);
  EXPECT_SAME(c.compression, compression, average_window);
  EXPECT_SAME(c.compression, compression, map_interval);

  // Particles entering and leaving (inflow, outflow, flow_report): off by default.
  const FlowSettings flow;
  EXPECT_SAME_EXACT(c.flow, flow, inflow_population);
  EXPECT_SAME(c.flow, flow, inflow_areal_mass);
  EXPECT_SAME(c.flow, flow, inflow_angle);
  EXPECT_SAME(c.flow, flow, inflow_layer_height);
  EXPECT_SAME(c.flow, flow, inflow_prefill_arc);
  EXPECT_SAME(c.flow, flow, inflow_sump_mass);
  EXPECT_SAME_EXACT(c.flow, flow, inflow_supply);
  EXPECT_SAME_EXACT(c.flow, flow, inflow_prefill_no_room);
  EXPECT_SAME(c.flow, flow, interval);
  EXPECT_SAME(c.flow, flow, outflow_angle);
  EXPECT_SAME(c.flow, flow, outflow_width);
  EXPECT_SAME(c.flow, flow, outflow_radius);
  EXPECT_SAME(c.flow, flow, sample_interval);
  EXPECT_SAME(c.flow, flow, flux_angle);
  EXPECT_SAME(c.flow, flow, density_window);
  EXPECT_FALSE(c.flow.inflow());
  EXPECT_FALSE(c.flow.outflow());

  // The developer after the doctor blade (dma).
  const DmaSettings dma;
  EXPECT_SAME(c.dma, dma, after_blade);
  EXPECT_SAME(c.dma, dma, window);
  EXPECT_SAME(c.dma, dma, height);
  EXPECT_SAME(c.dma, dma, front_window);
  EXPECT_SAME(c.dma, dma, release_from);
  EXPECT_SAME(c.dma, dma, release_to);
  EXPECT_SAME(c.dma, dma, sample_interval);
  EXPECT_SAME(c.dma, dma, average_from);

  const OutputSettings output;
  // The run folder of a case from a file is named after it; a Case built by hand writes into results/.
  EXPECT_EQ(c.output.directory, output.directory + "/" + c.name);
  EXPECT_TRUE(c.output.automatic);
  EXPECT_FALSE(output.automatic);
  EXPECT_SAME_EXACT(c.output, output, vtu);
  EXPECT_SAME_EXACT(c.output, output, xdmf);
}
