// The toner-development measurement against values computed independently here: toner placed
// by hand on the drum surface at known drum-frame positions on exposed and dark strips (TMA and
// fog from masses and strip areas integrated numerically), the neutralisation ratio and the
// bound from their definitions, the image moving with the drum, and a toner arriving on the
// drum between two samples (transfer rate and where).
#include "dem/measurements/toner_development.h"

#include "dem/dem_system.h"
#include "dem/run_summary.h"

#include "common/state_stream.h"
#include "case/case_parser.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

using namespace magbrush;
using namespace magbrush::dem;

namespace {

constexpr double eps0 = 8.8541878128e-12;

Case development_case()
{
  Case c;
  c.name = "development_test";
  c.source_file = "(test)";
  Sleeve s;
  s.radius = 10e-3;
  s.rpm = 400.0;
  c.sleeve = s;
  c.drum.present = true;
  c.drum.radius = 15e-3;
  c.drum.rpm = -170.0;
  c.drum.gap = 0.35e-3;
  c.drum.angle = 0.3;
  c.drum.pc_thickness = 20e-6;
  c.drum.pc_eps_r = 3.0;
  c.dem.periodic_length = 0.2e-3;
  c.electric.enabled = true;
  c.electric.bias = -650.0;
  c.electric.image.kind = LatentImage::Kind::surface_potential;
  c.electric.image.light_value = 0.0;
  c.electric.image.dark_value = -800.0;
  c.electric.image.period = 2e-3;
  c.electric.image.duty = 0.5;
  Population carrier;
  carrier.name = "carrier";
  carrier.kind = ParticleKind::carrier;
  Population toner;
  toner.name = "toner";
  toner.kind = ParticleKind::toner;
  toner.charge_to_mass = -0.03;
  c.populations = {carrier, toner};
  return c;
}

// The drum surface point at drum-frame arc s (counter-clockwise about the drum centre from the
// nip point) at time t: the image has turned by ω R t since t = 0.
std::pair<double, double> on_drum(const NipFrame &f, double s, double t)
{
  const double nip = std::atan2(f.sy - f.cy, f.sx - f.cx);
  const double angle = nip + (s + f.drum_omega * f.drum_radius * t) / f.drum_radius;
  return {f.cx + f.drum_radius * std::cos(angle), f.cy + f.drum_radius * std::sin(angle)};
}

// Exposed length of [a, b] by brute force (the pattern of latent_image_value); each strip edge
// inside the interval costs at most one sampling step (b − a)/2e6 of error.
double exposed_by_sampling(double a, double b, double period, double duty)
{
  const int n = 2000000;
  double len = 0.0;
  for (int k = 0; k < n; ++k)
  {
    const double s = a + (k + 0.5) * (b - a) / n;
    const double u = s / period + 0.5 * duty;
    len += (u - std::floor(u) < duty) ? (b - a) / n : 0.0;
  }
  return len;
}

} // namespace

TEST(DrumImage, StripsAreThoseOfTheFieldStageAndMoveWithTheDrum)
{
  const Case c = development_case();
  const NipFrame f = NipFrame::from_case(c);
  const DrumImage image(c.electric.image, f);
  // An exposed strip centred on the nip at t = 0: exposed for |s| < 0.5 mm, dark for 0.5–1.5 mm.
  EXPECT_TRUE(image.exposed(0.0));
  EXPECT_TRUE(image.exposed(0.49e-3));
  EXPECT_FALSE(image.exposed(0.51e-3));
  EXPECT_FALSE(image.exposed(-0.51e-3));
  EXPECT_TRUE(image.exposed(1.6e-3));
  // A point fixed on the drum surface keeps its drum-frame coordinate as the drum turns.
  for (double t : {0.0, 1e-4, 3.3e-3})
  {
    const auto [x, y] = on_drum(f, 0.7e-3, t);
    EXPECT_NEAR(image.drum_arc(x, y, t), 0.7e-3, 1e-12);
  }
  // Exposed lengths against brute-force sampling.
  for (auto [a, b] : {std::pair{0.0, 2e-3}, std::pair{-0.3e-3, 0.2e-3}, std::pair{0.4e-3, 5.3e-3}, std::pair{-7.1e-3, -1.2e-3}})
    EXPECT_NEAR(image.exposed_length(a, b), exposed_by_sampling(a, b, 2e-3, 0.5), 8.0 * (b - a) / 2e6) << a << " " << b;
}

TEST(TonerDevelopment, HandPlacedTonerGivesExactTmaFogChargeAndBound)
{
  const Case c = development_case();
  TonerDevelopment m(c);
  const NipFrame f = NipFrame::from_case(c);
  const DrumImage image(c.electric.image, f);
  const double t = 2.5e-3;
  // The window's ends on the drum surface, in the drum frame (independently: the nip coordinate
  // x of a drum surface point is R sin ψ, its arc R ψ downstream = −(counter-clockwise arc) here).
  auto arc_of_x = [&](double x) {
    const double psi = std::asin(x / f.drum_radius);
    // downstream is clockwise about the drum centre for a counter-clockwise sleeve
    const double ccw = (f.tx * (f.ny) - f.ty * (f.nx)) > 0 ? 1.0 : -1.0;
    return ccw * f.drum_radius * psi - f.drum_omega * f.drum_radius * t;
  };
  const double s1 = arc_of_x(1e-3), s2 = arc_of_x(4e-3);
  const double a = std::min(s1, s2), b = std::max(s1, s2);
  const double depth = c.dem.periodic_length;
  const double image_area = exposed_by_sampling(a, b, 2e-3, 0.5) * depth;
  const double dark_area = (b - a) * depth - image_area;
  // Toner at drum-frame positions inside the window: find exposed and dark spots by sampling.
  std::vector<DrumToner> toner;
  double m_img = 0, q_img = 0, m_dark = 0;
  int id = 0;
  for (double s = a + 0.05e-3; s < b; s += 0.173e-3)
  {
    const auto [x, y] = on_drum(f, s, t);
    const double mass = 2e-13 * (1 + 0.1 * id), charge = -0.03 * mass * (1 + 0.05 * (id % 3));
    toner.push_back({id++, x, y, mass, charge});
    const double u = s / 2e-3 + 0.25;
    if (u - std::floor(u) < 0.5)
      m_img += mass, q_img += charge;
    else
      m_dark += mass;
  }
  // One toner before the window (on the drum but still in the nip): not counted.
  const auto [xn, yn] = on_drum(f, 0.0 - f.drum_omega * f.drum_radius * 0.0, t);
  toner.push_back({id++, xn, yn, 1e-12, -3e-14});
  m.add_sample(t, toner);
  ASSERT_GT(m_img, 0.0);
  ASSERT_GT(m_dark, 0.0);
  EXPECT_NEAR(m.tma().mean(), m_img / image_area, 1e-5 * m_img / image_area); // sampling of the area
  EXPECT_NEAR(m.fog().mean(), m_dark / dark_area, 1e-5 * m_dark / dark_area);
  const double contrast = 650.0; // |−650 V − 0 V|
  EXPECT_DOUBLE_EQ(m.contrast_potential(), contrast);
  const double sigma_limit = eps0 * 3.0 * contrast / 20e-6;
  EXPECT_NEAR(m.neutralisation().mean(), std::abs(q_img / image_area) / sigma_limit, 1e-5 * std::abs(q_img / image_area) / sigma_limit);
  EXPECT_NEAR(m.tma_bound(), sigma_limit / 0.03, 1e-9 * sigma_limit / 0.03);
}

namespace {

// Three samples 5 µs apart: toner 1 on the drum at x = 0.2 mm throughout; toner 2 arrives at
// x ≈ −0.5 mm (in the nip, upstream of the centre) by the second and has left by the third.
void arrive_and_leave(TonerDevelopment &m, const Case &c)
{
  const NipFrame f = NipFrame::from_case(c);
  auto at_x = [&](double x) {
    const double psi = std::asin(x / f.drum_radius);
    return std::pair{f.cx + f.drum_radius * (-f.nx * std::cos(psi) + f.tx * std::sin(psi)),
                     f.cy + f.drum_radius * (-f.ny * std::cos(psi) + f.ty * std::sin(psi))};
  };
  const auto [x1, y1] = at_x(0.2e-3);
  const auto [x2, y2] = at_x(-0.5e-3);
  m.add_sample(0.0, {{1, x1, y1, 3e-13, -1e-14}});
  m.add_sample(5e-6, {{2, x2, y2, 4e-13, -1.2e-14}, {1, x1, y1, 3e-13, -1e-14}});
  m.add_sample(10e-6, {{1, x1, y1, 3e-13, -1e-14}});
}

} // namespace

TEST(TonerDevelopment, ArrivalsAreCountedWhereAndWhenTheyHappen)
{
  const Case c = development_case();
  TonerDevelopment m(c);
  arrive_and_leave(m, c);
  const std::string profile = m.transfer_profile_csv();
  // Over the 10 µs span and a 0.2 mm depth, in the 0.25 mm bin at −0.5 mm: 4e-13 kg arrived
  // and left.
  const double per = 1.0 / (10e-6 * 0.2e-3 * 0.25e-3);
  char expected[128];
  std::snprintf(expected, sizeof expected, "-0.5,%.6g,%.6g\n", 4e-13 * per, 4e-13 * per);
  EXPECT_NE(profile.find(expected), std::string::npos) << profile;
  const auto summary = m.summary();
  const auto rate = std::find_if(summary.begin(), summary.end(),
                                 [](const SummaryValue &v) { return v.key == "toner_transfer_rate_kg_per_s_m"; });
  ASSERT_NE(rate, summary.end());
  // Two intervals: 4e-13 kg in the first, nothing in the second.
  EXPECT_NEAR(rate->value, 0.5 * 4e-13 / (5e-6 * 0.2e-3), 1e-9 * 4e-13 / (5e-6 * 0.2e-3));
  std::vector<std::unique_ptr<Measurement>> all;
  all.push_back(std::make_unique<TonerDevelopment>(m));
  const std::string csv = run_summary_csv(all, c.statistics);
  for (const char *key : {"tma_kg_per_m2,", "tma_kg_per_m2_bound,", "fog_kg_per_m2,", "developed_q_over_m_C_per_kg,",
                          "neutralisation_ratio,", "toner_transfer_rate_kg_per_s_m,", "steady_state,"})
    EXPECT_NE(csv.find(key), std::string::npos) << key;
}

TEST(TonerDevelopment, SamplesBeforeTheAveragingWindowAreRowsButNotMeans)
{
  // The same three samples as above, with the averaging window opening at the second: all three
  // are rows of the file (the approach to the steady state), the means and the transfer profile
  // take only what lies inside the window, i.e. the interval from the second to the third sample.
  Case c = development_case();
  c.development.average_from = 5e-6;
  TonerDevelopment m(c);
  arrive_and_leave(m, c);
  const std::string csv = m.csv();
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 2 + 3) << csv; // comment, header, three rows
  EXPECT_NE(csv.find("\n0,"), std::string::npos) << csv;            // the sample before the window
  // The arrival happened before the window (between 0 and 5 us): the window's one interval saw
  // nothing arrive, so the rate's mean is 0 and the profile is empty over the 5 us span.
  const auto summary = m.summary();
  const auto rate = std::find_if(summary.begin(), summary.end(),
                                 [](const SummaryValue &v) { return v.key == "toner_transfer_rate_kg_per_s_m"; });
  ASSERT_NE(rate, summary.end());
  EXPECT_EQ(rate->value, 0.0);
  EXPECT_EQ(m.tma().size(), 2u);
  const std::string profile = m.transfer_profile_csv();
  const double per = 1.0 / (5e-6 * 0.2e-3 * 0.25e-3);
  char left[128];
  std::snprintf(left, sizeof left, "-0.5,0,%.6g\n", 4e-13 * per); // it left inside the window
  EXPECT_NE(profile.find(left), std::string::npos) << profile;
}

TEST(TonerDevelopment, AppliesToNipScenesWithTonerAndAField)
{
  Case c = development_case();
  EXPECT_TRUE(TonerDevelopment::applies(c));
  c.electric.enabled = false;
  EXPECT_FALSE(TonerDevelopment::applies(c));
  c = development_case();
  c.populations.pop_back();
  EXPECT_FALSE(TonerDevelopment::applies(c));
}

namespace {

// A periodic box (1 mm x 1 mm) of carrier and toner material with adhesion and no gravity,
// where a test places its particles by hand.
Case box_of_carriers_and_toner()
{
  return parse_case_text(R"(
name: retention
scene: box
materials:
  carrier: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 2200 kg/m^3, friction: 0.45, damping: 0.6, hamaker: 1e-19 J}
  toner: {youngs_modulus: 3e3 MPa, poisson_ratio: 0.35, density: 1100 kg/m^3, friction: 0.3, damping: 0.6, hamaker: 1e-19 J}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, hamaker: 0 J}
planes:
  - {name: floor, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
populations:
  - {name: carrier, kind: carrier, diameter: 35 um, count: 1, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 1 mm]]}
  - {name: toner, kind: toner, diameter: 7 um, count: 1, charge_to_mass: -30 uC/g, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 1 mm]]}
dem: {gravity: [0, 0, 0], periodic_length_x: 1 mm, periodic_length_y: 1 mm}
)",
                         "box.yaml");
}

} // namespace

// The developer's hold on its toner: the toner mass within the adhesion range of a carrier (or
// overlapping one) over all toner mass, from the neighbour list's pairs. Toner placed by hand
// around one carrier at known gaps: 1 nm (held: inside the 4 nm range), 10 nm (free), a 10 nm
// overlap (held), one touching only another toner, one far away, and one held across the
// periodic boundary (the pair's image shift counts).
TEST(TonerDevelopment, TonerOnCarriersIsTheMassWithinTheAdhesionRangeOfOne)
{
  const Case c = box_of_carriers_and_toner();
  DemSystem system(c);
  ParticleState &p = system.particles();
  const double rc = 17.5e-6, centre = 0.5e-3;
  p.add({centre, centre, centre}, rc, 2200.0, 0, 0.0);
  p.add({1e-6, centre, centre}, rc, 2200.0, 0, 0.0); // a carrier at the periodic boundary
  // A toner of radius rt at a surface gap from the carrier centred at (cx, centre, centre).
  auto toner_at = [&](double cx, double gap, double rt, double angle) {
    const double d = rc + rt + gap;
    p.add({cx + d * std::cos(angle), centre + d * std::sin(angle), centre}, rt, 1100.0, 1, -1e-15);
  };
  toner_at(centre, 1e-9, 3.0e-6, 0.0);       // held (1 nm)
  toner_at(centre, 10e-9, 3.5e-6, M_PI / 2); // free (10 nm > 4 nm)
  toner_at(centre, -10e-9, 4.0e-6, M_PI);    // held (overlapping)
  p.add({centre + 0.2e-3, centre, centre}, 3.2e-6, 1100.0, 1, -1e-15);          // free, far
  p.add({centre + 0.2e-3 + 6.4e-6, centre, centre}, 3.2e-6, 1100.0, 1, -1e-15); // on a toner only
  toner_at(1e-6, 2e-9, 3.7e-6, M_PI); // held through the boundary: x < 0 ...
  p.x.back() += 1e-3;                 // ... placed at the far side of the box
  system.initialize();
  auto mass = [](double r) { return 1100.0 * 4.0 / 3.0 * M_PI * r * r * r; };
  const double held = mass(3.0e-6) + mass(4.0e-6) + mass(3.7e-6);
  const double all = held + mass(3.5e-6) + 2 * mass(3.2e-6);
  ASSERT_GT(system.contact_table().adhesion_range(), 1e-9);
  std::vector<std::uint8_t> on;
  TonerDevelopment::mark_on_carriers(system, {0, 1}, {1, 0}, on);
  EXPECT_NEAR(TonerDevelopment::toner_share_on_carriers(system, {0, 1}, on), held / all, 1e-12);
  // Species flags the other way round: no toner, no share.
  TonerDevelopment::mark_on_carriers(system, {0, 0}, {1, 0}, on);
  EXPECT_TRUE(std::isnan(TonerDevelopment::toner_share_on_carriers(system, {0, 0}, on)));
}

TEST(TonerDevelopment, TheShareOnCarriersIsSampledIntoTheSummary)
{
  TonerDevelopment m(development_case());
  m.add_sample(1e-3, {}, 0.8);
  m.add_sample(2e-3, {}, 0.6);
  EXPECT_NEAR(m.on_carriers().mean(), 0.7, 1e-12);
  bool found = false;
  for (const auto &v : m.summary())
    if (v.key == "toner_on_carriers_fraction")
      found = std::abs(v.value - 0.7) < 1e-12;
  EXPECT_TRUE(found);
  EXPECT_NE(m.csv().find("toner_on_carriers_fraction"), std::string::npos);
}

// The drum's layer: toner resting on the toner that touches the drum counts, layer on layer, as
// long as no carrier holds it. Placed by hand in a box (the layer touching the drum given): B
// overlaps A (10 nm), C is 1 nm from B (inside the 4 nm adhesion range), D touches B but also a
// carrier (in the brush: not developed), E is 10 nm from A (free), F touches A across the
// periodic boundary.
TEST(TonerDevelopment, TheDrumsLayerIsTheTonerTouchingItAndTheTonerStackedOnThat)
{
  const Case c = box_of_carriers_and_toner();
  DemSystem system(c);
  ParticleState &p = system.particles();
  const double r = 3.5e-6, y = 0.5e-3, z = 0.5e-3;
  auto toner = [&](double x) { p.add({x, y, z}, r, 1100.0, 1, -1e-15); };
  const double xb = 0.3e-3 + 2 * r - 10e-9;
  toner(0.3e-3);                        // 0: A, touching the drum (given)
  toner(xb);                            // 1: B on A (10 nm overlap)
  toner(0.3e-3 + 4 * r - 10e-9 + 1e-9); // 2: C on B (1 nm gap)
  toner(xb);                            // 3: D, below B, touching it ...
  p.y.back() = y - 2 * r + 10e-9;
  p.add({xb, y - 2 * r + 10e-9 - r - 17.5e-6 + 5e-9, z}, 17.5e-6, 2200.0, 0, 0.0); // 4: ... and held by a carrier
  toner(0.3e-3 - 2 * r - 10e-9);        // 5: E, 10 nm from A
  toner(1e-3 - 1e-6);                   // 6: A2 at the far side, touching the drum (given)
  toner(1e-3 - 1e-6 + 2 * r - 10e-9 - 1e-3); // 7: F, on A2 across the boundary
  system.initialize();
  ASSERT_GT(system.contact_table().adhesion_range(), 1e-9);
  // The engine sorts its particles in space: they are found by their ids (the order added).
  std::vector<std::uint8_t> layer(p.size(), 0);
  for (std::size_t k = 0; k < p.size(); ++k)
    layer[k] = (p.id[k] == 0 || p.id[k] == 6) ? 1 : 0;
  std::vector<std::uint8_t> on_carrier;
  TonerDevelopment::mark_on_carriers(system, {0, 1}, {1, 0}, on_carrier);
  TonerDevelopment::stack_on_drum(system, {0, 1}, on_carrier, layer);
  // B on A, C on B, F on A2 through the boundary; D (held by a carrier) and E (free) are not.
  const std::vector<int> expected = {1, 2, 3, 0, 0, 0, 1, 2};
  for (std::size_t k = 0; k < p.size(); ++k)
    EXPECT_EQ(layer[k], expected[static_cast<std::size_t>(p.id[k])]) << "particle " << p.id[k];
}

// With development.average_over = image_periods the summary's TMA, fog, q/m and neutralisation
// ratio are those of whole periods of the drum's layer carried past measure_to. A layer of toner
// on the drum surface at the drum-frame lattice (k + ½) µm, 3e-13 kg on the exposed strips and
// 2e-14 kg on the dark ones, sampled every 20 µs for 2.2 periods as the drum turns: two whole
// periods, each with exactly the lattice's mass per area (test_developed_line.cpp), and a
// checkpoint half-way that continues to the same summary.
TEST(TonerDevelopment, OverImagePeriodsTheSummaryIsThatOfTheWholePeriodsPastTheLine)
{
  Case c = development_case();
  c.development.average_over = "image_periods";
  c.development.measure_from = 1.2e-3;
  c.development.measure_to = 2e-3;
  const NipFrame f = NipFrame::from_case(c);
  const DrumImage image(c.electric.image, f);
  const double spacing = 1e-6, m_image = 3e-13, m_dark = 2e-14, qm = -0.03;
  auto layer_at = [&](double t) {
    const double s_line = image.drum_arc_at_x(c.development.measure_to, t);
    std::vector<DrumToner> out;
    const long first = static_cast<long>(std::floor((s_line - 70e-6) / spacing));
    for (long k = first; k <= first + 140; ++k)
    {
      const double s = (static_cast<double>(k) + 0.5) * spacing;
      const double m = image.exposed(s) ? m_image : m_dark;
      const auto [x, y] = on_drum(f, s, t);
      out.push_back({static_cast<std::int32_t>(k + 1000000), x, y, m, qm * m});
    }
    return out;
  };
  const double period_time = 2e-3 / std::abs(f.drum_omega * f.drum_radius);
  TonerDevelopment whole(c), first(c);
  std::unique_ptr<TonerDevelopment> second;
  const double dt = 20e-6;
  const int samples = static_cast<int>(2.2 * period_time / dt);
  for (int n = 0; n <= samples; ++n)
  {
    const double t = n * dt;
    whole.add_sample(t, layer_at(t), 0.9);
    if (n <= samples / 2)
      first.add_sample(t, layer_at(t), 0.9);
    else
    {
      if (!second)
      {
        MemoryStateOut out;
        first.write_state(out);
        second = std::make_unique<TonerDevelopment>(c);
        MemoryStateIn in(out.bytes(), "test state");
        second->read_state(in);
        ASSERT_EQ(in.remaining(), 0u);
      }
      second->add_sample(t, layer_at(t), 0.9);
    }
  }
  const double depth = c.dem.periodic_length;
  const double tma = m_image / (spacing * depth), fog = m_dark / (spacing * depth);
  const double limit = eps0 * 3.0 * 650.0 / 20e-6;
  std::map<std::string, SummaryValue> s;
  for (const auto &v : whole.summary())
    s[v.key] = v;
  ASSERT_TRUE(s.count("image_periods_averaged"));
  EXPECT_EQ(s["image_periods_averaged"].value, 2.0);
  EXPECT_NEAR(s["tma_kg_per_m2"].value, tma, 1e-9 * tma);
  EXPECT_NEAR(s["tma_kg_per_m2"].standard_error, 0.0, 1e-9 * tma);
  EXPECT_NEAR(s["tma_kg_per_m2"].drift, 0.0, 1e-9);
  EXPECT_NEAR(s["fog_kg_per_m2"].value, fog, 1e-9 * fog);
  EXPECT_NEAR(s["developed_q_over_m_C_per_kg"].value, qm, 1e-12);
  EXPECT_NEAR(s["neutralisation_ratio"].value, std::abs(qm) * tma / limit, 1e-9 * std::abs(qm) * tma / limit);
  EXPECT_NEAR(s["tma_kg_per_m2_bound"].value, limit / 0.03, 1e-9 * limit / 0.03);
  // The fixed window's samples repeat with the image: their rows stay in the file, not in the summary.
  EXPECT_NE(whole.csv().find("stacked_toner"), std::string::npos);
  ASSERT_NE(whole.developed_line(), nullptr);
  EXPECT_EQ(second->developed_line()->periods_csv(), whole.developed_line()->periods_csv());
  std::map<std::string, double> resumed;
  for (const auto &v : second->summary())
    resumed[v.key] = v.value;
  EXPECT_EQ(resumed["tma_kg_per_m2"], s["tma_kg_per_m2"].value);
  EXPECT_EQ(resumed["toner_transfer_rate_kg_per_s_m"], s["toner_transfer_rate_kg_per_s_m"].value);
}

// On a solid area (a uniform image) the blocks lie on a grid fixed to the drum, so the lines at
// measure_from and measure_to count the same drum elements in blocks of the same index, and
// layer_change_past_measure_from compares them element by element. A layer on the drum's
// lattice (k + ½) µm with 3e-13 kg per toner as it passes measure_from and `gain` times that as
// it passes measure_to (as if the drum had collected toner in between): each line's TMA is its
// lattice's mass per area, and the change is exactly the difference, over every paired block.
TEST(TonerDevelopment, OnASolidAreaTheTwoLinesCompareTheSameDrumElements)
{
  for (double gain : {1.0, 1.5})
  {
    Case c = development_case();
    c.electric.image.period = 0.0;
    c.electric.image.duty = 1.0;
    c.development.average_over = "image_periods";
    c.development.block_length = 0.1e-3;
    c.development.measure_from = 1e-3;
    c.development.measure_to = 2e-3;
    const NipFrame f = NipFrame::from_case(c);
    const DrumImage image(c.electric.image, f);
    ASSERT_TRUE(image.solid());
    const double spacing = 1e-6, m = 3e-13, qm = -0.03;
    auto layer_at = [&](double t) {
      std::vector<DrumToner> out;
      for (const double x : {c.development.measure_from, c.development.measure_to})
      {
        const double s_line = image.drum_arc_at_x(x, t);
        const double mass = x == c.development.measure_to ? gain * m : m;
        const long first = static_cast<long>(std::floor((s_line - 70e-6) / spacing));
        for (long k = first; k <= first + 140; ++k)
        {
          const double s = (static_cast<double>(k) + 0.5) * spacing;
          const auto [px, py] = on_drum(f, s, t);
          out.push_back({static_cast<std::int32_t>(k + 1000000), px, py, mass, qm * mass});
        }
      }
      std::sort(out.begin(), out.end(), [](const DrumToner &a, const DrumToner &b) { return a.id < b.id; });
      return out;
    };
    const double speed = std::abs(f.drum_omega * f.drum_radius);
    const double dt = 10e-6, duration = (1e-3 + 0.65e-3) / speed;
    TonerDevelopment d(c);
    for (int n = 0; n * dt <= duration; ++n)
      d.add_sample(n * dt, layer_at(n * dt), 0.9);
    std::map<std::string, SummaryValue> s;
    for (const auto &v : d.summary())
      s[v.key] = v;
    const double tma = m / (spacing * c.dem.periodic_length);
    ASSERT_TRUE(s.count("layer_change_past_measure_from_kg_per_m2"));
    EXPECT_GE(s["image_periods_averaged"].value, 5.0);
    EXPECT_GE(s["image_periods_averaged_at_measure_from"].value, 14.0);
    EXPECT_NEAR(s["tma_at_measure_from_kg_per_m2"].value, tma, 1e-9 * tma) << gain;
    EXPECT_NEAR(s["tma_kg_per_m2"].value, gain * tma, 1e-9 * tma) << gain;
    EXPECT_NEAR(s["layer_change_past_measure_from_kg_per_m2"].value, (gain - 1.0) * tma, 1e-9 * tma) << gain;
    EXPECT_NEAR(s["layer_change_past_measure_from_kg_per_m2"].standard_error, 0.0, 1e-9 * tma) << gain;
    EXPECT_TRUE(std::isnan(s["fog_kg_per_m2"].value)); // no dark area on a solid one
  }
}
