// A restart with the magnetics on continues bit for bit: a brush of carriers forming chains in
// a ramped uniform field, a few of them sent off so that the held forces go stale, are
// refreshed locally and fully, and the lists are rebuilt, run N steps straight (with a
// checkpoint written after N/2) against N/2 steps + a restart from that checkpoint + N/2.
// Every staleness mode (relative, local, absolute), the cell-multipole far field and the hard
// cutoff with the slab tail, the mutual and the corrected model. The control: the same
// restart under magnetic settings that differ in an irrelevant knob restores nothing (the
// held state is for other settings) and is NOT bit-identical, so the comparison can fail.
// Also bit for bit: the held steps run inside the engine's thread team against the same steps
// through the serial path, and on one thread, with and without the quiet steps that skip the
// check (MagneticTeamSteps).
#include "dem/force_terms/magnetic_force_term.h"

#include "case/case_parser.h"
#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"
#include "dem/force_terms/gravity.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <random>
#include <string>

using namespace magbrush;
using namespace magbrush::magnetics;

namespace {

// 160 carriers of 60 µm in a periodic 0.6 mm × 0.6 mm slab over a stage (`scale` 2: 640 on
// 1.2 mm × 1.2 mm, enough for the engine to run a thread team); the field ramps up over 4 µs
// (the held forces follow the ramp), refresh interval 3 µs, 20 ns steps. `more`: further
// dem keys.
std::string brush_case(const std::string &mode, const std::string &far_field, const std::string &model,
                       int scale = 1, const std::string &more = "")
{
  const std::string side = std::to_string(0.6 * scale) + " mm", count = std::to_string(160 * scale * scale);
  return R"(
name: magnetic_restart
scene: box
materials:
  carrier: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 2200 kg/m^3, mu_r: 3.9, friction: 0.45, damping: 0.6}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, damping: 0.6}
populations:
  - {name: carrier, kind: carrier, material: carrier, diameter: 60 um, count: )" +
         count + ", insert_box: [[0 mm, 0 mm, 0.03 mm], [" + side + ", " + side + R"(, 0.5 mm]]}
planes:
  - {name: stage, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
applied_field: {kind: uniform, direction: [0.3, 0, 1], magnitude: 130 mT, ramp_time: 4 us}
dem: {time_step: 2e-8 s, periodic_length_x: )" +
         side + ", periodic_length_y: " + side + R"(, air_viscosity: 0 Pa*s,
      magnetic_refresh: 3 us, magnetic_staleness_mode: )" +
         mode + ", magnetic_far_field: " + far_field + ", magnetic_model: " + model + ", magnetic_cutoff: 4" + more +
         R"(}
)";
}

// The engine with the case's force terms (gravity, the magnetics), the carriers inserted, and
// one carrier in 32 sent off at 0.4–0.7 m/s in a random direction (it moves its staleness
// limit, 1.5 µm, in a few µs: local refreshes around it), one at 2 m/s (past half the
// magnetic skin within the run: the lists are rebuilt); or empty, for a restart.
std::unique_ptr<dem::DemSystem> make_system(const Case &c, bool insert, MagneticSettings *settings = nullptr)
{
  auto system = std::make_unique<dem::DemSystem>(c);
  if (settings) // the registry's terms by hand: gravity (drag is off), then the magnetics
  {
    system->add_force_term(std::make_unique<dem::Gravity>(c.dem.gravity));
    system->add_force_term(std::make_unique<MagneticForceTerm>(
      c, *settings, AppliedMagneticField::from_settings(c.applied_field), system->box().length));
  }
  else
    dem::add_case_force_terms(*system, c);
  if (insert)
  {
    system->insert_particles();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    auto &p = system->particles();
    for (std::size_t i = 0; i < p.size(); i += 32)
    {
      const double speed = i == 0 ? 2.0 : 0.3 + 0.1 * static_cast<double>(i / 32);
      const double d[3] = {u(rng), u(rng), u(rng)};
      const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      p.vx[i] = speed * d[0] / norm;
      p.vy[i] = speed * d[1] / norm;
      p.vz[i] = speed * d[2] / norm;
    }
    system->initialize();
  }
  return system;
}

const MagneticForceTerm &magnetics_of(const dem::DemSystem &s)
{
  for (const auto &t : s.force_terms())
    if (const auto *m = dynamic_cast<const MagneticForceTerm *>(t.get()))
      return *m;
  throw std::logic_error("no magnetic term");
}

// Every dynamic array, in particle-id order, as raw bytes.
std::vector<double> state_by_id(const dem::DemSystem &s)
{
  const auto &p = s.particles();
  const auto &f = s.forces();
  std::vector<double> out(p.size() * 15);
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    const double v[15] = {p.x[i], p.y[i], p.z[i], p.vx[i], p.vy[i], p.vz[i], p.wx[i], p.wy[i],
                          p.wz[i], f.fx[i], f.fy[i], f.fz[i], f.tx[i], f.ty[i], f.tz[i]};
    std::memcpy(&out[static_cast<std::size_t>(p.id[i]) * 15], v, sizeof v);
  }
  return out;
}

bool bit_identical(const std::vector<double> &a, const std::vector<double> &b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

struct Outcome
{
  bool identical = false;
  bool unperturbed = false; // the straight run with a checkpoint = the one without
  bool control_identical = true;
  bool control_restored = true;
  long evaluations = 0, local_refreshes = 0, list_rebuilds = 0;
};

// Straight run A (checkpoint after `half` steps) vs restart B from that checkpoint, the
// control C (restart under settings with another max_sweeps: no held state restored), and
// the straight run without a checkpoint.
Outcome straight_vs_restart(const std::string &mode, const std::string &far_field, const std::string &model,
                            int half)
{
  const Case c = parse_case_text(brush_case(mode, far_field, model), "magnetic_restart.yaml");
  const std::string path =
    (magbrush::testing::test_temp_dir("magnetic_restart") / (mode + "_" + far_field + "_" + model + ".bin")).string();
  auto a = make_system(c, true);
  for (int k = 0; k < half; ++k)
    a->step();
  a->write_checkpoint(path);
  const auto bytes = std::filesystem::file_size(path);
  for (int k = 0; k < half; ++k)
    a->step();

  auto b = make_system(c, false);
  b->read_checkpoint(path);
  EXPECT_TRUE(magnetics_of(*b).restored_state());
  for (int k = 0; k < half; ++k)
    b->step();

  MagneticSettings other = MagneticSettings::from_case(c.dem);
  ++other.max_sweeps; // no effect on a converged solve, but other settings: nothing restored
  auto control = make_system(c, false, &other);
  control->read_checkpoint(path);
  for (int k = 0; k < half; ++k)
    control->step();

  // Writing the checkpoint changed nothing in the run that wrote it.
  auto plain = make_system(c, true);
  for (int k = 0; k < 2 * half; ++k)
    plain->step();

  Outcome o;
  o.identical = a->step_count() == b->step_count() && bit_identical(state_by_id(*a), state_by_id(*b));
  o.unperturbed = bit_identical(state_by_id(*a), state_by_id(*plain));
  o.control_identical = bit_identical(state_by_id(*a), state_by_id(*control));
  o.control_restored = magnetics_of(*control).restored_state();
  const MagneticForceTerm &m = magnetics_of(*a);
  o.evaluations = m.evaluations();
  o.local_refreshes = m.local_refreshes();
  o.list_rebuilds = m.refresh_counts().rebuilds;
  EXPECT_EQ(m.evaluations(), magnetics_of(*b).evaluations());
  EXPECT_EQ(m.local_refreshes(), magnetics_of(*b).local_refreshes());
  std::printf("%-8s %-14s %-13s: %ld full evaluations, %ld local refreshes, %ld list rebuilds; restart %s, "
              "control (state dropped) %s; checkpoint %.0f bytes per carrier\n",
              mode.c_str(), far_field.c_str(), model.c_str(), o.evaluations, o.local_refreshes, o.list_rebuilds,
              o.identical ? "bit-identical" : "DIFFERS", o.control_identical ? "identical" : "differs",
              static_cast<double>(bytes) / static_cast<double>(a->particles().size()));
  std::filesystem::remove(path);
  return o;
}

} // namespace

class MagneticRestart : public ::testing::TestWithParam<std::tuple<const char *, const char *, const char *>>
{};

TEST_P(MagneticRestart, ContinuesBitIdentically)
{
  const auto [mode, far_field, model] = GetParam();
  const Outcome o = straight_vs_restart(mode, far_field, model, 300);
  EXPECT_TRUE(o.identical);
  EXPECT_TRUE(o.unperturbed);
  EXPECT_FALSE(o.control_restored);
  EXPECT_FALSE(o.control_identical) << "the comparison could not tell a restart without magnetic state";
  // The paths that hold state were taken: more than the first evaluation, and local
  // refreshes where the mode makes them.
  EXPECT_GT(o.evaluations, 2);
  EXPECT_GT(o.list_rebuilds, 1);
  // (With the hard cutoff the slab tail is on in this slab, and it has no local version.)
  if (std::string(mode) != "absolute" && std::string(far_field) != "none")
  {
    EXPECT_GT(o.local_refreshes, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(
  StalenessModesAndFarFields, MagneticRestart,
  ::testing::Values(std::make_tuple("relative", "cell_multipole", "corrected"),
                    std::make_tuple("local", "cell_multipole", "mutual_dipole"),
                    std::make_tuple("absolute", "cell_multipole", "corrected"),
                    std::make_tuple("relative", "none", "corrected"),
                    std::make_tuple("local", "none", "mutual_dipole")),
  [](const auto &info) {
    return std::string(std::get<0>(info.param)) + "_" + std::get<1>(info.param) + "_" + std::get<2>(info.param);
  });

// The steps that hold their magnetic forces run inside the engine's thread team (shared
// loops: gather, staleness check, the close pairs' changes, the held forces), the others go
// through add_forces() outside it. Both ways give the same bits: 640 carriers, the held
// forces and the held dipoles, on 2 threads with the held steps in the team and without, and
// on 1 thread; and with the team's quiet steps (no gather, no check while the engine's
// drifts bound every move below what the last check certified) against checking every step.
// The run mixes held steps with local refreshes, full evaluations and rebuilds.
TEST(MagneticTeamSteps, HeldStepsInsideTheTeamGiveTheBitsOfTheSerialPath)
{
  const int threads_before = omp_get_max_threads();
  for (const char *hold : {"forces", "dipoles"})
  {
    const Case c = parse_case_text(
      brush_case("relative", "cell_multipole", "corrected", 2, std::string(", magnetic_hold: ") + hold),
      "magnetic_team_steps.yaml");
    auto run = [&](int threads, bool in_team, bool quiet = true) {
      omp_set_num_threads(threads);
      auto s = make_system(c, true);
      for (const auto &t : s->force_terms())
        if (auto *m = dynamic_cast<MagneticForceTerm *>(t.get()))
        {
          m->set_held_steps_in_team(in_team);
          m->set_quiet_steps(quiet);
        }
      for (int k = 0; k < 400; ++k)
        s->step();
      return s;
    };
    const auto team = run(2, true), serial = run(2, false), one = run(1, true), looking = run(2, true, false);
    const MagneticForceTerm &m = magnetics_of(*team);
    std::printf("hold %-7s: %ld of 400 steps held inside the team, %ld of them quiet; %ld full evaluations, "
                "%ld local refreshes, %ld list rebuilds; %zu live pairs\n",
                hold, m.steps_held_in_team(), m.quiet_steps(), m.evaluations(), m.local_refreshes(),
                m.refresh_counts().rebuilds, m.dipoles().live_pairs());
    EXPECT_TRUE(bit_identical(state_by_id(*team), state_by_id(*serial))) << hold;
    EXPECT_TRUE(bit_identical(state_by_id(*team), state_by_id(*one))) << hold;
    EXPECT_TRUE(bit_identical(state_by_id(*team), state_by_id(*looking))) << hold;
    // Both paths were taken (the first 200 steps follow the field's ramp: serial), and the
    // quiet steps (no check, their moves bounded by the engine's drifts) on both thread counts.
    EXPECT_GT(m.steps_held_in_team(), 150) << hold;
    EXPECT_GT(m.quiet_steps(), 20) << hold;
    EXPECT_GT(magnetics_of(*one).quiet_steps(), 20) << hold;
    EXPECT_EQ(magnetics_of(*looking).quiet_steps(), 0) << hold;
    EXPECT_GT(m.evaluations() + m.local_refreshes(), 10) << hold;
    EXPECT_EQ(magnetics_of(*serial).steps_held_in_team(), 0) << hold;
  }
  omp_set_num_threads(threads_before);
}

// The engine runs its team on fewer threads while a scene is small (and a user may change the
// thread count between runs). The quiet steps' per-thread sums were valid only for the team
// that reset them: a thread of a larger team later summed from a stale value and checked while
// the others took a quiet step — the team deadlocked (the regulation cell at 1.3 ms, 2 threads).
// Here the team alternates between 2 and 1 threads every few steps; the run must finish with
// the bits of a run on one thread.
TEST(MagneticTeamSteps, TeamSizeChangingBetweenRunsKeepsTheThreadsInStep)
{
  const int threads_before = omp_get_max_threads();
  const Case c = parse_case_text(
    brush_case("relative", "cell_multipole", "corrected", 2, ", magnetic_hold: dipoles"), "magnetic_team_size.yaml");
  auto run = [&](bool alternate) {
    omp_set_num_threads(1);
    auto s = make_system(c, true);
    for (int k = 0; k < 400; ++k)
    {
      if (alternate)
        omp_set_num_threads(k / 7 % 2 == 0 ? 2 : 1);
      s->step();
    }
    return s;
  };
  const auto alternating = run(true), one = run(false);
  const MagneticForceTerm &m = magnetics_of(*alternating);
  std::printf("alternating 2/1 threads: %ld steps held in the team, %ld quiet\n", m.steps_held_in_team(),
              m.quiet_steps());
  EXPECT_GT(m.quiet_steps(), 20);
  EXPECT_TRUE(bit_identical(state_by_id(*alternating), state_by_id(*one)));
  omp_set_num_threads(threads_before);
}
