// The per-particle lookups allocate nothing (the DEM calls them millions of times per step
// from many threads): counted by replacing the global operator new in this test program.
#include "fields/applied_magnetic_field.h"
#include "fields/cartesian_field_interpolator.h"
#include "fields/nip_potential_field.h"
#include "tests/fields/exact_multipole.h"
#include "fields/polar_field_interpolator.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> allocations{0};
}

void *operator new(std::size_t size)
{
  ++allocations;
  if (void *p = std::malloc(size ? size : 1))
    return p;
  throw std::bad_alloc();
}
void operator delete(void *p) noexcept { std::free(p); }
void operator delete(void *p, std::size_t) noexcept { std::free(p); }

using namespace magbrush;

TEST(FieldLookups, DoNotAllocate)
{
  const auto exact = magbrush::testing::roller_like_field();
  auto polar = std::make_shared<const PolarFieldInterpolator>(sample_polar_grid(
      12.5e-3, 16e-3, 36, 720, [&](double x, double y) { return exact.A(x, y); }));
  const CartesianFieldInterpolator electric(
      sample_cartesian_grid(-1e-3, 1e-3, 21, 0.0, 4e-4, 9, [](double x, double y) { return x * y; }));
  // The nip field at a moving image phase: weights filled per step, lookups per particle.
  NipPotentialGrid nip;
  nip.bias = sample_cartesian_grid(-1e-3, 1e-3, 21, 0.0, 4e-4, 9, [](double x, double y) { return x * y; });
  nip.image_period = 0.5e-3;
  nip.drum_center = {0.0, 15e-3};
  nip.drum_radius = 15e-3;
  for (int k = 0; k < 4; ++k)
    nip.image.push_back(sample_cartesian_grid(-1e-3, 1e-3, 21, 0.0, 4e-4, 9, [k](double x, double y) {
                          return std::cos(1e4 * x + k) * (1.0 - 1e3 * y);
                        }).phi);
  std::vector<NipPotentialField> nip_fields;
  for (const auto phase : {NipPotentialField::PhaseInterpolation::linear,
                           NipPotentialField::PhaseInterpolation::trigonometric,
                           NipPotentialField::PhaseInterpolation::co_moving})
    nip_fields.emplace_back(nip, phase);
  auto weights = nip_fields[0].make_phase_weights();
  const auto roller = AppliedMagneticField::roller(polar, 1e-3);
  const auto uniform = AppliedMagneticField::uniform({0, 0, 1}, 0.13, 1e-3);
  const auto points = magbrush::testing::sample_annulus(12.5e-3, 20e-3, 1000); // grid and tail

  double sum = 0.0;
  const long before = allocations.load();
  for (const auto &p : points)
  {
    const Vec3 x{p[0], p[1], 0.0};
    Vec3 B, E;
    std::array<Vec3, 3> g;
    polar->evaluate(x, B, g);
    sum += B[0] + g[0][1];
    roller.evaluate(x, 5e-4, B, g);
    sum += B[1];
    uniform.evaluate(x, 5e-4, B, g);
    sum += B[2];
    electric.evaluate({p[0] * 0.1, p[1] * 0.01, 0.0}, E);
    sum += E[0];
    for (const auto &f : nip_fields)
    {
      f.phase_weights(p[0] * 0.03, weights);
      f.evaluate({p[0] * 0.1, p[1] * 0.01, 0.0}, weights, E);
      sum += E[1];
    }
  }
  EXPECT_EQ(allocations.load() - before, 0);
  EXPECT_TRUE(std::isfinite(sum));
  // The counter does count (a control, so that the zero above means something).
  const long control = allocations.load();
  auto *probe = new std::vector<double>(3);
  EXPECT_EQ(allocations.load() - control, 2);
  delete probe;
}
