// The applied-field force qE (dem/force_terms/electric_field_force.h): exact in a uniform
// field, a charge in the field of a moving σ0 cos(kx) latent image against the exact planar
// solution, the stale-grid refusal, the rule that switches it on, and 1 vs 2 threads.
#include "dem/force_terms/electric_field_force.h"
#include "dem/force_terms/force_term_registry.h"

#include "case/case_hash.h"
#include "case/case_parser.h"
#include "fields/field_files.h"
#include "fields/field_grid.h"

#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <random>

using namespace magbrush;
using magbrush::dem::ElectricFieldForce;
using magbrush::dem::ForceBuffers;
using magbrush::dem::ParticleState;

namespace {

constexpr double eps0 = 8.8541878128e-12;
constexpr double pi = 3.14159265358979323846;
namespace fs = std::filesystem;

NipPotentialGrid nip_grid(double x0, double x1, int n_x, double y0, double y1, int n_y,
                          const std::function<double(double, double)> &bias,
                          const std::function<double(double, double, double)> &image, int K,
                          double period)
{
  NipPotentialGrid g;
  g.bias = sample_cartesian_grid(x0, x1, n_x, y0, y1, n_y, bias);
  g.image_period = period;
  // A planar surface y = 0 moving toward +x: the bottom of a huge drum centred above it
  // (counter-clockwise there is +x).
  g.drum_center = {0.0, 1e3};
  g.drum_radius = 1e3;
  for (int k = 0; k < K; ++k)
    g.image.push_back(sample_cartesian_grid(x0, x1, n_x, y0, y1, n_y, [&](double x, double y) {
                        return image(x, y, k * period / K);
                      }).phi);
  return g;
}

ParticleState particles(const std::vector<std::array<double, 3>> &x, const std::vector<double> &q)
{
  ParticleState s;
  for (std::size_t k = 0; k < x.size(); ++k)
    s.add({x[k][0], x[k][1], x[k][2]}, 4e-6, 1200.0, 0, q[k]);
  return s;
}

ForceBuffers zero_forces(std::size_t n)
{
  ForceBuffers f;
  f.resize(n);
  f.clear();
  return f;
}

Drum turning_drum(double surface_speed)
{
  Drum d;
  d.present = true;
  d.radius = 15e-3;
  d.rpm = surface_speed / d.radius * 60.0 / (2.0 * pi);
  return d;
}

} // namespace

// Φ = −E0·x: the spline reproduces a linear potential exactly, so F = q E0 to round-off, for
// every charge; uncharged particles get nothing, a charge outside the window nothing (counted).
TEST(ElectricFieldForce, UniformFieldGivesExactlyQE)
{
  const double Ex = 1.3e6, Ey = -2.1e6;
  auto field = std::make_shared<const NipPotentialField>(
    nip_grid(-1e-3, 1e-3, 11, 0.0, 5e-4, 7, [&](double x, double y) { return -(Ex * x + Ey * y); },
             [](double, double, double) { return 0.0; }, 1, 0.0));
  ElectricFieldForce term(field, turning_drum(0.3), {0.0, 0.0, 0.0});
  const ParticleState s = particles({{0.1e-3, 0.2e-3, 0.0}, {-0.77e-3, 0.49e-3, 3e-3},
                                     {0.0, 0.0, 0.0}, {0.3e-3, 0.1e-3, 0.0}, {2e-3, 0.1e-3, 0.0}},
                                    {-1.5e-15, 2.0e-15, 7e-16, 0.0, -1e-15});
  ForceBuffers f = zero_forces(s.size());
  term.add_forces(s, f, 1e-3);
  for (std::size_t k = 0; k < 3; ++k)
  {
    EXPECT_NEAR(f.fx[k], s.charge[k] * Ex, 1e-12 * std::abs(s.charge[k] * Ex)) << k;
    EXPECT_NEAR(f.fy[k], s.charge[k] * Ey, 1e-12 * std::abs(s.charge[k] * Ey)) << k;
    EXPECT_EQ(f.fz[k], 0.0);
  }
  EXPECT_EQ(f.fx[3], 0.0); // uncharged
  EXPECT_EQ(f.fx[4], 0.0); // outside the window
  EXPECT_EQ(term.lookups(), 4);
  EXPECT_EQ(term.lookups_outside(), 1);
}

// A latent image σ0 cos(k s) on a photoconductor (t, εr) over a grounded substrate, a grounded
// electrode across the gap g (Kweon's planar stack): in the gap
//   Φ = φ_s cos(k x) sinh(k (t + g − y)) / sinh(k g),  φ_s = σ0 / (ε0 k (εr coth kt + coth kg)).
// The image is carried along x by the drum surface, u(t) = v t: the grid stores K = 8 phases,
// the term interpolates to u(t) and must give q E(x − u, y). Trigonometric interpolation is
// exact in phase for this single harmonic, and so is the co-moving one for a translation
// along a plane; linear has the phase error 1 − cos(π/K) ≈ 7.6e-2 of the field at worst, and
// we check it is that large.
TEST(ElectricFieldForce, ChargeInAMovingCosineImageFieldMatchesThePlanarSolution)
{
  const double t = 20e-6, g = 100e-6, eps_r = 3.0, sigma0 = 1e-4, L = 160e-6;
  const double k = 2.0 * pi / L;
  const double phi_s = sigma0 / (eps0 * k * (eps_r / std::tanh(k * t) + 1.0 / std::tanh(k * g)));
  // y measured from the photoconductor surface (the gap is 0 ≤ y ≤ g).
  const auto phi = [&](double x, double y, double u) {
    return phi_s * std::cos(k * (x - u)) * std::sinh(k * (g - y)) / std::sinh(k * g);
  };
  const auto E_exact = [&](double x, double y, double u) {
    const double c = phi_s * k / std::sinh(k * g);
    return std::array<double, 2>{c * std::sin(k * (x - u)) * std::sinh(k * (g - y)),
                                 c * std::cos(k * (x - u)) * std::cosh(k * (g - y))};
  };
  const int K = 8;
  const NipPotentialGrid grid =
    nip_grid(-L, L, 129, 0.0, g, 41, [](double, double) { return 0.0; }, phi, K, L);
  const Drum drum = turning_drum(0.27);
  const double E_scale = phi_s * k / std::tanh(k * g);

  for (const auto phase : {NipPotentialField::PhaseInterpolation::trigonometric,
                           NipPotentialField::PhaseInterpolation::linear,
                           NipPotentialField::PhaseInterpolation::co_moving})
  {
    ElectricFieldForce term(std::make_shared<const NipPotentialField>(grid, phase), drum,
                            {0.0, 0.0, 0.0});
    std::vector<std::array<double, 3>> x;
    std::vector<double> q;
    for (int i = 0; i < 17; ++i)
      for (const double y : {4e-6, 0.3 * g, 0.8 * g})
      {
        x.push_back({-0.8 * L + i * 0.1 * L, y, 0.0}); // co-moving lookups turn by ≤ L/K
        q.push_back(-2e-15 * (1 + i % 3));
      }
    const ParticleState s = particles(x, q);
    double worst = 0.0;
    for (const double time : {0.0, 0.37e-4, 1.13e-4, 2.9e-4})
    {
      ForceBuffers f = zero_forces(s.size());
      term.add_forces(s, f, time);
      const double u = NipPotentialField::surface_travel(drum, time);
      for (std::size_t m = 0; m < s.size(); ++m)
      {
        const auto E = E_exact(s.x[m], s.y[m], u);
        worst = std::max(worst, std::hypot(f.fx[m] - s.charge[m] * E[0], f.fy[m] - s.charge[m] * E[1]) /
                                  (std::abs(s.charge[m]) * E_scale));
      }
    }
    std::printf("cosine image through the grid and qE (%s in phase, K = %d): max |ΔF|/(|q| E) = %.2e\n",
                term.field().interpolation_name(), K, worst);
    if (phase != NipPotentialField::PhaseInterpolation::linear)
      EXPECT_LT(worst, 2e-5); // the spatial spline alone (h = L/64, O(h³))
    else
    {
      EXPECT_GT(worst, 2e-2);
      EXPECT_LT(worst, 0.09);
    }
  }
}

// The DEM refuses an electric grid computed for other inputs, naming the key; both the image
// and the new phase-sampling key are field inputs.
TEST(ElectricFieldForce, StaleGridIsRefusedNamingTheKey)
{
  const std::string yaml = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kweon_development.yaml";
  const fs::path dir = magbrush::testing::test_temp_dir("electric_stale_grid"); // this process's own
  const Case c = load_case(yaml, {"field.output_dir=" + dir.string()});
  ASSERT_TRUE(c.electric.enabled);
  NipPotentialGrid grid = nip_grid(-1e-3, 1e-3, 6, 0.0, 1e-3, 6, [](double, double) { return 1.0; },
                                   [](double, double, double) { return 0.0; }, 2, 2e-3);
  write_electric_grid(field::electric_grid_path(c), grid, case_provenance(c, FieldKind::electric));
  EXPECT_NO_THROW(NipPotentialField::for_case(c, field::electric_grid_path(c)));
  for (const auto &[key, value] : std::vector<std::pair<std::string, std::string>>{
         {"electric.image.period", "1 mm"}, {"field.electric_phase_samples", "32"}})
  {
    const Case changed = load_case(yaml, {"field.output_dir=" + dir.string(), key + "=" + value});
    try
    {
      NipPotentialField::for_case(changed, field::electric_grid_path(changed));
      ADD_FAILURE() << "a grid computed before " << key << " changed was accepted";
    }
    catch (const ProvenanceMismatch &e)
    {
      EXPECT_EQ(e.differing_key, key);
      EXPECT_NE(std::string(e.what()).find("regenerate"), std::string::npos) << e.what();
    }
  }
  // The drum's speed moves the image but is not a field input.
  const Case faster = load_case(yaml, {"field.output_dir=" + dir.string(), "drum.rpm=-200rpm"});
  EXPECT_NO_THROW(NipPotentialField::for_case(faster, field::electric_grid_path(faster)));
}

// On with an enabled electric section and a charged population; the log's reason otherwise.
TEST(ElectricFieldForce, RuleNamesWhyItIsOff)
{
  const std::string yaml = std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kweon_development.yaml";
  const dem::ForceTermFactory *qE = nullptr;
  const auto factories = dem::force_term_factories();
  for (const auto &f : factories)
    if (f.order == dem::force_term_order::electric_field)
      qE = &f;
  ASSERT_NE(qE, nullptr);
  Case c = load_case(yaml);
  ASSERT_TRUE(c.electric.enabled);
  bool charged = false;
  for (const auto &p : c.populations)
    charged = charged || p.charge_to_mass != 0.0;
  ASSERT_TRUE(charged);
  EXPECT_EQ(qE->not_needed_because(c), "");
  for (auto &p : c.populations)
    p.charge_to_mass = 0.0;
  EXPECT_EQ(qE->not_needed_because(c), "no population is charged");
  c.electric.enabled = false;
  EXPECT_EQ(qE->not_needed_because(c), "the case has no enabled electric section");
}

// Every particle's force is computed alone: 1 and 2 threads give the same bits.
TEST(ElectricFieldForce, OneAndTwoThreadsGiveTheSameBits)
{
  const double L = 400e-6;
  auto field = std::make_shared<const NipPotentialField>(
    nip_grid(-1e-3, 1e-3, 81, 0.0, 4e-4, 21, [](double, double y) { return -650.0 * y / 4e-4; },
             [&](double x, double y, double u) {
               return 120.0 * std::cos(2 * pi * (x - u) / L) * std::exp(-2 * pi * y / L);
             },
             16, L),
    NipPotentialField::PhaseInterpolation::trigonometric);
  ElectricFieldForce term(field, turning_drum(0.27), {0.0, 0.0, 1e-3});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-1.1e-3, 1.1e-3), uy(0.0, 4e-4), uz(-1e-3, 2e-3),
    uq(-3e-15, 3e-15);
  std::vector<std::array<double, 3>> x;
  std::vector<double> q;
  for (int k = 0; k < 3000; ++k)
  {
    x.push_back({ux(rng), uy(rng), uz(rng)});
    q.push_back(k % 5 == 0 ? 0.0 : uq(rng));
  }
  const ParticleState s = particles(x, q);
  const int threads = omp_get_max_threads();
  ForceBuffers f1 = zero_forces(s.size()), f2 = zero_forces(s.size());
  omp_set_num_threads(1);
  term.add_forces(s, f1, 3.3e-4);
  omp_set_num_threads(2);
  term.add_forces(s, f2, 3.3e-4);
  omp_set_num_threads(threads);
  EXPECT_EQ(std::memcmp(f1.fx.data(), f2.fx.data(), s.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(f1.fy.data(), f2.fy.data(), s.size() * sizeof(double)), 0);
  double sum = 0.0;
  for (double v : f1.fx)
    sum += std::abs(v);
  EXPECT_GT(sum, 0.0);
  EXPECT_GT(term.lookups_outside(), 0); // some were placed beyond x = ±1 mm
}
