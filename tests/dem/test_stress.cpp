// The stress suite: the engine pushed to where it breaks. Each case must
// either give the right answer (checked against an exact result) or stop with a message that
// names the cause — and, in a run, keep a last good checkpoint and write nothing that is not a
// number (time series, snapshots and checkpoint are read back). Each case appends a row to the suite's table (stress_table.h; tools/stress,
// docs/stress.md).
//
// Built twice: dem_stress_quick (label stress_quick, in the default suite: the reduced cases,
// a few seconds each) and dem_stress (label stress, MAGBRUSH_STRESS_FULL: more settings and
// the 10⁶-step energy balance; tools/stress).
#include "dem/dem_run.h"
#include "dem/energy_ledger.h"
#include "dem/force_terms/force_term_registry.h"
#include "tests/dem/dem_test_scenes.h"
#include "tests/dem/stress_table.h"
#include "tests/test_temp_dir.h"

#include "case/case_parser.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#ifndef MAGBRUSH_STRESS_FULL
#define MAGBRUSH_STRESS_FULL 0
#endif
// The two builds' tests need names of their own (ctest names them by the GoogleTest name).
#if MAGBRUSH_STRESS_FULL
#define STRESS_SUITE Stress
#else
#define STRESS_SUITE StressQuick
#endif

namespace magbrush::dem::testing {
namespace {

namespace fs = std::filesystem;
constexpr bool full = MAGBRUSH_STRESS_FULL != 0;

std::string format(const char *fmt, double a, double b = 0.0, double c = 0.0)
{
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

// Every dynamic quantity of every particle is a number.
bool state_is_finite(const DemSystem &s)
{
  for (double v : state_by_id(s))
    if (!std::isfinite(v))
      return false;
  return true;
}

// Every numeric cell of a CSV file is finite ("nan", "inf" anywhere fail).
bool csv_is_finite(const fs::path &path, std::string &bad)
{
  std::ifstream in(path);
  std::string line;
  std::getline(in, line); // header
  long rows = 0;
  while (std::getline(in, line))
  {
    ++rows;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ','))
    {
      char *end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (end != cell.c_str() && !std::isfinite(v))
      {
        bad = path.string() + ": " + line;
        return false;
      }
      if (cell.find("nan") != std::string::npos || cell.find("inf") != std::string::npos)
      {
        bad = path.string() + ": " + line;
        return false;
      }
    }
  }
  if (rows == 0)
    bad = path.string() + " has no rows";
  return rows > 0;
}

// ------------------------------------------------------------------------------------------
// A sphere dropped head-on onto a 50 GPa plane: its largest overlap against Hertz's and its
// rebound speed against the impact speed (undamped, frictionless: e = 1).
struct Impact
{
  bool refused = false, stopped = false;
  std::string message;
  double overlap_error = 0.0, restitution_error = 0.0, steps_in_contact = 0.0;
};

Material carrier_material()
{
  Material m = elastic_material("carrier", 1e9, 0.35, 2200); // Kawamoto's carrier
  return m;
}

Case sphere_on_wall_case(const Material &m, double wall_modulus)
{
  Case c = single_species_case(m);
  add_rigid_plane(c, {0, 0, 0}, {0, 0, 1});
  c.materials.back().youngs_modulus = wall_modulus;
  c.dem.verlet_skin = 0.1;
  return c;
}

// dt_fraction of the engine's stable limit (0: the automatic step).
Impact sphere_wall_impact(const Material &m, double radius, double speed, double dt_fraction)
{
  Case c = sphere_on_wall_case(m, 5e10);
  Impact out;
  if (dt_fraction > 0.0)
  {
    DemSystem probe(c);
    probe.particles().add({0, 0, radius * 1.01}, radius, m.density, 0, 0.0);
    probe.initialize();
    c.dem.time_step = dt_fraction * probe.stable_time_step_info().limit;
  }
  DemSystem sys(c);
  sys.particles().add({0, 0, radius + 1e-3 * radius}, radius, m.density, 0, 0.0);
  sys.particles().vz = {-speed};
  try
  {
    sys.initialize();
  }
  catch (const std::invalid_argument &e)
  {
    out.refused = true;
    out.message = e.what();
    return out;
  }
  const double E_star = sys.contact_table().particle_wall(0, 0).effective_modulus;
  const double mass = sys.particles().mass[0];
  const HertzImpact h = hertz_impact(mass, radius, E_star, speed);
  double delta_max = 0.0;
  long in_contact = 0;
  try
  {
    for (long k = 0; k < 1000000; ++k)
    {
      sys.step();
      const double delta = radius - sys.particles().z[0];
      delta_max = std::max(delta_max, delta);
      in_contact += delta > 0.0;
      if (sys.particles().vz[0] > 0.0 && delta < 0.0)
        break;
    }
  }
  catch (const StabilityError &e)
  {
    out.stopped = true;
    out.message = e.what();
    return out;
  }
  out.overlap_error = delta_max / h.delta_max - 1.0;
  out.restitution_error = sys.particles().vz[0] / speed - 1.0;
  out.steps_in_contact = static_cast<double>(in_contact);
  EXPECT_TRUE(state_is_finite(sys));
  return out;
}

// Right: overlap within 3 % of Hertz and the rebound within 1 % (the limit is set for ten
// steps per contact at 1 m/s; a fast impact has fewer).
void judge_impact(const std::string &name, const std::string &setting, const Impact &r, double seconds)
{
  StressRow row{name, setting, StressOutcome::right, "", "", seconds};
  if (r.refused || r.stopped)
  {
    row.outcome = r.refused ? StressOutcome::refused : StressOutcome::stopped;
    row.message = r.message;
    EXPECT_FALSE(r.message.empty());
  }
  else
  {
    row.figure = format("delta_max %+.2e of Hertz, rebound %+.2e, %.0f steps in contact", r.overlap_error,
                        r.restitution_error, r.steps_in_contact);
    EXPECT_LT(std::abs(r.overlap_error), 0.03) << setting;
    EXPECT_LT(std::abs(r.restitution_error), 0.01) << setting;
  }
  record_stress_row(row);
}

TEST(STRESS_SUITE, TimeStepAgainstTheStableLimitWithFastImpacts)
{
  const std::vector<double> fractions = full ? std::vector<double>{0.1, 0.25, 0.5, 0.75, 0.9, 1.0, 1.2, 1.5}
                                             : std::vector<double>{0.1, 1.0, 1.5};
  // 5 m/s: 17x the Kawamoto sleeve's surface speed (0.29 m/s), a bead flung off the brush;
  // 20 m/s: beyond anything the scenes drive (the overlap reaches the guard's 10 %).
  const std::vector<double> speeds = full ? std::vector<double>{1.0, 5.0, 20.0} : std::vector<double>{5.0};
  for (double v : speeds)
    for (double f : fractions)
    {
      const double t0 = omp_get_wtime();
      const Impact r = sphere_wall_impact(carrier_material(), 30e-6, v, f);
      const std::string setting = format("dt = %.2g x limit, 60 um carrier at %.3g m/s on 50 GPa", f, v);
      judge_impact("time step", setting, r, omp_get_wtime() - t0);
      if (f > 1.0)
      {
        EXPECT_TRUE(r.refused) << "a step above the limit must be refused: " << setting;
      }
    }
}

// 7 µm toner (E = 3 GPa) against 50 GPa walls: a stiffness ratio of ~17 and a contact of a
// few ns; the automatic step must resolve it.
TEST(STRESS_SUITE, TonerAgainstAStiffWall)
{
  Material toner = elastic_material("toner", 3e9, 0.35, 1100);
  const std::vector<double> speeds = full ? std::vector<double>{0.1, 1.0, 5.0} : std::vector<double>{1.0};
  for (double v : speeds)
  {
    const double t0 = omp_get_wtime();
    const Impact r = sphere_wall_impact(toner, 3.5e-6, v, 0.0);
    judge_impact("stiffness ratio", format("7 um toner (3 GPa) at %.3g m/s on 50 GPa, automatic step", v), r,
                 omp_get_wtime() - t0);
  }
}

// ------------------------------------------------------------------------------------------
// Two spheres placed overlapping by a fraction of their radius, at rest, undamped: below the
// guard the Hertz energy comes out as kinetic energy (½ m* v_rel² = (2/5) k_n δ0^{5/2});
// above it the engine stops at step 0 with the pair named.
TEST(STRESS_SUITE, InitialOverlaps)
{
  const std::vector<double> fractions = full ? std::vector<double>{0.001, 0.02, 0.05, 0.09, 0.15, 0.5}
                                             : std::vector<double>{0.02, 0.09, 0.15};
  const Material m = carrier_material();
  const double R = 30e-6;
  for (double f : fractions)
  {
    const double t0 = omp_get_wtime();
    Case c = single_species_case(m);
    c.dem.verlet_skin = 0.1;
    DemSystem sys(c);
    const double delta0 = f * R;
    sys.particles().add({-R + 0.5 * delta0, 0, 0}, R, m.density, 0, 0.0);
    sys.particles().add({R - 0.5 * delta0, 0, 0}, R, m.density, 0, 0.0);
    StressRow row{"initial overlap", format("two 60 um carriers overlapping by %.3g %% of r, at rest", 100 * f),
                  StressOutcome::right, "", "", 0.0};
    try
    {
      sys.initialize();
      const double E_star = sys.contact_table().particle_pair(0, 0).effective_modulus;
      const double released = HertzNormal::energy(HertzNormal::stiffness(E_star, 0.5 * R), delta0);
      for (long k = 0; k < 100000 && std::abs(sys.particles().x[1] - sys.particles().x[0]) <= 2 * R; ++k)
        sys.step();
      sys.advance(10);
      const double kinetic = sys.kinetic_energy();
      row.figure = format("kinetic energy after separation %+.2e of the Hertz energy released", kinetic / released - 1.0);
      EXPECT_NEAR(kinetic / released, 1.0, 0.01) << row.setting;
      EXPECT_LT(f, c.dem.max_overlap_fraction) << "an overlap beyond the guard ran";
      EXPECT_TRUE(state_is_finite(sys));
    }
    catch (const StabilityError &e)
    {
      row.outcome = StressOutcome::stopped;
      row.message = e.what();
      EXPECT_GT(f, c.dem.max_overlap_fraction) << row.message;
      EXPECT_NE(row.message.find("overlaps particle id"), std::string::npos) << row.message;
      EXPECT_NE(row.message.find("at step 0"), std::string::npos) << row.message;
    }
    row.seconds = omp_get_wtime() - t0;
    record_stress_row(row);
  }
}

// ------------------------------------------------------------------------------------------
// Two carriers a hair apart along a uniform field, μr from the paper's 3.9 to 10⁴ (the
// polarisability α ∝ (μr − 1)/(μr + 2) saturates at 1), linear and with a saturation
// magnetisation: the attraction must stay finite and grow with μr, and a run of the pair
// (which the field pulls into contact) must either hold them at a finite overlap or stop.
TEST(STRESS_SUITE, PermeabilityUpToSaturation)
{
  const std::vector<double> mu_rs = full ? std::vector<double>{3.9, 10, 30, 100, 1000, 1e4} : std::vector<double>{3.9, 1e4};
  const std::vector<double> saturations = {0.0, 3e5}; // linear; ferrite-like M_s = 3e5 A/m
  // The exact two-sphere correction (the default model) and plain mutual dipoles, which have
  // no series to converge.
  const std::vector<std::string> models = full ? std::vector<std::string>{"corrected", "mutual_dipole"}
                                               : std::vector<std::string>{"corrected"};
  const double R = 30e-6;
  for (const std::string &model : models)
  {
    for (double Ms : saturations)
    {
      double previous = 0.0;
      for (double mu_r : mu_rs)
      {
        const double t0 = omp_get_wtime();
        Material m = carrier_material();
        m.mu_r = mu_r;
        m.saturation_magnetisation = Ms;
        m.damping = 0.6;
        Case c = single_species_case(m);
        c.populations[0].kind = ParticleKind::carrier;
        c.applied_field.kind = AppliedField::Kind::uniform;
        c.applied_field.uniform_direction = {0, 0, 1};
        c.applied_field.uniform_magnitude = 0.13;
        c.dem.verlet_skin = 0.1;
        c.dem.magnetic_refresh = 0.0;
        c.dem.magnetic_model = model;
        DemSystem sys(c);
        add_case_force_terms(sys, c);
        sys.particles().add({0, 0, -R - 0.01 * R}, R, m.density, 0, 0.0);
        sys.particles().add({0, 0, R + 0.01 * R}, R, m.density, 0, 0.0);
        StressRow row{"permeability", format("two carriers in 130 mT, mu_r = %.3g, M_s = %.3g A/m, ", mu_r, Ms) + model,
                      StressOutcome::right, "", "", 0.0};
        try
        {
          sys.initialize();
        }
        catch (const std::runtime_error &e)
        {
          row.outcome = StressOutcome::refused;
          row.message = e.what();
          EXPECT_NE(row.message.find("materials.*.mu_r"), std::string::npos) << row.message;
          EXPECT_GT(mu_r, 10.0) << row.message; // (it converges at the measured carriers' 3-10)
          row.seconds = omp_get_wtime() - t0;
          record_stress_row(row);
          continue;
        }
        // Not touching yet: the forces are the magnetic attraction alone.
        const std::size_t top = sys.particles().z[0] > sys.particles().z[1] ? 0 : 1;
        const double pull = -sys.forces().fz[top];
        EXPECT_TRUE(std::isfinite(pull));
        EXPECT_GT(pull, previous) << row.setting << ": the attraction must grow with mu_r";
        previous = pull;
        try
        {
          sys.advance(full ? 20000 : 4000);
          const auto &p = sys.particles();
          const double gap = std::abs(p.z[1] - p.z[0]) - 2 * R;
          row.figure = format("attraction %.3g uN; after the run overlap %.3g %% of r", pull * 1e6, -100 * gap / R);
          EXPECT_TRUE(state_is_finite(sys));
          EXPECT_LT(-gap / R, c.dem.max_overlap_fraction);
        }
        catch (const StabilityError &e)
        {
          row.outcome = StressOutcome::stopped;
          row.message = e.what();
          row.figure = format("attraction %.3g uN", pull * 1e6);
        }
        row.seconds = omp_get_wtime() - t0;
        record_stress_row(row);
      }
    }
  }
}

// ------------------------------------------------------------------------------------------
// A doctor blade touching the sleeve: refused at the case check with the key named.
TEST(STRESS_SUITE, BladeTouchingTheSleeveIsRefused)
{
  const double t0 = omp_get_wtime();
  const std::string yaml = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kweon_full_roller.yaml";
  StressRow row{"blade on the sleeve", "kweon_full_roller with blades.doctor.gap = 0", StressOutcome::refused, "", "",
                0.0};
  try
  {
    load_case(yaml, {"blades.doctor.gap=0 mm"});
    ADD_FAILURE() << "a blade touching the sleeve was accepted";
  }
  catch (const std::exception &e)
  {
    row.message = e.what();
  }
  EXPECT_NE(row.message.find("blades.doctor.gap"), std::string::npos) << row.message;
  row.seconds = omp_get_wtime() - t0;
  record_stress_row(row);
}

// A doctor blade 5 µm from the sleeve — a seventh of a carrier — with carriers carried into
// the wedge by the turning sleeve (Kweon's roller at 400 rpm, 0.42 m/s). A body force of
// 1000 g towards the roller's axis stands in for the magnets' pull (µN on a 35 µm bead), which
// drives the friction that drags them. The right answer: no bead passes the gap, and the
// state stays finite (the sleeve slides under the held beads); or a stop with a message.
TEST(STRESS_SUITE, CarriersDraggedIntoABladeAlmostTouchingTheSleeve)
{
  const double t0 = omp_get_wtime();
  const std::string yaml = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kweon_full_roller.yaml";
  Case c = load_case(yaml, {"blades.doctor.gap=5um", "dem.air_viscosity=0"});
  c.applied_field.kind = AppliedField::Kind::none; // (the pull is the body force below)
  c.electric.enabled = false;
  for (auto &p : c.populations)
    p.charge_to_mass = 0.0;
  c.flow = {};
  // The blade sits at 270° (below the axis): "towards the axis" there is +y.
  c.dem.gravity = {0, 1000 * 9.81, 0};
  DemSystem sys(c);
  add_case_force_terms(sys, c);
  const double R_sleeve = c.sleeve->radius, r = 17.5e-6;
  const double blade_angle = 270.0 * M_PI / 180.0;
  const int beads = full ? 12 : 4;
  for (int k = 0; k < beads; ++k)
  {
    // Upstream of the blade's face (1.5 mm thick: its face is 0.75 mm before its centre line;
    // the sleeve turns counter-clockwise), a bead's width apart.
    const double angle = blade_angle - (1.0e-3 + 2.2 * r * k) / R_sleeve;
    sys.particles().add({(R_sleeve + r) * std::cos(angle), (R_sleeve + r) * std::sin(angle), 0}, r,
                        c.material(c.populations[0].material).density, 0, 0.0);
  }
  StressRow row{"blade on the sleeve",
                format("kweon_full_roller, blade 5 um from the sleeve, %.0f carriers of 35 um dragged in at 0.42 m/s "
                       "under 1000 g",
                       beads),
                StressOutcome::right, "", "", 0.0};
  double last_angle = 0.0;
  try
  {
    sys.initialize();
    const long steps = std::lround((full ? 5e-3 : 1.5e-3) / sys.time_step());
    sys.advance(steps);
    const auto &p = sys.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
    {
      double a = std::atan2(p.y[i], p.x[i]);
      if (a < 0)
        a += 2 * M_PI;
      last_angle = std::max(last_angle, a);
    }
    EXPECT_TRUE(state_is_finite(sys));
    EXPECT_LT(last_angle, blade_angle) << "a bead passed the 5 um gap";
    row.figure = format("foremost bead %.1f um upstream of the blade's centre line after %.3g ms",
                        (blade_angle - last_angle) * R_sleeve * 1e6, sys.time() * 1e3);
  }
  catch (const StabilityError &e)
  {
    // The wedge at the blade's edge self-locks: the sleeve's drag and the blade's reaction
    // grow together, without bound, against prescribed walls.
    row.outcome = StressOutcome::stopped;
    row.message = e.what();
    EXPECT_NE(row.message.find("overlaps a wall"), std::string::npos) << row.message;
    EXPECT_TRUE(state_is_finite(sys));
  }
  row.seconds = omp_get_wtime() - t0;
  record_stress_row(row);
}

// ------------------------------------------------------------------------------------------
// Kawamoto's compression test in a small periodic square: the plate is lowered onto a brush
// in 130 mT until the gap is a little more than one bead (a monolayer). With room for a
// monolayer the beads end in one layer; with more beads than fit, the prescribed plate cannot
// be resisted and the run must stop with a message and keep its last good checkpoint.
struct PlateRun
{
  bool stopped = false;
  std::string message, log;
  fs::path dir;
  double spread = 0.0; // largest − smallest bead centre height at the end [m]
};

PlateRun press_to_monolayer(long beads, double plate_speed, double wall_friction, const std::string &name)
{
  const std::string yaml = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_brush_compression.yaml";
  PlateRun out;
  out.dir = magbrush::testing::test_temp_dir("stress_plate_" + name);
  const double d = 60e-6, side = 0.3e-3, gap = 1.04 * d, start = 0.35e-3, t_down = (start - gap) / plate_speed;
  Case c = load_case(yaml, {"output.directory=" + out.dir.string(), "populations.carrier.count=" + std::to_string(beads),
                            "populations.carrier.diameter_std=0um", "dem.periodic_length_x=0.3mm",
                            "dem.periodic_length_y=0.3mm", "dem.checkpoint_interval=100us",
                            "dem.output_interval=100us"});
  c.dem.duration = 0.2e-3 + t_down;
  c.populations[0].insert_box = std::array<Vec3, 2>{Vec3{0, 0, 0.03e-3}, Vec3{side, side, 0.3e-3}};
  c.applied_field.schedule = {{0.0, 0.0}, {0.05e-3, 0.13}};
  c.applied_field.uniform_magnitude = 0.13;
  c.planes[1].point = {0, 0, start};
  c.planes[1].path = {{0.0, {0, 0, 0}}, {0.1e-3, {0, 0, 0}}, {0.1e-3 + t_down, {0, 0, gap - start}}};
  for (auto &m : c.materials)
    if (m.name == "wall")
      m.friction = wall_friction;
  c.compression.sample_interval = 10e-6;
  c.compression.average_window = 50e-6;
  c.compression.map_interval = 0.0;
  std::ostringstream log;
  try
  {
    DemRun run(c, RunOptions{}, log);
    run.run();
    const auto &p = run.system().particles();
    double lo = 1e9, hi = -1e9;
    for (double z : p.z)
      lo = std::min(lo, z), hi = std::max(hi, z);
    out.spread = hi - lo;
  }
  catch (const StabilityError &e)
  {
    out.stopped = true;
    out.message = e.what();
  }
  out.log = log.str();
  return out;
}

// Every value of the float datasets of one HDF5 snapshot is finite (and the checksums read).
bool snapshot_is_finite(const fs::path &h5, std::string &bad)
{
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0)
  {
    bad = h5.string() + " cannot be opened";
    return false;
  }
  bool ok = true;
  for (const char *name : {"position", "velocity", "angular_velocity", "force", "radius"})
  {
    const hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    const hid_t space = d >= 0 ? H5Dget_space(d) : -1;
    const hssize_t count = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
    std::vector<double> values(static_cast<std::size_t>(std::max<hssize_t>(count, 0)));
    const bool read = count >= 0 && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0;
    if (space >= 0)
      H5Sclose(space);
    if (d >= 0)
      H5Dclose(d);
    if (!read)
      bad = h5.string() + ": dataset " + name + " unreadable";
    for (double v : values)
      if (!std::isfinite(v))
        bad = h5.string() + ": a non-finite value in " + name;
    ok = ok && bad.empty();
  }
  H5Fclose(f);
  return ok;
}

// What a run left behind: a readable, finite last checkpoint, a finite time series and finite
// snapshots.
void expect_good_outputs(const PlateRun &r, const Case &c)
{
  std::string bad;
  EXPECT_TRUE(csv_is_finite(r.dir / "dem" / "time_series.csv", bad)) << bad;
  long snapshots = 0;
  for (const auto &entry : fs::recursive_directory_iterator(r.dir / "dem"))
    if (entry.path().extension() == ".h5")
    {
      ++snapshots;
      EXPECT_TRUE(snapshot_is_finite(entry.path(), bad)) << bad;
    }
  EXPECT_GT(snapshots, 0) << "no snapshot was written";
  const fs::path checkpoint = r.dir / "dem" / "checkpoint.bin";
  ASSERT_TRUE(fs::exists(checkpoint)) << r.log;
  DemSystem restored(c);
  add_case_force_terms(restored, c);
  restored.read_checkpoint(checkpoint.string());
  EXPECT_TRUE(state_is_finite(restored));
}

TEST(STRESS_SUITE, PlatePressesTheBrushToAMonolayer)
{
  // A monolayer holds ~29 beads in the 0.3 mm square: 20 fit, 60 do not. 0.29 m/s is 3x
  // Kawamoto's plate speed; the full suite also presses 20 beads, at 0.29 and 0.05 m/s, and
  // between frictionless walls. (A straight chain between walls with friction μ is locked:
  // it can only tip over once it leans by more than atan μ, 19° at μ = 0.35.)
  struct Press
  {
    long beads;
    double speed, wall_friction;
  };
  std::vector<Press> runs = {{60, 0.288, 0.35}};
  if (full)
    runs = {{20, 0.288, 0.35}, {60, 0.288, 0.35}, {20, 0.05, 0.35}, {20, 0.288, 0.0}};
  for (const Press &press : runs)
  {
    const long n = press.beads;
    const double t0 = omp_get_wtime();
    const PlateRun r = press_to_monolayer(n, press.speed, press.wall_friction,
                                          std::to_string(n) + "_" + std::to_string(static_cast<int>(press.speed * 1000)) +
                                              "_" + std::to_string(static_cast<int>(press.wall_friction * 100)));
    StressRow row{"plate to a monolayer",
                  format("%.0f beads of 60 um in a 0.3 mm square, 130 mT, plate down to a 62.4 um gap at %.3g m/s, ",
                         static_cast<double>(n), press.speed) +
                      format("wall friction %.2g", press.wall_friction),
                  StressOutcome::right, "", "", omp_get_wtime() - t0};
    const std::string yaml = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_brush_compression.yaml";
    const Case c = load_case(yaml, {"populations.carrier.count=" + std::to_string(n), "dem.periodic_length_x=0.3mm",
                                    "dem.periodic_length_y=0.3mm"});
    if (r.stopped)
    {
      // The prescribed plate is an unbounded force: beads that cannot get out of its way are
      // pressed into each other until the overlap guard stops the run.
      row.outcome = StressOutcome::stopped;
      row.message = r.message;
      EXPECT_NE(r.message.find("overlaps"), std::string::npos) << r.message;
      EXPECT_NE(r.log.find("the last good checkpoint is kept"), std::string::npos) << r.log;
    }
    else
    {
      row.figure = format("bead centres within %.3g um of one layer", r.spread * 1e6);
      EXPECT_LE(n, 29) << "more beads than a monolayer holds ended in one layer without a stop";
      EXPECT_LT(r.spread, 0.05 * 60e-6) << "not a monolayer";
    }
    expect_good_outputs(r, c);
    record_stress_row(row);
  }
}

// ------------------------------------------------------------------------------------------
// The energy balance of a long run: frictionless, damped beads under gravity between a stage
// and a plate that moves up and down (the wall puts work in, the contacts dissipate it). The
// ledger (dem/energy_ledger.h) sums the wall's work and the dashpots' losses independently of
// the integrator; the residual must stay within a stated fraction of the energy turned over.
TEST(STRESS_SUITE, EnergyBalanceOfALongRun)
{
  const double t0 = omp_get_wtime();
  const long steps = full ? 1000000 : 20000;
  Material m = elastic_material("bead", 1e8, 0.35, 2200);
  m.damping = 0.3;
  Case c = single_species_case(m);
  const double side = 0.4e-3, top = 0.5e-3;
  c.populations[0].diameter_mean = 100e-6;
  c.populations[0].diameter_std = 10e-6;
  c.populations[0].count = 24;
  c.populations[0].insert_box = std::array<Vec3, 2>{Vec3{0, 0, 0}, Vec3{side, side, 0.45e-3}};
  c.dem.periodic_length_x = c.dem.periodic_length_y = side;
  c.dem.gravity = {0, 0, -9.81};
  c.dem.seed = 7;
  add_rigid_plane(c, {0, 0, 0}, {0, 0, 1});
  c.materials.back().youngs_modulus = 5e10;
  add_rigid_plane(c, {0, 0, top}, {0, 0, -1});
  // The plate goes down 0.2 mm and back every 4 ms (0.1 m/s), for as long as the run lasts.
  auto &path = c.planes.back().path;
  for (int k = 0; k <= 200; ++k)
    path.push_back({2e-3 * k, {0, 0, k % 2 ? -0.2e-3 : 0.0}});
  DemSystem sys(c);
  add_case_force_terms(sys, c);
  sys.insert_particles();
  give_random_velocities(sys.particles(), 11);
  sys.initialize();
  EnergyLedger ledger(sys);
  for (long k = 0; k < steps; ++k)
  {
    sys.step();
    ledger.record(sys);
  }
  const EnergyLedger::Balance b = ledger.balance(sys);
  // The energy turned over: what came in (initial + wall work) — what the balance moves.
  const double turnover = b.initial + std::abs(b.wall_work) + b.dissipated;
  const double relative = std::abs(b.residual()) / turnover;
  StressRow row{"energy balance",
                format("24 damped frictionless beads, moving plate, gravity, %.3g steps of %.3g s", static_cast<double>(steps),
                       sys.time_step()),
                StressOutcome::right,
                format("residual %.2e of the %.3g J turned over (wall work %.3g J", relative, turnover, b.wall_work) +
                    format(", dissipated %.3g J)", b.dissipated),
                "", omp_get_wtime() - t0};
  std::printf("energy: initial %.6g J, kinetic %.6g, elastic %.6g, gravitational %.6g, dissipated %.6g, wall work "
              "%.6g, residual %.3g J\n",
              b.initial, b.kinetic, b.elastic, b.gravitational, b.dissipated, b.wall_work, b.residual());
  EXPECT_GT(b.wall_work, 0.0) << "the plate did no work: the case tests nothing";
  EXPECT_GT(b.dissipated, 0.0);
  EXPECT_LT(relative, 1e-3);
  EXPECT_TRUE(state_is_finite(sys));
  record_stress_row(row);
}

// The ledger refuses what it cannot account for rather than balancing it wrongly.
TEST(STRESS_SUITE, EnergyLedgerRefusesFriction)
{
  const Case c = falling_spheres_case(10, 0.5e-3, 0.5e-3, 3);
  DemSystem sys(c);
  sys.insert_particles();
  sys.initialize();
  EXPECT_THROW(EnergyLedger{sys}, std::invalid_argument);
}

} // namespace
} // namespace magbrush::dem::testing
