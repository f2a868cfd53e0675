// The nip measurements against results computed independently here: hand-placed beads on the
// drum with known forces and velocities (exact bin values), hand-placed bead pairs with known
// branch directions (exact inclinations), beads moved across the nip window (exact counts),
// and one engine step with beads pressed on a turning drum (Hertz force, slip = −drum speed).
#include "dem/measurements/brush_height.h"
#include "dem/measurements/chain_inclination.h"
#include "dem/measurements/nip_frame.h"
#include "dem/measurements/nip_profile.h"
#include "dem/measurements/nip_time_series.h"

#include "dem/dem_system.h"
#include "dem/run_summary.h"

#include "case/case_parser.h"

#include "common/state_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace magbrush;
using namespace magbrush::dem;

namespace {

constexpr double pi = M_PI;

// Kawamoto's prototype nip, turned so that the drum sits at `drum_angle` (the frame must not
// assume the drum on +x).
Case nip_case(double drum_angle = 0.0)
{
  Case c;
  c.name = "nip_test";
  c.source_file = "(test)";
  Sleeve s;
  s.radius = 12.5e-3;
  s.rpm = 219.0;
  c.sleeve = s;
  c.drum.present = true;
  c.drum.radius = 50e-3;
  c.drum.rpm = -29.0;
  c.drum.gap = 0.4e-3;
  c.drum.angle = drum_angle;
  for (const char *name : {"carrier", "sleeve", "drum"})
  {
    Material m;
    m.name = name;
    m.youngs_modulus = std::string(name) == "carrier" ? 1e9 : 5e10;
    m.poisson_ratio = std::string(name) == "carrier" ? 0.35 : 0.3;
    m.density = 2200;
    m.friction = std::string(name) == "carrier" ? 0.45 : 0.35;
    m.damping = 0.6;
    c.materials.push_back(m);
  }
  Population p;
  p.name = "carrier";
  p.material = "carrier";
  p.diameter_mean = 60e-6;
  c.populations.push_back(p);
  c.dem.periodic_length = 1e-3;
  c.dem.gravity = {0, 0, 0};
  c.dem.air_viscosity = 0.0;
  c.nip.bin_width = 0.25e-3;
  c.nip.half_width = 2e-3;
  return c;
}

// A point at nip coordinate x on the drum surface, pushed `out` outward from it, in the frame.
Vector3 on_drum(const NipFrame &f, double x, double out, double z = 0.5e-3)
{
  const double psi = std::asin(x / f.drum_radius);
  // Drum surface point: C + Rd (−n cos ψ + t sin ψ).
  const double ux = -f.nx * std::cos(psi) + f.tx * std::sin(psi), uy = -f.ny * std::cos(psi) + f.ty * std::sin(psi);
  return {f.cx + (f.drum_radius + out) * ux, f.cy + (f.drum_radius + out) * uy, z};
}

// The summary row of `key` (a failure when there is none).
SummaryValue value(const std::vector<SummaryValue> &s, const std::string &key)
{
  for (const auto &v : s)
    if (v.key == key)
      return v;
  ADD_FAILURE() << "no " << key;
  return SummaryValue{};
}

} // namespace

TEST(NipFrame, RelativeSpeedAndCoordinatesOfThePrototype)
{
  for (double angle : {0.0, 0.7})
  {
    const NipFrame f = NipFrame::from_case(nip_case(angle));
    // π 25 mm 219 rpm/60 − π 100 mm 29 rpm/60 (both surfaces move the same way).
    const double expected = pi * 25e-3 * 219.0 / 60.0 - pi * 100e-3 * 29.0 / 60.0;
    EXPECT_NEAR(f.relative_surface_speed(), expected, 1e-12);
    EXPECT_NEAR(expected, 0.1349, 1e-4);
    // Gap centre at x = 0 and angles 0; a sleeve point at angle θ has x = Rs sin θ.
    const double h = f.sleeve_radius + 0.5 * f.gap;
    EXPECT_NEAR(f.x_along(h * f.nx, h * f.ny), 0.0, 1e-15);
    const double th = 0.1;
    const double px = f.sleeve_radius * (std::cos(th) * f.nx + std::sin(th) * f.tx);
    const double py = f.sleeve_radius * (std::cos(th) * f.ny + std::sin(th) * f.ty);
    EXPECT_NEAR(f.sleeve_angle(px, py), th, 1e-12);
    EXPECT_NEAR(f.x_along(px, py), f.sleeve_radius * std::sin(th), 1e-15);
    // Downstream is where the sleeve surface goes: ω ẑ × (Rs n) ∥ t.
    EXPECT_NEAR(-f.ny * f.tx + f.nx * f.ty, 1.0, 1e-15);
    const Vector3 q = on_drum(f, 1e-3, 0.0);
    EXPECT_NEAR(f.x_along(q.x, q.y), 1e-3, 1e-15);
    EXPECT_NEAR(f.drum_angle(q.x, q.y), std::asin(1e-3 / f.drum_radius), 1e-13);
  }
  Case no_drum = nip_case();
  no_drum.drum.present = false;
  EXPECT_FALSE(NipFrame::applies(no_drum));
  EXPECT_THROW(NipFrame::from_case(no_drum), std::invalid_argument);
}

// A run that ends before nip.average_from averages nothing: no peak pressure (not 0 Pa) and
// no averaging times (not -1 s) in nip_summary.csv, so that no report prints a mean of nothing.
TEST(NipProfile, NoSamplesGiveNoNumbers)
{
  const NipProfile profile(nip_case());
  ASSERT_EQ(profile.samples(), 0);
  EXPECT_TRUE(std::isnan(profile.peak_normal_pressure()));
  const std::string summary = profile.summary_csv();
  EXPECT_NE(summary.find("samples,0,"), std::string::npos) << summary;
  EXPECT_NE(summary.find("t_from,nan,"), std::string::npos) << summary;
  EXPECT_NE(summary.find("t_to,nan,"), std::string::npos) << summary;
  EXPECT_NE(summary.find("peak_normal_pressure,nan,"), std::string::npos) << summary;
}

TEST(NipProfile, HandPlacedBeadsGiveExactBinValues)
{
  const Case c = nip_case(0.4);
  NipProfile profile(c);
  const NipFrame &f = profile.frame();
  const double r = 30e-6, overlap = 0.2e-6, a = r - overlap; // lever arm centre → contact point
  // Independent drum surface speed at the gap centre and its direction (downstream).
  const double v_drum = -c.drum.omega() * c.drum.radius; // > 0: the drum moves downstream too
  // Bead A at the gap centre: moving downstream at 0.2 m/s and spinning at w about +z.
  // Its contact point moves at v + ω × (a n) (n: towards the drum) = v + w a (ẑ × n) = v + w a t.
  DrumContact A;
  A.position = on_drum(f, 0.0, r - overlap);
  A.velocity = {0.2 * f.tx, 0.2 * f.ty, 0.0};
  const double w = 1000.0;
  A.angular_velocity = {0.0, 0.0, w};
  A.radius = r;
  // Force on the drum: 2 mN into the drum (−n_out = +n at the centre), 0.7 mN downstream.
  A.force_on_wall = {2e-3 * f.nx + 0.7e-3 * f.tx, 2e-3 * f.ny + 0.7e-3 * f.ty, 0.0};
  // Bead B at x = +1 mm (bin 4), at rest, pressing 1 mN along its own drum normal.
  DrumContact B;
  B.position = on_drum(f, 1e-3, r - overlap);
  B.radius = r;
  const double psi = std::asin(1e-3 / f.drum_radius);
  const double nox = -f.nx * std::cos(psi) + f.tx * std::sin(psi), noy = -f.ny * std::cos(psi) + f.ty * std::sin(psi);
  B.force_on_wall = {-1e-3 * nox, -1e-3 * noy, 0.0};
  // Bead C outside the profile (x = 3 mm > half_width): ignored.
  DrumContact C = B;
  C.position = on_drum(f, 3e-3, r - overlap);

  profile.add_sample(1e-3, {A, B, C});
  profile.add_sample(2e-3, {A}); // second sample: only A
  ASSERT_EQ(profile.samples(), 2);
  const auto bins = profile.bins();
  ASSERT_EQ(bins.size(), 17u); // −2 mm … +2 mm in 0.25 mm
  const NipBin &b0 = bins[8], &b4 = bins[12];
  EXPECT_NEAR(b0.x, 0.0, 1e-18);
  EXPECT_NEAR(b4.x, 1e-3, 1e-15);
  const double Rd = c.drum.radius, Lz = c.dem.periodic_length;
  const double area0 = 2.0 * Rd * std::asin(0.125e-3 / Rd) * Lz;
  const double area4 = Rd * (std::asin(1.125e-3 / Rd) - std::asin(0.875e-3 / Rd)) * Lz;
  EXPECT_NEAR(b0.area / area0, 1.0, 1e-12);
  EXPECT_NEAR(b4.area / area4, 1.0, 1e-12);
  // A in both samples: mean force = its force; B in one of two: half of it.
  EXPECT_NEAR(b0.normal_pressure, 2e-3 / area0, 1e-9 * 2e-3 / area0);
  EXPECT_NEAR(b0.tangential_pressure, 0.7e-3 / area0, 1e-9 * 0.7e-3 / area0);
  EXPECT_NEAR(b4.normal_pressure, 0.5e-3 / area4, 1e-9 * 0.5e-3 / area4);
  EXPECT_NEAR(b4.tangential_pressure, 0.0, 1e-9 * 0.5e-3 / area4);
  EXPECT_NEAR(b0.touching, 1.0, 1e-15);
  EXPECT_NEAR(b4.touching, 0.5, 1e-15);
  EXPECT_NEAR(b0.density, 1.0 / area0, 1e-9 / area0);
  // Slip of A: 0.2 + w a − v_drum; of B: −(drum surface speed) at rest.
  EXPECT_NEAR(b0.slip, 0.2 + w * a - v_drum, 1e-12);
  EXPECT_NEAR(b0.slip_std, 0.0, 1e-7);
  EXPECT_NEAR(b4.slip, -v_drum, 1e-12);
  EXPECT_NEAR(profile.slip_at_gap_centre(), 0.2 + w * a - v_drum, 1e-12);
  // The chain speed leaves the spin out: A's centre moves 0.2 m/s, the drum v_drum under it.
  EXPECT_NEAR(b0.chain_speed, 0.2 - v_drum, 1e-12);
  EXPECT_NEAR(b4.chain_speed, -v_drum, 1e-12);
  EXPECT_NEAR(profile.chain_speed_at_gap_centre(), 0.2 - v_drum, 1e-12);
  // Σ F_t / Σ F_n over both samples: (2 × 0.7) / (2 × 2 + 1) mN.
  EXPECT_NEAR(profile.tangential_over_normal(), 1.4 / 5.0, 1e-12);
  EXPECT_NEAR(profile.peak_normal_pressure(), 2e-3 / area0, 1e-9 * 2e-3 / area0);
  // Empty bins have no slip (NaN), zero pressure.
  EXPECT_TRUE(std::isnan(bins[0].slip));
  EXPECT_EQ(bins[0].normal_pressure, 0.0);
  // Before nip.average_from nothing is accumulated by the engine path; the CSV has units.
  const std::string csv = profile.csv();
  EXPECT_NE(csv.find("x_mm,"), std::string::npos);
  EXPECT_NE(csv.find("normal_pressure_Pa"), std::string::npos);
  EXPECT_NE(profile.summary_csv().find("slip_at_gap_centre"), std::string::npos);
  EXPECT_NE(csv.find("chain_speed_m_s"), std::string::npos);
  EXPECT_NE(profile.summary_csv().find("chain_speed_at_gap_centre"), std::string::npos);
}

// Which contacts slide, from the slip of each contact point alone: beads at the gap centre
// (contact point moving with the drum there at v_drum along the downstream tangent t, no spin)
// pressing 1 mN each, with hand-chosen velocities relative to the drum.
TEST(NipProfile, SlidingSharesFromTheSlipOfEachContact)
{
  const Case c = nip_case(0.4);
  NipProfile profile(c);
  const NipFrame &f = profile.frame();
  const double v_drum = -c.drum.omega() * c.drum.radius; // the drum surface, downstream
  const double threshold = 0.1 * f.relative_surface_speed();
  EXPECT_NEAR(profile.sliding_speed(), threshold, 1e-15);
  const double r = 30e-6, overlap = 0.2e-6;
  const Vector3 t{f.tx, f.ty, 0.0}, z{0.0, 0.0, 1.0};
  auto bead = [&](const Vector3 &relative, double normal_mN) {
    DrumContact b;
    b.position = on_drum(f, 0.0, r - overlap);
    b.radius = r;
    b.velocity = v_drum * t + relative;
    b.force_on_wall = {normal_mN * 1e-3 * f.nx, normal_mN * 1e-3 * f.ny, 0.0}; // +n: into the drum
    return b;
  };
  // Downstream at 3 × the threshold; upstream at 2 ×; at 45° between downstream and the slab
  // depth (|slip| 2 × the threshold: the depth counts); creeping at half the threshold along
  // the depth (sticks); pressing twice as hard and creeping downstream (sticks).
  const double s = threshold;
  const std::vector<DrumContact> contacts{bead(3 * s * t, 1), bead(-2 * s * t, 1),
                                          bead(std::sqrt(2.0) * s * (t + z), 1), bead(0.5 * s * z, 1),
                                          bead(0.9 * s * t, 2)};
  profile.add_sample(1e-3, contacts);
  // Σ F_n = 6 mN; sliding: the first three (3 mN); downstream cosines 1, −1, 1/√2.
  EXPECT_NEAR(profile.sliding_share(), 3.0 / 6.0, 1e-12);
  EXPECT_NEAR(profile.sliding_downstream_share(), (1.0 - 1.0 + std::sqrt(0.5)) / 6.0, 1e-9);
  const std::string summary = profile.summary_csv();
  EXPECT_NE(summary.find("sliding_share,0.5,"), std::string::npos) << summary;
  EXPECT_NE(summary.find("sliding_downstream_share,"), std::string::npos) << summary;
}

TEST(ChainInclination, HandPlacedPairsGiveTheirBranchAngle)
{
  Case c = nip_case(0.0);
  c.nip.chain_bin_angle = 2.0 * pi / 180.0;
  c.nip.chain_half_angle = 20.0 * pi / 180.0;
  c.nip.average_from = 0.0;
  c.dem.max_overlap_fraction = 0.5; // (the pair through the periodic image overlaps by 32 %)
  // The beads in an engine (the measurement takes its touching pairs from the contact list)
  // and one sample of them.
  auto sample = [&](const std::vector<Vector3> &at, const std::vector<double> &radius) {
    DemSystem system(c);
    for (std::size_t k = 0; k < at.size(); ++k)
      system.particles().add(at[k], radius[k], c.material("carrier").density, 0, 0.0);
    system.initialize();
    ChainInclination chains(c);
    chains.sample(system);
    EXPECT_EQ(chains.samples(), 1);
    return chains.bins();
  };
  const NipFrame f = NipFrame::from_case(c);
  const double r = 30e-6, d = 2.0 * r * 0.999; // touching
  std::vector<Vector3> x;
  std::vector<double> radii;
  // A pair with midpoint at sleeve angle θ, radius Rs + 0.2 mm, branch at β from the local
  // normal (positive downstream): bin of θ must report β.
  auto pair = [&](double theta, double beta, double z) {
    const double rm = f.sleeve_radius + 0.2e-3;
    const double ex = std::cos(theta), ey = std::sin(theta); // radial (drum on +x, CCW sleeve)
    const double tx = -ey, ty = ex;                          // downstream tangent
    const double bx = std::cos(beta) * ex + std::sin(beta) * tx, by = std::cos(beta) * ey + std::sin(beta) * ty;
    const Vector3 m{rm * ex, rm * ey, z};
    x.push_back({m.x - 0.5 * d * bx, m.y - 0.5 * d * by, z});
    x.push_back({m.x + 0.5 * d * bx, m.y + 0.5 * d * by, z});
    radii.push_back(r);
    radii.push_back(r);
  };
  const double deg = pi / 180.0;
  pair(-10 * deg, -25 * deg, 0.3e-3); // inlet, leaning back
  pair(0.0, 0.0, 0.3e-3);             // gap centre, upright
  pair(12 * deg, 35 * deg, 0.3e-3);   // outlet, leaning forward
  // Bin at +6°: two pairs at ±20° → inclination 0, anisotropy cos 40°.
  pair(6 * deg, 20 * deg, 0.2e-3);
  pair(6 * deg, -20 * deg, 0.6e-3);
  // Bin at −4°: two pairs at 10° and 100° → isotropic (anisotropy 0).
  pair(-4 * deg, 10 * deg, 0.2e-3);
  pair(-4 * deg, 100 * deg, 0.6e-3);
  // A pair straddling the periodic boundary along z at −16°: touching through the image,
  // branch nearly along z; in-plane part along the normal.
  {
    const double th = -16 * deg, rm = f.sleeve_radius + 0.2e-3;
    x.push_back({rm * std::cos(th), rm * std::sin(th), 0.01e-3});
    x.push_back({(rm + 5e-6) * std::cos(th), (rm + 5e-6) * std::sin(th), 1e-3 - 0.04e-3});
    radii.push_back(r);
    radii.push_back(r);
  }
  const auto bins = sample(x, radii);
  auto at = [&](double theta_deg) { return bins[static_cast<std::size_t>(std::lround(theta_deg / 2.0) + 10)]; };
  EXPECT_NEAR(at(-10).inclination, -25 * deg, 1e-12);
  EXPECT_NEAR(at(0).inclination, 0.0, 1e-12);
  EXPECT_NEAR(at(12).inclination, 35 * deg, 1e-12);
  EXPECT_NEAR(at(-10).anisotropy, 1.0, 1e-12);
  EXPECT_NEAR(at(6).inclination, 0.0, 1e-12);
  EXPECT_NEAR(at(6).anisotropy, std::cos(40 * deg), 1e-12);
  EXPECT_NEAR(at(-4).anisotropy, 0.0, 1e-12);
  EXPECT_NEAR(at(6).contacts, 2.0, 0.0);
  EXPECT_NEAR(at(-16).contacts, 1.0, 0.0); // found through the periodic image
  EXPECT_NEAR(at(-16).inclination, 0.0, 1e-9);
  EXPECT_TRUE(std::isnan(at(18).inclination)); // no contact there
  // Pairs farther apart than the sum of radii are not contacts.
  EXPECT_EQ(sample({{12.7e-3, 0, 0.5e-3}, {12.7e-3 + 61e-6, 0, 0.5e-3}}, {r, r})[10].contacts, 0.0);
}

TEST(BrushHeight, StackedBeadsGiveTheirTipHeightMassAndTheGap)
{
  Case c = nip_case(0.0);
  c.nip.chain_bin_angle = 2.0 * pi / 180.0;
  c.nip.chain_half_angle = 20.0 * pi / 180.0;
  c.nip.average_from = 0.0;
  Population toner = c.populations.front();
  toner.name = "toner";
  toner.kind = ParticleKind::toner;
  c.populations.push_back(toner);
  const double deg = pi / 180.0, rs = 12.5e-3, r = 30e-6, rho = c.material("carrier").density;
  const double m = rho * 4.0 / 3.0 * pi * r * r * r;
  DemSystem system(c);
  auto place = [&](double theta_deg, double centre_height, int species) {
    const double rm = rs + centre_height;
    system.particles().add({rm * std::cos(theta_deg * deg), rm * std::sin(theta_deg * deg), 0.5e-3}, r, rho, species,
                           0.0);
  };
  // At the gap centre (bin 0°) a stack whose tops are 60, 120 and 180 um above the sleeve, and
  // a toner particle above it (not part of the brush); one bead in the bin at -6°.
  place(0.3, 30e-6, 0);
  place(-0.4, 90e-6, 0);
  place(0.2, 150e-6, 0);
  place(0.0, 300e-6, 1);
  place(-6.4, 100e-6, 0);
  system.initialize();
  BrushHeight brush(c);
  brush.sample(system);
  // Second sample: the top bead of the stack sinks to 90 um (the tip is then the 120 um bead),
  // the bead at -6° leaves the profile.
  ParticleState &p = system.particles();
  auto move = [&](std::size_t i, double theta_deg, double centre_height) {
    p.x[i] = (rs + centre_height) * std::cos(theta_deg * deg);
    p.y[i] = (rs + centre_height) * std::sin(theta_deg * deg);
  };
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::abs(p.radius[i] - r) < 1e-12 && p.species[i] == 0 &&
        std::abs(std::hypot(p.x[i], p.y[i]) - (rs + 150e-6)) < 1e-9)
      move(i, 0.2, 60e-6);
    else if (std::abs(std::atan2(p.y[i], p.x[i]) + 6.4 * deg) < 1e-9)
      move(i, -30.0, 100e-6);
  brush.sample(system);
  ASSERT_EQ(brush.samples(), 2);
  const auto bins = brush.bins();
  auto at = [&](double theta_deg) { return bins[static_cast<std::size_t>(std::lround(theta_deg / 2.0) + 10)]; };
  const double bin_area = rs * 2.0 * deg * 1e-3;
  EXPECT_NEAR(at(0).tip_height, 0.5 * (180e-6 + 120e-6), 1e-12);
  EXPECT_NEAR(at(0).carriers, 3.0, 0.0);
  EXPECT_NEAR(at(0).mass_per_area, 3.0 * m / bin_area, 1e-9 * m / bin_area);
  EXPECT_NEAR(at(-6).tip_height, 130e-6, 1e-12); // averaged over the sample that held a bead
  EXPECT_NEAR(at(-6).carriers, 0.5, 0.0);        // but its mass over both
  EXPECT_NEAR(at(-6).mass_per_area, 0.5 * m / bin_area, 1e-9 * m / bin_area);
  EXPECT_TRUE(std::isnan(at(8).tip_height));
  EXPECT_EQ(at(8).mass_per_area, 0.0);
  // The gap: the development gap at the line of centres; elsewhere the point that far out along
  // the sleeve's radius lies on the drum (drum centre at Rs + gap + Rd on +x), and the gap widens.
  EXPECT_NEAR(at(0).gap, 0.4e-3, 1e-15);
  const double d = rs + 0.4e-3 + 50e-3;
  for (double theta : {-20.0, -10.0, 6.0, 20.0})
  {
    const double g = at(theta).gap, rp = rs + g;
    EXPECT_NEAR(std::hypot(rp * std::cos(theta * deg) - d, rp * std::sin(theta * deg)), 50e-3, 1e-12) << theta;
    EXPECT_GT(g, 0.4e-3);
  }
  EXPECT_NEAR(at(-10).gap, at(10).gap, 1e-15);
  // Written and read back (the checkpoint's state): the same profile.
  MemoryStateOut out;
  brush.write_state(out);
  BrushHeight restored(c);
  MemoryStateIn in(out.bytes(), "test");
  restored.read_state(in);
  EXPECT_EQ(restored.csv(), brush.csv());
}

TEST(NipTimeSeries, CountsBeadsCrossingTheWindowAndLostBeads)
{
  Case c = nip_case(0.0);
  c.nip.chain_half_angle = 10.0 * pi / 180.0;
  NipTimeSeries series(c);
  const double rm = 12.6e-3, r = 30e-6, deg = pi / 180.0;
  auto at = [&](double theta_deg) { return Vector3{rm * std::cos(theta_deg * deg), rm * std::sin(theta_deg * deg), 0.5e-3}; };
  const std::vector<std::int32_t> ids = {0, 1, 2, 3};
  const std::vector<double> radii(4, r);
  // t0: bead 0 upstream, 1 in, 2 in, 3 in.
  series.add_beads(0.0, ids, {at(-12), at(-5), at(5), at(0)}, radii);
  // t1: 0 entered, 2 left, 3 went back upstream.
  series.add_beads(1.0, ids, {at(-9), at(-4), at(11), at(-11)}, radii);
  // t2: 3 re-enters, 1 flies off (lost: beyond the grid), 2 comes back in.
  series.add_beads(2.0, ids, {at(-8), {0.1, 0.0, 0.0}, at(9), at(-9)}, radii);
  const auto &rows = series.rows();
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].in_window, 3);
  EXPECT_EQ(rows[1].in_window, 2); // 0, 1
  EXPECT_EQ(rows[1].entered, 0); // +1 (bead 0) − 1 (bead 3 went back)
  EXPECT_EQ(rows[1].left, 1);
  EXPECT_EQ(rows[2].lost, 1);
  EXPECT_EQ(rows[2].entered, 1);
  EXPECT_EQ(rows[2].left, 0);
  EXPECT_EQ(rows[2].in_window, 3); // 0, 2, 3
  for (const auto &row : rows)
  {
    EXPECT_EQ(row.beads, 4);
    if (row.lost == 0)
    {
      EXPECT_EQ(row.in_window, rows[0].in_window + row.entered - row.left);
    }
  }
  // A non-finite bead is lost too.
  series.add_beads(3.0, ids, {at(-8), {std::nan(""), 0.0, 0.0}, at(9), at(-9)}, radii);
  EXPECT_EQ(series.rows().back().lost, 1);
}

// The nip's STATE for the steady-state verdict: the beads in the window over the averaging
// window. A window still filling drifts; a full one holds, and then a drum force that only
// fluctuates (within its noise) does not fail the run, while one that trends does.
TEST(NipTimeSeries, BeadsInTheWindowAreTheStateOfTheSteadyStateVerdict)
{
  Case c = nip_case(0.0);
  c.nip.chain_half_angle = 10.0 * pi / 180.0;
  c.nip.average_from = 10.0;
  const double rm = 12.6e-3, r = 30e-6, deg = pi / 180.0;
  auto at = [&](double theta_deg) { return Vector3{rm * std::cos(theta_deg * deg), rm * std::sin(theta_deg * deg), 0.5e-3}; };
  // 200 beads; at sample k the first in(k) of them are in the window, the rest upstream.
  auto run = [&](auto in) {
    NipTimeSeries series(c);
    std::vector<std::int32_t> ids(200);
    std::vector<double> radii(200, r);
    for (int i = 0; i < 200; ++i)
      ids[static_cast<std::size_t>(i)] = i;
    for (int k = 0; k < 120; ++k)
    {
      std::vector<Vector3> x(200);
      for (int i = 0; i < 200; ++i)
        x[static_cast<std::size_t>(i)] = at(i < in(k) ? 0.0 : -15.0);
      series.add_beads(static_cast<double>(k), ids, x, radii);
    }
    return series;
  };
  // Filling: 100 → 199 beads over the whole run; averaged from t = 10 (samples 10 … 119).
  const NipTimeSeries filling = run([](int k) { return 100 + (99 * k) / 119; });
  const auto f = filling.summary();
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].key, "beads_in_nip_window");
  EXPECT_TRUE(f[0].state);
  EXPECT_GT(f[0].drift, 0.2); // the halves' means 131 and 177
  // Full: 150 ± 1 beads.
  const NipTimeSeries full = run([](int k) { return 150 + (k % 3) - 1; });
  const auto s = full.summary();
  EXPECT_NEAR(s[0].value, 150.0, 0.02);
  EXPECT_LT(std::abs(s[0].drift), 0.01);

  // The verdict with a drum force beside the state: one that fluctuates (a 4 % drift within
  // two of its standard errors), one that trends (6 % at six standard errors).
  auto force = [](double drift, double error) {
    SummaryValue v;
    v.key = "normal_force_per_length_N_m", v.value = 1.0, v.drift = drift, v.drift_standard_error = error;
    return v;
  };
  auto verdict = [&](const SummaryValue &state, const SummaryValue &fn) {
    SteadyStateVerdict v;
    v.add(state, 0.02);
    v.add(fn, 0.02);
    return v;
  };
  EXPECT_EQ(verdict(s[0], force(-0.04, 0.025)).verdict(), 1.0);
  EXPECT_EQ(verdict(s[0], force(-0.06, 0.01)).verdict(), 0.0);
  EXPECT_EQ(verdict(f[0], force(-0.04, 0.025)).verdict(), 0.0); // still filling
  // A drift beyond the tolerance whose error is unknown (too few samples for blocks) is not
  // taken for noise; one within the tolerance passes without an error.
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(verdict(s[0], force(1.8, unknown)).verdict(), 0.0);
  EXPECT_EQ(verdict(s[0], force(0.01, unknown)).verdict(), 1.0);
  const std::string rows = verdict(f[0], force(0.0, 0.01)).rows(0.02);
  EXPECT_NE(rows.find("steady_state,0,"), std::string::npos) << rows;
  EXPECT_NE(rows.find("significant_drift,1,"), std::string::npos) << rows; // the filling is a trend
  // Without a state, the strict rule: the fluctuating force alone fails the 2 % test.
  SteadyStateVerdict alone;
  alone.add(force(-0.04, 0.025), 0.02);
  EXPECT_EQ(alone.verdict(), 0.0);
}

TEST(NipProfile, OneEngineStepOnATurningDrum)
{
  // Beads pressed on the drum by a prescribed overlap, the drum turning: the profile must
  // see the Hertz force (k_n δ^{3/2}, computed here from the materials) in the right bins
  // and a slip equal to minus the drum surface speed (the beads are at rest).
  Case c = nip_case(0.0);
  c.sleeve->rpm = 0.0;
  c.nip.sample_interval = 1e-9;
  // A tiny step, so that the beads are still where they were put when the forces are read
  // (the Hertz force accelerates a 60 µm bead at ~1e7 m/s²).
  c.dem.time_step = 1e-11;
  DemSystem system(c);
  NipProfile profile(c);
  const NipFrame &f = profile.frame();
  const double r = 30e-6, overlap = 0.3e-6;
  const Material &m = c.material("carrier");
  for (double x : {-1e-3, 0.0, 0.5e-3, 1.5e-3})
    system.particles().add(on_drum(f, x, r - overlap), r, m.density, 0, 0.0);
  system.initialize();
  system.step();
  profile.sample(system);
  // Hertz between a 1 GPa bead (ν 0.35) and a 50 GPa drum (ν 0.3), R* = r.
  const Material &wall = c.material("drum");
  const double e_star = 1.0 / ((1 - m.poisson_ratio * m.poisson_ratio) / m.youngs_modulus +
                               (1 - wall.poisson_ratio * wall.poisson_ratio) / wall.youngs_modulus);
  const double hertz = 4.0 / 3.0 * e_star * std::sqrt(r) * std::pow(overlap, 1.5);
  const double v_drum = -c.drum.omega() * c.drum.radius;
  const auto bins = profile.bins();
  for (double x : {-1e-3, 0.0, 0.5e-3, 1.5e-3})
  {
    const NipBin &b = bins[static_cast<std::size_t>(std::lround(x / 0.25e-3) + 8)];
    EXPECT_NEAR(b.normal_force_per_bead / hertz, 1.0, 2e-3) << "x = " << x;
    EXPECT_NEAR(b.slip / -v_drum, 1.0, 1e-3) << "x = " << x;
    // The drum drags the beads downstream: the beads drag it back (tangential < 0), at most μ F_n.
    EXPECT_LT(b.tangential_pressure, 0.0);
    EXPECT_LE(-b.tangential_pressure, 0.35 * b.normal_pressure * (1 + 1e-12));
  }
  EXPECT_EQ(bins[1].contacts, 0);
}

TEST(NipCaseKeys, DefaultsEqualTheContractStruct)
{
  const Case c = load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/tests/case/valid/minimal_roller.yaml");
  const NipSettings d;
  EXPECT_DOUBLE_EQ(c.nip.average_from, d.average_from);
  EXPECT_DOUBLE_EQ(c.nip.sample_interval, d.sample_interval);
  EXPECT_DOUBLE_EQ(c.nip.bin_width, d.bin_width);
  EXPECT_DOUBLE_EQ(c.nip.half_width, d.half_width);
  EXPECT_NEAR(c.nip.chain_bin_angle, d.chain_bin_angle, 1e-15);
  EXPECT_NEAR(c.nip.chain_half_angle, d.chain_half_angle, 1e-15);
  const Case o = load_case(std::string(MAGBRUSH_SOURCE_DIR) + "/tests/case/valid/minimal_roller.yaml",
                           {"nip.average_from=1ms", "nip.bin_width=0.1mm"});
  EXPECT_NEAR(o.nip.average_from, 1e-3, 1e-18);
  EXPECT_NEAR(o.nip.bin_width, 1e-4, 1e-18);
}

// The study summary (dem/summary.csv via dem/run_summary.h): per-sample totals give the means
// with their standard error, and the drift between halves decides the steady state.
TEST(NipProfile, SummaryJudgesSteadyStateByTheDriftOfItsMeans)
{
  const Case c = nip_case(0.0);
  const double r = 30e-6, overlap = 0.2e-6;
  auto bead_pressing = [&](const NipProfile &p, double newtons) {
    DrumContact b;
    b.position = on_drum(p.frame(), 0.0, r - overlap);
    b.radius = r;
    b.force_on_wall = {newtons * p.frame().nx, newtons * p.frame().ny, 0.0};
    return b;
  };
  // Steady: the same 1 mN bead every sample, alternating with a second one of 1 mN.
  NipProfile steady(c);
  for (int k = 0; k < 100; ++k)
  {
    std::vector<DrumContact> beads = {bead_pressing(steady, 1e-3)};
    if (k % 2)
      beads.push_back(bead_pressing(steady, 1e-3));
    steady.add_sample(k * 1e-6, beads);
  }
  const SummaryValue fn = value(steady.summary(), "normal_force_per_length_N_m");
  const double Lz = c.dem.periodic_length;
  EXPECT_NEAR(fn.value, 1.5e-3 / Lz, 1e-12);
  EXPECT_NEAR(fn.drift, 0.0, 1e-12);
  // Ten blocks of ten samples, each with five 1-bead and five 2-bead samples: no spread.
  EXPECT_NEAR(fn.standard_error, 0.0, 1e-12);
  std::vector<std::unique_ptr<Measurement>> m;
  m.push_back(std::make_unique<NipProfile>(steady));
  EXPECT_NE(run_summary_csv(m, c.statistics).find("steady_state,1,"), std::string::npos);

  // Draining: the force falls linearly from 2 mN to 1 mN over the window; drift between the
  // halves = 0.5 / 1.5 = 33 %, far beyond 2 %: not a steady state.
  NipProfile draining(c);
  for (int k = 0; k < 100; ++k)
    draining.add_sample(k * 1e-6, {bead_pressing(draining, 2e-3 - 1e-3 * k / 100.0)});
  const SummaryValue d = value(draining.summary(), "normal_force_per_length_N_m");
  EXPECT_NEAR(d.drift, -(0.5e-3) / (1.505e-3), 1e-9); // falling: a negative drift
  EXPECT_GT(d.standard_error, 0.0);
  m.clear();
  m.push_back(std::make_unique<NipProfile>(draining));
  EXPECT_NE(run_summary_csv(m, c.statistics).find("steady_state,0,"), std::string::npos);
}

// The peak and the centre bin carry standard errors from their own per-sample series: the
// scatter of the means of ten blocks of ten samples, computed here from the blocks' known means.
TEST(NipProfile, PeakAndCentreBinHaveBlockStandardErrors)
{
  const Case c = nip_case(0.0);
  NipProfile profile(c);
  const NipFrame &f = profile.frame();
  const double r = 30e-6, overlap = 0.2e-6;
  auto bead = [&](double x, double newtons) {
    DrumContact b;
    b.position = on_drum(f, x, r - overlap);
    b.radius = r;
    const double psi = std::asin(x / f.drum_radius);
    const double nox = -f.nx * std::cos(psi) + f.tx * std::sin(psi), noy = -f.ny * std::cos(psi) + f.ty * std::sin(psi);
    b.force_on_wall = {-newtons * nox, -newtons * noy, 0.0};
    return b;
  };
  // Block j (samples 10 j .. 10 j + 9): one bead of (1 + 0.1 j) mN at the centre, a second
  // one of 1 mN there in even blocks; at x = 1 mm a steady 5 mN, the peak with no scatter.
  std::vector<double> centre_force(10), centre_beads(10);
  for (int k = 0; k < 100; ++k)
  {
    const int j = k / 10;
    std::vector<DrumContact> beads = {bead(0.0, 1e-3 * (1.0 + 0.1 * j)), bead(1e-3, 5e-3)};
    if (j % 2 == 0)
      beads.push_back(bead(0.0, 1e-3));
    centre_force[static_cast<std::size_t>(j)] = 1e-3 * (1.0 + 0.1 * j) + (j % 2 == 0 ? 1e-3 : 0.0);
    centre_beads[static_cast<std::size_t>(j)] = j % 2 == 0 ? 2.0 : 1.0;
    profile.add_sample(k * 1e-6, beads);
  }
  auto mean_and_error = [](const std::vector<double> &blocks) {
    double m = 0.0, ss = 0.0;
    for (double v : blocks)
      m += v / 10.0;
    for (double v : blocks)
      ss += (v - m) * (v - m);
    return std::make_pair(m, std::sqrt(ss / 9.0 / 10.0));
  };
  const auto bins = profile.bins();
  const double area0 = bins[8].area, area4 = bins[12].area;
  const auto summary = profile.summary();
  const auto [f0, f0_error] = mean_and_error(centre_force);
  const SummaryValue centre = value(summary, "normal_pressure_at_gap_centre_Pa");
  EXPECT_NEAR(centre.value, f0 / area0, 1e-9 * f0 / area0);
  EXPECT_NEAR(centre.standard_error, f0_error / area0, 1e-9 * f0 / area0);
  const auto [n0, n0_error] = mean_and_error(centre_beads);
  const SummaryValue density = value(summary, "density_at_gap_centre_per_mm2");
  EXPECT_NEAR(density.value, n0 / area0 * 1e-6, 1e-9 * n0 / area0 * 1e-6);
  EXPECT_NEAR(density.standard_error, n0_error / area0 * 1e-6, 1e-9 * n0 / area0 * 1e-6);
  // The peak is the steady bin at 1 mm (5 mN over a bin of nearly the centre's area), exact.
  ASSERT_GT(5e-3 / area4, f0 / area0);
  const SummaryValue peak = value(summary, "peak_normal_pressure_Pa");
  EXPECT_NEAR(peak.value, 5e-3 / area4, 1e-9 * 5e-3 / area4);
  EXPECT_NEAR(peak.standard_error, 0.0, 1e-9 * 5e-3 / area4);
  EXPECT_GT(centre.standard_error, 0.0);

  // The series survive a checkpoint: a profile read back gives the same errors.
  MemoryStateOut out;
  profile.write_state(out);
  MemoryStateIn in(out.bytes(), "test state");
  NipProfile restored(c);
  restored.read_state(in);
  const SummaryValue again = value(restored.summary(), "normal_pressure_at_gap_centre_Pa");
  EXPECT_EQ(again.standard_error, centre.standard_error);
  EXPECT_EQ(value(restored.summary(), "density_at_gap_centre_per_mm2").standard_error, density.standard_error);
}
