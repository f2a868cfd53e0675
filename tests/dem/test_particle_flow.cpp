// Inflow and outflow on a conveyor: a sleeve (R = 2 mm, ω = 100 rad/s, v = 0.2 m/s) that
// carries a layer of beads fed onto it at 90° (inflow.areal_mass Γ = 0.05 kg/m²) and removed
// in the sector from 150° (outflow); a radial pull of 1000 m/s² towards the axis stands in for
// the magnet (so the beads ride on the sleeve by friction, without the magnetics' cost). The
// scene starts empty.
//
//  * steady state: the bead count settles (windowed means drift < 2 %);
//  * flux through the radial line at 130° (counted from positions, by id) equals the areal
//    mass around it × v × L_z, and the source's Γ × v × L_z, within 3 block-averaged standard
//    errors;
//  * mass budget: in − out = present − present(0), with in and out counted by the inflow and
//    the outflow, present summed from the particle state; the mass created follows Γ R φ(t) L_z
//    to within one bead;
//  * 1 vs 2 threads bit-identical, and a restart from a checkpoint in the middle continues
//    bit-identically (the source's random stream, mass owed and counters are in it).
#include "tests/dem/dem_test_scenes.h"
#include "dem/checkpoint_file.h"
#include "dem/measurements/flow_report.h"
#include "dem/particle_flow.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>

using namespace magbrush;
using namespace magbrush::dem;
using namespace magbrush::dem::testing;

namespace {

constexpr double deg = M_PI / 180.0;
constexpr double omega = 100.0, sleeve_radius = 2e-3, areal_mass = 0.05;

Case conveyor_case(double slab, double E = 1e7)
{
  Material m = elastic_material("carrier", E, 0.3, 2200);
  m.friction = 0.5;
  m.damping = 0.6;
  Case c = single_species_case(m);
  c.scene = "roller";
  c.populations[0].name = "carrier";
  c.populations[0].kind = ParticleKind::carrier;
  c.populations[0].diameter_mean = 100e-6;
  c.populations[0].diameter_std = 10e-6;
  Sleeve s;
  s.radius = sleeve_radius;
  s.rpm = omega * 60.0 / (2.0 * M_PI);
  c.sleeve = s;
  Material sl = elastic_material("sleeve", 5e10, 0.3, 0.0);
  sl.friction = 0.5;
  sl.damping = 0.6;
  c.materials.push_back(sl);
  c.dem.periodic_length = slab;
  c.dem.seed = 11;
  c.flow.inflow_areal_mass = areal_mass;
  c.flow.inflow_angle = 90 * deg;
  c.flow.inflow_layer_height = 0.3e-3;
  c.flow.interval = 20e-6;
  c.flow.outflow_angle = 150 * deg;
  c.flow.outflow_width = 60 * deg;
  c.flow.flux_angle = 130 * deg;
  c.flow.density_window = 16 * deg;
  c.flow.sample_interval = 50e-6;
  return c;
}

std::unique_ptr<DemSystem> make_conveyor(const Case &c, double pull = 1000.0)
{
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<RadialPull>(pull));
  sys->set_particle_exchange(std::make_unique<ParticleFlow>(c, *sys));
  sys->initialize();
  return sys;
}

// Runs to `end` [s], sampling the flow report every sample interval.
void run_sampled(DemSystem &sys, FlowReport &report, double end)
{
  const long every = std::max(1L, std::lround(report.interval() / sys.time_step()));
  const long last = std::lround(end / sys.time_step());
  while (sys.step_count() < last)
  {
    sys.advance(std::min(every, last - sys.step_count()));
    report.sample(sys);
  }
}

struct MeanAndError
{
  double mean = 0.0, error = 0.0; // the standard error of the mean over the blocks
};
MeanAndError over_blocks(const std::vector<double> &v)
{
  MeanAndError m;
  for (double x : v)
    m.mean += x;
  m.mean /= static_cast<double>(v.size());
  double var = 0.0;
  for (double x : v)
    var += (x - m.mean) * (x - m.mean);
  m.error = std::sqrt(var / static_cast<double>(v.size() - 1) / static_cast<double>(v.size()));
  return m;
}

} // namespace

TEST(DemParticleFlow, ConveyorReachesSteadyStateWithFluxEqualToDensityTimesSpeed)
{
  omp_set_num_threads(2);
  // Blocks of 4 ms: longer than a bead needs to cross the density window (16 deg, 2.8 ms), so
  // that the blocks are close to independent and their standard error means what it says.
  const double slab = 3e-3, end = 40e-3, steady_from = 12e-3, block = 4e-3;
  Case c = conveyor_case(slab);
  c.flow.average_from = steady_from;
  auto sys = make_conveyor(c);
  FlowReport report(c);
  run_sampled(*sys, report, end);
  const auto &rows = report.rows();
  const double v = omega * sleeve_radius, nominal = areal_mass * v * slab;

  // Steady state: the means over the two halves of the steady part (14 ms each, 1.3 transit
  // times of a bead from inflow to outflow) agree within 2 %, for the mass and the count.
  constexpr std::size_t W = 2;
  std::vector<double> count(W, 0.0), mass(W, 0.0);
  std::vector<long> samples(W, 0);
  for (const auto &r : rows)
    if (r.time > steady_from)
    {
      const std::size_t w = std::min<std::size_t>(W - 1, static_cast<std::size_t>((r.time - steady_from) / ((end - steady_from) / W)));
      count[w] += static_cast<double>(r.present);
      mass[w] += r.present_mass;
      ++samples[w];
    }
  for (std::size_t w = 0; w < W; ++w)
  {
    count[w] /= static_cast<double>(samples[w]);
    mass[w] /= static_cast<double>(samples[w]);
  }
  auto drift = [](const std::vector<double> &v) {
    const double lo = *std::min_element(v.begin(), v.end()), hi = *std::max_element(v.begin(), v.end());
    return (hi - lo) / lo;
  };
  std::printf("steady state: window means %.1f %.1f beads (drift %.2f %%), %.4g %.4g kg (drift %.2f %%)\n", count[0],
              count[1], 100.0 * drift(count), mass[0], mass[1], 100.0 * drift(mass));
  EXPECT_LT(drift(mass), 0.02);
  EXPECT_LT(drift(count), 0.02);
  EXPECT_GT(count[0], 150.0);

  // Flux per block (crossings counted from positions) against the areal mass × v × L_z.
  std::vector<double> flux, dens, diff;
  double t0 = steady_from, crossed = 0.0, areal = 0.0;
  long n_areal = 0, crossings = 0;
  for (const auto &r : rows)
  {
    if (r.time <= steady_from)
      continue;
    crossed += r.crossed_mass;
    crossings += r.crossed;
    areal += r.areal_mass;
    ++n_areal;
    if (r.time >= t0 + block - 1e-12)
    {
      flux.push_back(crossed / (r.time - t0));
      dens.push_back(areal / static_cast<double>(n_areal) * v * slab);
      diff.push_back(flux.back() - dens.back());
      t0 = r.time;
      crossed = areal = 0.0;
      n_areal = 0;
    }
  }
  const MeanAndError F = over_blocks(flux), D = over_blocks(dens), d = over_blocks(diff);
  std::printf("flux through 130 deg: %.5g kg/s +- %.2g (%zu blocks of %.3g s, %ld beads crossed); areal mass x v x L_z "
              "= %.5g +- %.2g; difference %.3g +- %.2g; source Gamma v L_z = %.5g kg/s\n",
              F.mean, F.error, flux.size(), block, crossings, D.mean, D.error, d.mean, d.error, nominal);
  EXPECT_GE(flux.size(), 6u);
  EXPECT_LT(std::abs(d.mean), 3.0 * d.error) << "flux != density x speed";
  EXPECT_LT(std::abs(F.mean - nominal), 3.0 * F.error) << "flux != the source's areal mass x speed";
  EXPECT_LT(F.error, 0.05 * nominal) << "the check is too weak to mean anything";

  // The report's summary (what a study tabulates): the supplied developer per sleeve area in its
  // flux and its areal form, both the source's Γ within 3 of their own standard errors; a fixed
  // supply declines nothing, so that key is absent.
  std::map<std::string, SummaryValue> summary;
  for (const SummaryValue &k : report.summary())
    summary[k.key] = k;
  ASSERT_EQ(summary.count("supplied_flux_kg_per_m2"), 1u);
  ASSERT_EQ(summary.count("supplied_areal_mass_kg_per_m2"), 1u);
  EXPECT_EQ(summary.count("inflow_declined_fraction"), 0u);
  for (const char *key : {"supplied_flux_kg_per_m2", "supplied_areal_mass_kg_per_m2"})
  {
    const SummaryValue &k = summary[key];
    std::printf("summary %s = %.5g +- %.2g kg/m^2 (source %.5g)\n", key, k.value, k.standard_error, areal_mass);
    EXPECT_LT(std::abs(k.value - areal_mass), 3.0 * k.standard_error) << key;
    EXPECT_LT(k.standard_error, 0.05 * areal_mass) << key << ": too weak to mean anything";
  }
}

TEST(DemParticleFlow, MassBudgetCloses)
{
  omp_set_num_threads(1);
  const Case c = conveyor_case(2e-3);
  auto sys = make_conveyor(c);
  FlowReport report(c);
  run_sampled(*sys, report, 20e-3);
  const auto &rows = report.rows();
  const FlowReportRow &first = rows.front(), &last = rows.back();
  long worst_count = 0;
  double worst_mass = 0.0, worst_due = 0.0;
  const double bead_max = 2200 * M_PI / 6.0 * std::pow(130e-6, 3); // d_mean + 3σ
  for (const auto &r : rows)
  {
    worst_count = std::max(worst_count, std::labs((r.in - r.out) - (r.present - first.present + first.in - first.out)));
    worst_mass = std::max(worst_mass, std::abs((r.in_mass - r.out_mass) - (r.present_mass - first.present_mass +
                                                                            first.in_mass - first.out_mass)));
    worst_due = std::max(worst_due, std::abs(r.due_mass - r.in_mass));
  }
  std::printf("budget over %zu samples: in %ld (%.5g kg), out %ld (%.5g kg), present %ld (%.5g kg); worst |in - out - "
              "(present - present0)| = %ld beads, %.3g kg; worst |due - created| = %.3g kg (one bead <= %.3g kg)\n",
              rows.size(), last.in, last.in_mass, last.out, last.out_mass, last.present, last.present_mass, worst_count,
              worst_mass, worst_due, bead_max);
  EXPECT_GT(last.in, 300);
  EXPECT_GT(last.out, 100);
  EXPECT_EQ(worst_count, 0);
  EXPECT_LT(worst_mass, 1e-9 * last.in_mass);
  EXPECT_LE(worst_due, bead_max);
  // The engine's own counts agree with the source's and the sink's.
  EXPECT_EQ(sys->particles_entered(), last.in);
  EXPECT_EQ(sys->particles_left(), last.out);
}

TEST(DemParticleFlow, OneAndTwoThreadsGiveIdenticalBits)
{
  // A wide slab (above 512 beads, so that two threads share the work), softer beads and a
  // weaker pull (a longer time step): 6 ms of feeding.
  const Case c = conveyor_case(12e-3, 1e6);
  std::vector<double> result[2];
  std::size_t present = 0;
  for (int threads : {1, 2})
  {
    omp_set_num_threads(threads);
    auto sys = make_conveyor(c, 100.0);
    sys->advance(std::lround(6e-3 / sys->time_step()));
    result[threads - 1] = state_by_id(*sys);
    present = sys->particles().size();
  }
  omp_set_num_threads(2);
  std::printf("1 vs 2 threads with inflow and outflow: %zu beads present at the end\n", present);
  EXPECT_GT(present, 520u);
  EXPECT_TRUE(bit_identical(result[0], result[1]));
}

TEST(DemParticleFlow, RestartInTheMiddleContinuesBitIdentically)
{
  omp_set_num_threads(1);
  const Case c = conveyor_case(2e-3, 1e6);
  const std::string path = (magbrush::testing::test_temp_dir("dem_flow_restart") / "restart.bin").string();
  auto a = make_conveyor(c, 100.0);
  const long half = std::lround(9.3e-3 / a->time_step()), rest = std::lround(6e-3 / a->time_step());
  a->advance(half);
  a->write_checkpoint(path);
  a->advance(rest);

  DemSystem b(c);
  b.add_force_term(std::make_unique<RadialPull>(100.0));
  b.set_particle_exchange(std::make_unique<ParticleFlow>(c, b));
  b.read_checkpoint(path);
  b.advance(rest);
  const auto *fa = static_cast<const ParticleFlow *>(a->particle_exchange());
  const auto *fb = static_cast<const ParticleFlow *>(b.particle_exchange());
  EXPECT_GT(a->particles_left(), 50);
  EXPECT_EQ(fa->source()->created_count(), fb->source()->created_count());
  EXPECT_EQ(fa->sink()->removed_count(), fb->sink()->removed_count());
  EXPECT_TRUE(bit_identical(state_by_id(*a), state_by_id(b)));
  std::filesystem::remove(path);
}

TEST(DemParticleFlow, InflowThatCannotBeHeldIsRefusedNamingTheKey)
{
  auto refusal = [](Case c) -> std::string {
    try
    {
      DemSystem sys(c);
      ParticleFlow flow(c, sys);
    }
    catch (const std::invalid_argument &e)
    {
      return e.what();
    }
    return "";
  };
  Case thin = conveyor_case(2e-3);
  thin.flow.inflow_layer_height = 0.12e-3; // 0.05 kg/m² of 100 um beads in 20 um of free height
  EXPECT_NE(refusal(thin).find("inflow.layer_height"), std::string::npos) << refusal(thin);
  Case unnamed = conveyor_case(2e-3);
  unnamed.flow.inflow_population = "developer";
  EXPECT_NE(refusal(unnamed).find("inflow.population"), std::string::npos) << refusal(unnamed);
  Case no_slab = conveyor_case(0.0);
  EXPECT_NE(refusal(no_slab).find("dem.periodic_length"), std::string::npos) << refusal(no_slab);
  EXPECT_EQ(refusal(conveyor_case(2e-3)), "");
}

// A pocket on the sleeve: walls across it 2° before the entry and 8° past it, 20 µm off it
// (beads of 100 µm cannot pass): the layer piles up in it until the entry arc is full. A fixed supply stops the run with a
// message naming the cause; a sump (inflow.supply: sump) leaves what finds no room in the
// sump, and the mass it created plus the mass it declined is the mass offered.
TEST(DemParticleFlow, ASumpLeavesWhatFindsNoRoomAndAFixedSupplyStops)
{
  omp_set_num_threads(2);
  auto blocked = [](const std::string &supply) {
    Case c = conveyor_case(0.5e-3);
    c.flow.inflow_supply = supply;
    c.flow.outflow_width = 0.0; // nothing leaves
    c.flow.inflow_areal_mass = 0.3;
    c.flow.inflow_layer_height = 1e-3;
    for (const double a0 : {84 * deg, 98 * deg})
    {
      BladeOrGuide block;
      block.name = a0 < 90 * deg ? "back" : "front";
      block.material = "sleeve";
      const double a1 = a0 + 4 * deg, r0 = sleeve_radius + 20e-6, r1 = sleeve_radius + 2.5e-3;
      block.polygon = {{r0 * std::cos(a0), r0 * std::sin(a0)}, {r0 * std::cos(a1), r0 * std::sin(a1)},
                       {r1 * std::cos(a1), r1 * std::sin(a1)}, {r1 * std::cos(a0), r1 * std::sin(a0)}};
      c.blades.push_back(block);
    }
    return c;
  };
  const double end = 0.012; // the sleeve offers ~300 beads; the pocket's entry arc is full with ~100
  {
    Case c = blocked("sump");
    c.flow.average_from = 8e-3; // the pocket is full: (nearly) all that is offered is declined
    auto sys = make_conveyor(c);
    FlowReport report(c);
    run_sampled(*sys, report, end);
    const auto *flow = dynamic_cast<const ParticleFlow *>(sys->particle_exchange());
    ASSERT_NE(flow, nullptr);
    const ParticleSource &in = *flow->source();
    double created = 0.0;
    for (double m : in.created_mass())
      created += m;
    const double one_bead = 2200.0 * M_PI / 6.0 * std::pow(130e-6, 3); // the largest drawn (3 sigma)
    std::printf("sump: offered %.4g kg, created %.4g kg, declined %.4g kg, %zu beads present\n", in.mass_due(end),
                created, in.declined_mass(), sys->particles().size());
    EXPECT_GT(in.declined_mass(), 0.25 * in.mass_due(end)) << "the full pocket should turn much of the offer away";
    EXPECT_NEAR(created + in.declined_mass(), in.mass_due(end), one_bead);
    EXPECT_EQ(report.rows().back().declined_mass, in.declined_mass());
    double declined_fraction = std::nan("");
    for (const SummaryValue &k : report.summary())
      if (k.key == "inflow_declined_fraction")
        declined_fraction = k.value;
    std::printf("declined over 8-12 ms: %.4f of the offer\n", declined_fraction);
    EXPECT_GT(declined_fraction, 0.8);
    EXPECT_LE(declined_fraction, 1.0 + 1e-12);
  }
  {
    const Case c = blocked("fixed");
    auto sys = make_conveyor(c);
    std::string message;
    try
    {
      sys->advance(std::lround(end / sys->time_step()));
    }
    catch (const std::runtime_error &e)
    {
      message = e.what();
    }
    EXPECT_NE(message.find("does not fit into the entry arc"), std::string::npos) << message;
  }
}

// inflow.prefill_arc: the sleeve starts carrying the layer over 40° past the entry (90° … 130°),
// Γ per sleeve area to within one bead, within the layer height, moving with the sleeve; those
// beads are the initial state (nothing "entered"), and the first of them reach the outflow at
// 150° after the 20° of the gap, where a bare sleeve's first beads need the whole 60°.
TEST(DemParticleFlow, APrefilledArcCarriesTheLayerFromTheStart)
{
  omp_set_num_threads(2);
  const double slab = 2e-3, arc = 40 * deg;
  Case c = conveyor_case(slab);
  c.flow.inflow_prefill_arc = arc;
  auto sys = std::make_unique<DemSystem>(c);
  sys->add_force_term(std::make_unique<RadialPull>(1000.0));
  sys->set_particle_exchange(std::make_unique<ParticleFlow>(c, *sys));
  sys->insert_particles();
  sys->initialize();
  const ParticleState &p = sys->particles();
  const auto *flow = dynamic_cast<const ParticleFlow *>(sys->particle_exchange());
  double mass = 0.0, worst_speed = 0.0;
  int outside = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    mass += p.mass[i];
    const double r = std::hypot(p.x[i], p.y[i]), th = std::atan2(p.y[i], p.x[i]);
    if (th < 90 * deg || th > 130 * deg || r - p.radius[i] < sleeve_radius - 1e-12 ||
        r + p.radius[i] > sleeve_radius + c.flow.inflow_layer_height + 1e-12)
      ++outside;
    worst_speed = std::max(worst_speed, std::hypot(p.vx[i] + omega * p.y[i], p.vy[i] - omega * p.x[i]));
  }
  const double due = areal_mass * sleeve_radius * arc * slab;
  const double bead_max = 2200 * M_PI / 6.0 * std::pow(130e-6, 3);
  std::printf("prefilled %zu beads, %.5g kg against Γ R Δφ L_z = %.5g kg\n", p.size(), mass, due);
  EXPECT_GT(p.size(), 100u);
  EXPECT_NEAR(mass, due, bead_max);
  EXPECT_EQ(outside, 0);
  EXPECT_LT(worst_speed, 1e-12);
  EXPECT_EQ(flow->source()->prefilled_count(), static_cast<long>(p.size()));
  EXPECT_DOUBLE_EQ(flow->source()->prefilled_mass(), mass);
  // 5 ms later (the sleeve turns 29°): the prefilled beads of the last ~9° have crossed into the
  // outflow; a bare sleeve's first beads (60° upstream of it) are still on their way.
  sys->advance(std::lround(5e-3 / sys->time_step()));
  auto bare = make_conveyor(conveyor_case(slab));
  bare->advance(std::lround(5e-3 / bare->time_step()));
  std::printf("after 5 ms: %ld prefilled beads left through the outflow, %ld of the bare sleeve's\n",
              sys->particles_left(), bare->particles_left());
  EXPECT_GT(sys->particles_left(), 15);
  EXPECT_EQ(bare->particles_left(), 0);
  // The run's inflow is its own: what it created follows Γ R φ(t) L_z, the prefill apart.
  EXPECT_EQ(flow->source()->created_count()[0], sys->particles_entered());
  EXPECT_NEAR(flow->source()->created_mass()[0], flow->source()->mass_due(sys->time()), bead_max);
}

// A layer that has no room (the arc already packed with beads) is refused naming the key.
TEST(DemParticleFlow, APrefillWithNoRoomIsRefusedNamingTheKey)
{
  Case c = conveyor_case(1e-3);
  c.flow.inflow_prefill_arc = 20 * deg;
  DemSystem sys(c);
  ParticleSource source(c, sys.walls(), sys.box());
  // A cubic lattice of 100 µm beads at 95 µm spacing (its holes smaller than the smallest bead
  // the source draws) filling the layer from 92° to 112°.
  ParticleState packed;
  for (double r = sleeve_radius + 50e-6; r < sleeve_radius + 0.3e-3; r += 95e-6)
    for (double th = 92 * deg; th < 112 * deg; th += 95e-6 / r)
      for (double z = 0.0; z < 1e-3 - 1e-9; z += 1e-3 / 10)
        packed.add({r * std::cos(th), r * std::sin(th), z}, 50e-6, 2200, 0, 0.0);
  ParticleState add;
  try
  {
    source.prefill(packed, add);
    FAIL() << "a prefill into a packed arc was accepted";
  }
  catch (const std::invalid_argument &e)
  {
    std::printf("%s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("inflow.prefill_arc"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("deg"), std::string::npos);
  }
}

// inflow.prefill_where_no_room: thin. A roof of beads from 130 µm above the sleeve, 100° to 125°
// (a cubic lattice whose holes no drawn bead passes), leaves room for about one layer of beads
// under it; the layer of 0.12 kg/m² (27 % solid in the 0.2 mm its centres may use) does not fit
// there. Thinned: the first piece (90° to 97°, before the roof) carries the whole layer, the arc
// under the roof what fits, the arc after it no more than what passed (the layer squeezed
// through a gap), and the layer's mass is placed, thinned or withheld, to within a bead.
// Refused by default (the test above).
TEST(DemParticleFlow, APrefillThinnedWhereItFindsNoRoomCarriesOnWhatPassed)
{
  const double slab = 1e-3, arc = 50 * deg, gamma = 0.12;
  Case c = conveyor_case(slab);
  c.flow.inflow_areal_mass = gamma;
  c.flow.inflow_prefill_arc = arc;
  c.flow.inflow_prefill_no_room = "thin";
  DemSystem sys(c);
  ParticleSource source(c, sys.walls(), sys.box());
  ParticleState roof;
  const double r_roof = sleeve_radius + 180e-6;
  for (double th = 100 * deg; th < 125 * deg; th += 95e-6 / r_roof)
    for (double z = 0.0; z < slab - 1e-9; z += slab / 10)
      roof.add({r_roof * std::cos(th), r_roof * std::sin(th), z}, 50e-6, 2200, 0, 0.0);
  ParticleState add;
  ASSERT_NO_THROW(source.prefill(roof, add));
  // Mass per degree of the layer placed before, under and after the roof.
  auto mass_between = [&](double a, double b) {
    double m = 0.0;
    for (std::size_t i = 0; i < add.size(); ++i)
    {
      const double th = std::atan2(add.y[i], add.x[i]);
      if (th >= a * deg && th < b * deg)
        m += add.mass[i];
    }
    return m / (b - a);
  };
  const double layer = gamma * sleeve_radius * deg * slab; // per degree
  const double before = mass_between(90, 97), under = mass_between(105, 124), after = mass_between(127, 140);
  const double bead_max = 2200 * M_PI / 6.0 * std::pow(130e-6, 3);
  std::printf("per degree, of the layer's %.4g kg: %.4g before the roof, %.4g under it, %.4g after it; passed "
              "%.3f at %.1f deg; thinned %.4g kg\n",
              layer, before, under, after, source.prefill_passed_fraction(),
              source.prefill_narrowest_angle() / deg, source.prefill_thinned_mass());
  EXPECT_NEAR(before, layer, 0.1 * layer);
  EXPECT_LT(under, 0.8 * layer);
  EXPECT_GT(under, 0.2 * layer);
  EXPECT_LE(after, under * 1.1);
  EXPECT_GT(after, 0.1 * layer);
  EXPECT_LT(source.prefill_passed_fraction(), 0.8);
  EXPECT_GE(source.prefill_narrowest_angle(), 100 * deg);
  EXPECT_LE(source.prefill_narrowest_angle(), 125 * deg);
  EXPECT_EQ(source.prefilled_count(), static_cast<long>(add.size()));
  // The layer's mass over the whole arc is placed, thinned (no room) or withheld (not given to
  // the pieces past the narrowest place), to within the last piece's remainder (a bead).
  double placed = 0.0;
  for (std::size_t i = 0; i < add.size(); ++i)
    placed += add.mass[i];
  EXPECT_DOUBLE_EQ(source.prefilled_mass(), placed);
  EXPECT_GT(source.prefill_thinned_mass(), 0.0);
  EXPECT_GT(source.prefill_withheld_mass(), 0.0);
  EXPECT_NEAR(placed + source.prefill_thinned_mass() + source.prefill_withheld_mass(),
              gamma * sleeve_radius * arc * slab, bead_max);
}

// A finite, closed sump (inflow.sump_mass): it holds ~100 beads' worth at the start; the sleeve
// draws ~17 beads per ms, so it runs dry after ~6 ms; what the outflow removes (from ~10 ms on,
// when the first beads arrive there) returns to it and is fed again. At every row of the flow
// report the mass in the scene plus the mass in the sump is the initial total, and a restart
// in the middle continues bit for bit with the sump's stock.
TEST(DemParticleFlow, AFiniteSumpRunsDryGetsBackWhatLeavesAndConservesMass)
{
  omp_set_num_threads(1);
  const double slab = 2e-3, one_bead = 2200.0 * M_PI / 6.0 * std::pow(130e-6, 3);
  Case c = conveyor_case(slab);
  c.flow.inflow_supply = "sump";
  c.flow.inflow_sump_mass = 100 * 2200.0 * M_PI / 6.0 * std::pow(100e-6, 3) / slab;
  auto sys = make_conveyor(c);
  FlowReport report(c);
  run_sampled(*sys, report, 20e-3);
  const auto &rows = report.rows();
  const auto *flow = dynamic_cast<const ParticleFlow *>(sys->particle_exchange());
  ASSERT_TRUE(flow->source()->finite_sump());
  const double total = c.flow.inflow_sump_mass * slab; // nothing in the scene at the start
  double worst = 0.0, least_stock = total;
  long in_when_dry = -1;
  for (const auto &r : rows)
  {
    worst = std::max(worst, std::abs(r.present_mass + r.sump_mass - total));
    least_stock = std::min(least_stock, r.sump_mass);
    if (in_when_dry < 0 && r.sump_mass < one_bead)
      in_when_dry = r.in;
  }
  std::printf("finite sump of %.4g kg: least stock %.3g kg, %ld created when it ran dry, %ld in the end (%ld "
              "out); worst |scene + sump - total| = %.3g kg\n",
              total, least_stock, in_when_dry, rows.back().in, rows.back().out, worst);
  EXPECT_LT(worst, 1e-12 * total);
  EXPECT_LT(least_stock, one_bead);                // it ran dry ...
  EXPECT_GT(rows.back().out, 20);                  // ... got beads back ...
  EXPECT_GT(rows.back().in, in_when_dry + 10);     // ... and fed them again
  EXPECT_LE(rows.back().in_mass, total + rows.back().out_mass + 1e-12 * total); // never more than it held

  // Restart at 8 ms (dry, before the first return) and at 13 ms (feeding what came back).
  for (const double at : {8e-3, 13e-3})
  {
    const std::string path = (magbrush::testing::test_temp_dir("dem_flow_sump") / "restart.bin").string();
    auto a = make_conveyor(c);
    const long first = std::lround(at / a->time_step()), rest = std::lround(4e-3 / a->time_step());
    a->advance(first);
    a->write_checkpoint(path);
    a->advance(rest);
    DemSystem b(c);
    b.add_force_term(std::make_unique<RadialPull>(1000.0));
    b.set_particle_exchange(std::make_unique<ParticleFlow>(c, b));
    b.read_checkpoint(path);
    b.advance(rest);
    const auto *fa = static_cast<const ParticleFlow *>(a->particle_exchange());
    const auto *fb = static_cast<const ParticleFlow *>(b.particle_exchange());
    EXPECT_EQ(fa->source()->sump_stock(), fb->source()->sump_stock());
    EXPECT_TRUE(bit_identical(state_by_id(*a), state_by_id(b)));
    std::filesystem::remove(path);
  }
}
