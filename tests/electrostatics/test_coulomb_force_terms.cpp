// The DEM force terms of the electrostatics: Coulomb (dem/force_terms/coulomb.h) and the
// conductors' images (dem/force_terms/conductor_images.h) — Newton's third law over a neutral
// periodic system, the same bits on 1 and 2 threads, a restart from a checkpoint bit for bit,
// the image force on a charge near the drum and the sleeve, and a uniform sheet of charge on
// the photoconductor dropping the potential by σ(h + L/εr)/ε0 through the pair images, and the
// renewal of a few moved charges alone giving what a whole evaluation of that moment gives.
#include "dem/checkpoint_file.h"
#include "dem/force_terms/conductor_images.h"
#include "dem/force_terms/coulomb.h"
#include "dem/force_terms/held_forces.h"
#include "electrostatics/coulomb_constants.h"
#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

using namespace magbrush;
using namespace magbrush::electrostatics;

namespace {

// Toner (7 µm, ±) and carriers (50 µm, the counter-charge) at random in a slab periodic along
// z: net neutral.
dem::ParticleState brush(std::size_t toner, std::size_t carriers, double wx, double wy, double wz, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  dem::ParticleState s;
  double total = 0.0;
  for (std::size_t k = 0; k < toner + carriers; ++k)
  {
    const bool is_toner = k < toner;
    const double q = is_toner ? -2e-15 * (0.5 + u(rng)) : 0.0;
    s.add({wx * u(rng), wy * u(rng), wz * u(rng)}, is_toner ? 3.5e-6 : 25e-6, 5000.0, is_toner ? 1 : 0, q);
    total += q;
  }
  for (std::size_t k = toner; k < toner + carriers; ++k)
    s.charge[k] = -total / static_cast<double>(carriers);
  return s;
}

dem::ForceBuffers forces_of(dem::ForceTerm &term, const dem::ParticleState &s, double t)
{
  dem::ForceBuffers f;
  f.resize(s.size());
  f.clear();
  term.add_forces(s, f, t);
  return f;
}

CoulombTermSettings settings(int order, double cell, double refresh)
{
  CoulombTermSettings s;
  s.far.order = order;
  s.far.cell_size = cell;
  s.refresh = refresh;
  return s;
}

bool same_bits(const std::vector<double> &a, const std::vector<double> &b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

} // namespace

TEST(CoulombTerm, SettingsOfADefaultCaseAreTheStructDefaults)
{
  // The electric keys' defaults (case/case_keys_electric.cpp, checked against the Electric
  // struct in test_module_defaults) reach the term as its own defaults; no drum: no images.
  const CoulombTermSettings from_case = CoulombTermSettings::from_case(Case{}), built;
  EXPECT_EQ(from_case.far.order, built.far.order);
  EXPECT_EQ(from_case.far.cell_size, built.far.cell_size);
  EXPECT_EQ(from_case.refresh, built.refresh);
  EXPECT_EQ(from_case.image_terms, built.image_terms);
  EXPECT_FALSE(from_case.image_surface.has_value());
}

TEST(CoulombTerm, NeutralPeriodicSystemHasNoNetForce)
{
  // Every pair and image acts twice with opposite signs: the net force is zero up to the far
  // field's expansion error, which is not antisymmetric.
  const std::array<double, 3> box = {0.0, 0.0, 1e-3};
  const auto s = brush(2000, 400, 1e-3, 0.4e-3, 1e-3, 7);
  for (int order : {2, 4, 6})
  {
    CoulombTerm term(settings(order, 0.1e-3, 0.0), box);
    const auto f = forces_of(term, s, 0.0);
    double net[3] = {0, 0, 0}, sum = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      net[0] += f.fx[i];
      net[1] += f.fy[i];
      net[2] += f.fz[i];
      sum += std::hypot(f.fx[i], f.fy[i], f.fz[i]);
    }
    const double ratio = std::hypot(net[0], net[1], net[2]) / sum;
    std::printf("neutral slab, 2,400 charges, order %d: |Σ F| / Σ |F| = %.2e\n", order, ratio);
    if (order == 4)
    {
      EXPECT_LT(ratio, 1e-6);
    }
  }
}

TEST(CoulombTerm, ForcesHaveTheSameBitsOnOneAndTwoThreads)
{
  const std::array<double, 3> box = {0.0, 0.0, 1e-3};
  const auto s = brush(3000, 300, 1e-3, 0.4e-3, 1e-3, 8);
  // With and without pair images in a drum plane at y = 0, and the self images.
  GroundedSurface drum;
  drum.layer = LayeredImages(3.0, 20e-6);
  for (bool images : {false, true})
  {
    dem::ForceBuffers f[2];
    for (int threads : {1, 2})
    {
      omp_set_num_threads(threads);
      CoulombTermSettings set = settings(4, 25e-6, 0.0);
      if (images)
        set.image_surface = drum;
      CoulombTerm term(set, box);
      f[threads - 1] = forces_of(term, s, 0.0);
      ConductorImages self({drum});
      self.add_forces(s, f[threads - 1], 0.0);
    }
    omp_set_num_threads(2);
    EXPECT_TRUE(same_bits(f[0].fx, f[1].fx));
    EXPECT_TRUE(same_bits(f[0].fy, f[1].fy));
    EXPECT_TRUE(same_bits(f[0].fz, f[1].fz));
  }
}

TEST(CoulombTerm, HeldFarFieldRestartsBitForBit)
{
  // Refresh every 1 ms: the second step uses the held far field and exact near pairs at the
  // moved positions; a term restored from a checkpoint written in between does the same.
  const std::array<double, 3> box = {0.0, 0.0, 1e-3};
  auto s = brush(1500, 200, 1e-3, 0.4e-3, 1e-3, 9);
  CoulombTerm a(settings(4, 0.1e-3, 1e-3), box);
  forces_of(a, s, 0.0);
  const auto path = (magbrush::testing::test_temp_dir("coulomb_term") / "state.bin").string();
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  {
    dem::CheckpointWriter out(path);
    a.write_state(out);
    out.commit();
  }
  CoulombTerm b(settings(4, 0.1e-3, 1e-3), box);
  {
    dem::CheckpointReader in(path);
    b.read_state(in);
  }
  for (std::size_t i = 0; i < s.size(); ++i)
    s.x[i] += 1e-6 * std::sin(static_cast<double>(i));
  const auto fa = forces_of(a, s, 1e-6), fb = forces_of(b, s, 1e-6);
  EXPECT_EQ(a.evaluations(), 1);
  EXPECT_EQ(b.evaluations(), 1);
  EXPECT_TRUE(same_bits(fa.fx, fb.fx));
  EXPECT_TRUE(same_bits(fa.fy, fb.fy));
  EXPECT_TRUE(same_bits(fa.fz, fb.fz));
  // And the held forces are close to a fresh evaluation at the moved positions (the held far
  // field's staleness after a 1 µm move).
  CoulombTerm fresh(settings(4, 0.1e-3, 1e-3), box);
  const auto ff = forces_of(fresh, s, 1e-6);
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    num += std::pow(fa.fx[i] - ff.fx[i], 2) + std::pow(fa.fy[i] - ff.fy[i], 2) + std::pow(fa.fz[i] - ff.fz[i], 2);
    den += ff.fx[i] * ff.fx[i] + ff.fy[i] * ff.fy[i] + ff.fz[i] * ff.fz[i];
  }
  std::printf("held far field after a 1 µm move: RMS force change against a fresh evaluation %.2e\n",
              std::sqrt(num / den));
  EXPECT_LT(std::sqrt(num / den), 1e-2);
}

TEST(ConductorImages, ChargeNearDrumAndSleeveFeelsItsImages)
{
  // A charge between a bare sleeve (radius 10 mm at the origin) and a drum (radius 15 mm,
  // layer εr = 3, 20 µm) along x: the force is the sum of the two planar image forces along
  // the normals; a particle overlapping the drum gets its images at h = its radius.
  GroundedSurface sleeve;
  sleeve.shape = GroundedSurface::Shape::cylinder;
  sleeve.radius = 10e-3;
  GroundedSurface drum = sleeve;
  drum.centre_x = 10e-3 + 0.5e-3 + 15e-3;
  drum.radius = 15e-3;
  drum.layer = LayeredImages(3.0, 20e-6);
  ConductorImages term({drum, sleeve});
  dem::ParticleState s;
  const double q = -3e-15, r = 3.5e-6;
  s.add({10.45e-3, 0.0, 0.0}, r, 1000.0, 0, q);       // 50 µm from the drum, 450 µm from the sleeve
  s.add({drum.centre_x - drum.radius + 1e-6, 0.0, 0.0}, r, 1000.0, 0, q); // overlapping the drum
  s.add({10.2e-3, 0.0, 0.0}, r, 1000.0, 0, 0.0);      // uncharged
  const auto f = forces_of(term, s, 0.0);
  const double k = coulomb_constant * q * q;
  const double expected0 = -k * drum.layer.self_force(50e-6) + k * LayeredImages(1.0, 0.0).self_force(450e-6);
  EXPECT_NEAR(f.fx[0] / expected0, 1.0, 1e-12);
  EXPECT_GT(f.fx[0], 0.0); // towards the nearer drum
  const double expected1 = -k * drum.layer.self_force(r) + k * LayeredImages(1.0, 0.0).self_force(0.5e-3 + 1e-6);
  EXPECT_NEAR(f.fx[1] / expected1, 1.0, 1e-12);
  EXPECT_EQ(f.fy[0], 0.0);
  EXPECT_EQ(f.fx[2], 0.0);
  // The grounded-plane limit through the term: a sleeve-only scene, F = q²/(16πε0h²).
  ConductorImages bare({sleeve});
  const auto g = forces_of(bare, s, 0.0);
  const double h = 0.45e-3;
  EXPECT_NEAR(g.fx[0] / (-q * q / (16.0 * pi * vacuum_permittivity * h * h)), 1.0, 1e-12);
}

TEST(PairImages, UniformSheetOnPhotoconductorDropsThePotentialBySigmaLOverEps)
{
  // A uniform sheet σ on the photoconductor (εr = 3, L = 20 µm, grounded substrate): 16 × 16
  // charges at height h above the layer in a cell periodic along x and z. Far above (two
  // periods) the potential against the substrate is σ(h + L/εr)/ε0 — σL/(ε0 εr) for a sheet ON
  // the layer, plus the air gap h — evaluated by the Coulomb sum of the charges and their pair
  // images (probes of zero charge, which carry no images). Measured relative error of the
  // potential: ≤ 1.6e-4 at order 4, ≤ 1.9e-5 at order 6; the field there ≤ 3.9e-5 of σ/ε0.
  const double P = 0.2e-3, L = 20e-6, eps_r = 3.0;
  for (double h : {0.5e-6, 3.5e-6})
  {
    GroundedSurface plane;
    plane.layer = LayeredImages(eps_r, L);
    std::vector<double> x, y, z, q;
    const int m = 16;
    const double qi = -1e-15;
    for (int i = 0; i < m; ++i)
      for (int k = 0; k < m; ++k)
      {
        x.push_back((i + 0.5) * P / m);
        y.push_back(h);
        z.push_back((k + 0.5) * P / m);
        q.push_back(qi);
      }
    for (double px : {0.0, 0.07e-3})
    {
      x.push_back(px);
      y.push_back(2.0 * P);
      z.push_back(0.03e-3);
      q.push_back(0.0);
    }
    for (int terms : {1, 2})
      for (int order : {4, 6})
    {
      CoulombSettings settings;
      settings.order = order;
      settings.cell_size = 25e-6;
      // (The M2L in double precision: the potential far above is a small difference of the
      // sheet's and its images' −2πσ|y|, which amplifies the single-precision rounding of
      // the translations, ~1e-7, by y/(h + L/εr) ≈ 30–60: 1.4e-4 at order 6 in single.)
      settings.single_precision = false;
      PeriodicCoulomb coulomb(settings, {P, 0.0, P});
      coulomb.set_image_surface(plane, terms);
      coulomb.rebuild(q.size(), x.data(), y.data(), z.data(), q.data(), nullptr);
      std::vector<double> E(3 * q.size()), phi(q.size());
      coulomb.field(x.data(), y.data(), z.data(), q.data(), nullptr, E.data(), phi.data());
      const double sigma = m * m * qi / (P * P);
      const double expected = sigma * (h + L / eps_r) / vacuum_permittivity;
      for (std::size_t p = q.size() - 2; p < q.size(); ++p)
      {
        const double field = std::hypot(E[3 * p], E[3 * p + 1], E[3 * p + 2]);
        std::printf("sheet at h = %.1f µm, %d pair-image terms, order %d: potential %.6f V, σ(h + L/εr)/ε0 = "
                    "%.6f V, relative error %.2e; field %.2e of σ/ε0\n",
                    h * 1e6, terms, order, phi[p], expected, phi[p] / expected - 1.0,
                    field / (std::abs(sigma) / vacuum_permittivity));
        EXPECT_NEAR(phi[p] / expected, 1.0, order == 6 ? 5e-5 : 3e-4);
        EXPECT_LT(field, 1e-4 * std::abs(sigma) / vacuum_permittivity);
      }
    }
  }
}

TEST(CoulombTerm, AnExchangeOfAsManyParticlesAsLeftSelectsTheChargesAgain)
{
  // Before: +q, −q and an uncharged particle. The −q particle leaves and a +q one enters in the
  // same exchange: the count stays 3, the charged set changes. The term must then act on the
  // new pair of charges, as a fresh term does (it used to keep reading the old indices: the
  // newcomer felt nothing).
  const std::array<double, 3> box = {0.0, 0.0, 1e-3};
  dem::ParticleState before;
  before.add({0.2e-3, 0.2e-3, 0.5e-3}, 4e-6, 1000.0, 0, 2e-15);
  before.add({0.3e-3, 0.2e-3, 0.5e-3}, 4e-6, 1000.0, 0, -2e-15);
  before.add({0.6e-3, 0.3e-3, 0.5e-3}, 25e-6, 1000.0, 1, 0.0);
  dem::ParticleState after;
  after.add({0.2e-3, 0.2e-3, 0.5e-3}, 4e-6, 1000.0, 0, 2e-15);
  after.add({0.6e-3, 0.3e-3, 0.5e-3}, 25e-6, 1000.0, 1, 0.0);
  after.add({0.25e-3, 0.25e-3, 0.5e-3}, 4e-6, 1000.0, 0, 2e-15);
  CoulombTerm term(settings(4, 25e-6, 1.0), box);
  forces_of(term, before, 0.0);
  term.particles_changed({0, 2, -1});
  // A checkpoint written between the exchange and the next step keeps the pending selection.
  const auto path = (magbrush::testing::test_temp_dir("coulomb_term_exchange") / "state.bin").string();
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  {
    dem::CheckpointWriter out(path);
    term.write_state(out);
    out.commit();
  }
  CoulombTerm restored(settings(4, 25e-6, 1.0), box);
  {
    dem::CheckpointReader in(path);
    restored.read_state(in);
  }
  const auto f = forces_of(term, after, 1e-9), r = forces_of(restored, after, 1e-9);
  CoulombTerm fresh(settings(4, 25e-6, 1.0), box);
  const auto g = forces_of(fresh, after, 1e-9);
  ASSERT_GT(std::abs(g.fx[2]), 0.0);
  for (std::size_t i = 0; i < 3; ++i)
  {
    EXPECT_EQ(f.fx[i], g.fx[i]) << i;
    EXPECT_EQ(f.fy[i], g.fy[i]) << i;
    EXPECT_EQ(f.fz[i], g.fz[i]) << i;
    EXPECT_EQ(r.fx[i], g.fx[i]) << i;
    EXPECT_EQ(r.fy[i], g.fy[i]) << i;
    EXPECT_EQ(r.fz[i], g.fz[i]) << i;
  }
}

TEST(PeriodicCoulomb, RenewingAFewMovedChargesGivesWhatAFieldOfTheirNewPlacesGives)
{
  // Two rounds of moving a few charges (with their pair images in a layered drum plane): after
  // renew(), the moved charges' fields are a field() at the new places bit for bit, the others'
  // held fields plus the changes renew() gave them agree with it to round-off, and no moved
  // charge is among those touched.
  const std::array<double, 3> box = {0.0, 0.0, 1e-3};
  auto s = brush(1500, 200, 1e-3, 0.4e-3, 1e-3, 11);
  for (std::size_t i = 0; i < s.size(); ++i)
    s.y[i] += 30e-6; // above the drum plane at y = 0
  GroundedSurface drum;
  drum.layer = LayeredImages(3.0, 20e-6);
  CoulombSettings set;
  PeriodicCoulomb c(set, box);
  c.set_image_surface(drum, 2);
  const std::size_t n = s.size();
  c.rebuild(n, s.x.data(), s.y.data(), s.z.data(), s.charge.data(), s.radius.data());
  std::vector<double> held(3 * n), fresh(3 * n), dE, E_moved;
  c.field(s.x.data(), s.y.data(), s.z.data(), s.charge.data(), s.radius.data(), held.data(), nullptr);
  std::vector<std::uint32_t> touched;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1e-6, 1e-6);
  for (int round = 0; round < 2; ++round)
  {
    std::vector<std::uint32_t> moved;
    for (std::uint32_t k = static_cast<std::uint32_t>(round); k < n; k += 57)
    {
      moved.push_back(k);
      s.x[k] += u(rng);
      s.y[k] += u(rng);
      s.z[k] += u(rng);
    }
    c.renew(moved, s.x.data(), s.y.data(), s.z.data(), s.charge.data(), s.radius.data(), touched, dE, E_moved);
    for (const std::uint32_t k : touched)
    {
      EXPECT_TRUE(std::find(moved.begin(), moved.end(), k) == moved.end());
      for (int d = 0; d < 3; ++d)
      {
        held[3 * k + d] += dE[3 * k + d];
        dE[3 * k + d] = 0.0;
      }
    }
    for (std::size_t a = 0; a < moved.size(); ++a)
      for (int d = 0; d < 3; ++d)
        held[3 * moved[a] + d] = E_moved[3 * a + d];
    EXPECT_GT(touched.size(), moved.size());
    c.field(s.x.data(), s.y.data(), s.z.data(), s.charge.data(), s.radius.data(), fresh.data(), nullptr);
    double largest = 0.0, worst = 0.0;
    for (std::size_t i = 0; i < 3 * n; ++i)
      largest = std::max(largest, std::abs(fresh[i]));
    for (std::size_t i = 0; i < 3 * n; ++i)
      worst = std::max(worst, std::abs(held[i] - fresh[i]));
    for (const std::uint32_t k : moved)
      for (int d = 0; d < 3; ++d)
        EXPECT_EQ(held[3 * k + d], fresh[3 * k + d]);
    std::printf("round %d: %zu moved, %zu entries touched; held vs field(): %.1e of the largest field\n", round,
                moved.size(), touched.size(), worst / largest);
    EXPECT_LT(worst, 1e-12 * largest);
  }
}

TEST(CoulombTerm, HeldWithTheMovedRenewedAloneIsAWholeEvaluationOfTheirNewPlaces)
{
  // The chain the engine runs: HeldForces around the Coulomb term, renewing alone the few
  // charges that moved the hold distance. Held forces after the move = the term evaluated
  // (with the same held far field and cells) with the moved charges where they are and the
  // others where they were, to round-off; the others' own small moves are not yet seen.
  const std::array<double, 3> box = {0.0, 0.0, 1e-3};
  auto s = brush(1500, 200, 1e-3, 0.4e-3, 1e-3, 12);
  const double d = 20e-9;
  dem::HeldForces held(std::make_unique<CoulombTerm>(settings(4, 25e-6, 1e-3), box), d, box, {}, 0.05);
  CoulombTerm whole(settings(4, 25e-6, 1e-3), box);
  forces_of(held, s, 0.0);
  forces_of(whole, s, 0.0);
  auto mixed = s;
  std::vector<std::uint32_t> moved;
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    const bool fast = i % 40 == 3;
    const double step = fast ? 3.0 * d : 0.3 * d;
    s.x[i] += step * std::cos(static_cast<double>(i));
    s.y[i] += step * std::sin(static_cast<double>(i));
    if (fast)
    {
      mixed.x[i] = s.x[i];
      mixed.y[i] = s.y[i];
      moved.push_back(static_cast<std::uint32_t>(i));
    }
  }
  const auto fh = forces_of(held, s, 1e-8), fw = forces_of(whole, mixed, 1e-8);
  EXPECT_EQ(held.renewals(), 1);
  EXPECT_EQ(held.renewed(), static_cast<long>(moved.size()));
  EXPECT_EQ(held.evaluations(), 1);
  double largest = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i)
  {
    largest = std::max({largest, std::abs(fw.fx[i]), std::abs(fw.fy[i]), std::abs(fw.fz[i])});
    worst = std::max({worst, std::abs(fh.fx[i] - fw.fx[i]), std::abs(fh.fy[i] - fw.fy[i]),
                      std::abs(fh.fz[i] - fw.fz[i])});
  }
  std::printf("%zu of %zu renewed alone: held vs whole evaluation %.1e of the largest force\n", moved.size(),
              s.size(), worst / largest);
  EXPECT_LT(worst, 1e-12 * largest);
  // More than the share moved: everybody is evaluated.
  for (std::size_t i = 0; i < s.size(); ++i)
    s.x[i] += 2.0 * d;
  forces_of(held, s, 2e-8);
  EXPECT_EQ(held.evaluations(), 2);
  EXPECT_EQ(held.renewals(), 1);
}
