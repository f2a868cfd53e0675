// The DEM's applied field: the uniform shortcut (with its ramp) is exact and has no gradient;
// the roller kind is the grid interpolator, scaled by the same ramp.
#include "fields/applied_magnetic_field.h"
#include "tests/fields/exact_multipole.h"
#include "fields/field_grid.h"

#include <filesystem>
#include <unistd.h>

#include <gtest/gtest.h>
#include "tests/test_temp_dir.h"

using namespace magbrush;

TEST(AppliedMagneticField, UniformFieldWithRampIsExact)
{
  // Kawamoto's compression test: along z, ramping to 130 mT over 1 ms.
  const auto f = AppliedMagneticField::uniform({0, 0, 2.0}, 0.130, 1e-3);
  EXPECT_EQ(f.kind(), AppliedMagneticField::Kind::uniform);
  EXPECT_FALSE(f.has_gradient());
  for (double t : {-1.0, 0.0, 0.25e-3, 0.5e-3, 1e-3, 5.0})
  {
    Vec3 B;
    std::array<Vec3, 3> g;
    f.evaluate({1.0, -2.0, 3.0}, t, B, g);
    const double s = t <= 0 ? 0.0 : std::min(1.0, t / 1e-3);
    EXPECT_EQ(B[0], 0.0);
    EXPECT_EQ(B[1], 0.0);
    EXPECT_DOUBLE_EQ(B[2], 0.130 * s) << "t = " << t;
    for (const auto &row : g)
      EXPECT_EQ(row, (Vec3{0, 0, 0}));
  }
  // An oblique direction is normalised.
  const auto oblique = AppliedMagneticField::uniform({3, 4, 0}, 0.1);
  const Vec3 B = oblique.field({0, 0, 0}, 0.0);
  EXPECT_DOUBLE_EQ(B[0], 0.06);
  EXPECT_DOUBLE_EQ(B[1], 0.08);
}

TEST(AppliedMagneticField, NoneIsZeroAndBadSettingsAreRefused)
{
  const AppliedMagneticField none;
  EXPECT_EQ(none.kind(), AppliedMagneticField::Kind::none);
  EXPECT_EQ(none.field({1, 2, 3}, 1.0), (Vec3{0, 0, 0}));
  EXPECT_THROW(AppliedMagneticField::uniform({0, 0, 0}, 0.1), std::invalid_argument);
  EXPECT_THROW(AppliedMagneticField::uniform({0, 0, 1}, 0.1, -1.0), std::invalid_argument);
  EXPECT_THROW(AppliedMagneticField::roller(nullptr), std::invalid_argument);
  AppliedField settings;
  settings.kind = AppliedField::Kind::roller;
  EXPECT_THROW(AppliedMagneticField::from_settings(settings), std::invalid_argument);
}

TEST(AppliedMagneticField, FromCaseSettings)
{
  AppliedField settings;
  settings.kind = AppliedField::Kind::uniform;
  settings.uniform_direction = {0, 0, 1};
  settings.uniform_magnitude = 0.05;
  settings.ramp_time = 2e-3;
  const auto f = AppliedMagneticField::from_settings(settings);
  EXPECT_DOUBLE_EQ(f.field({0, 0, 0}, 1e-3)[2], 0.025);
  settings.kind = AppliedField::Kind::none;
  EXPECT_EQ(AppliedMagneticField::from_settings(settings).kind(), AppliedMagneticField::Kind::none);
}

// Roller kind: exactly what the interpolator gives, times the ramp; the plain-array overload
// (for the magnetics callback) agrees with the Vec3 one.
TEST(AppliedMagneticField, RollerKindIsTheGridInterpolatorTimesTheRamp)
{
  const auto exact = magbrush::testing::roller_like_field();
  auto grid = std::make_shared<const PolarFieldInterpolator>(sample_polar_grid(
      12.5e-3, 16e-3, 36, 720, [&](double x, double y) { return exact.A(x, y); }));
  const auto f = AppliedMagneticField::roller(grid, 1e-3);
  EXPECT_TRUE(f.has_gradient());
  const Vec3 x{0.0, 13e-3, 5e-4};
  Vec3 B0, B;
  std::array<Vec3, 3> g0, g;
  grid->evaluate(x, B0, g0);
  f.evaluate(x, 0.4e-3, B, g);
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_DOUBLE_EQ(B[i], 0.4 * B0[i]);
    for (int j = 0; j < 3; ++j)
      EXPECT_DOUBLE_EQ(g[i][j], 0.4 * g0[i][j]);
  }
  double Ba[3], ga[3][3];
  const double xa[3] = {x[0], x[1], x[2]};
  f.evaluate(xa, 2e-3, Ba, ga);
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_EQ(Ba[i], B0[i]);
    for (int j = 0; j < 3; ++j)
      EXPECT_EQ(ga[i][j], g0[i][j]);
  }
  EXPECT_THROW(f.field({0, 1e-3, 0}, 1.0), FieldLookupError);
  Vec3 Bt;
  std::array<Vec3, 3> gt;
  EXPECT_FALSE(f.try_evaluate({0, 1e-3, 0}, 1.0, Bt, gt));
  EXPECT_EQ(Bt, (Vec3{0, 0, 0}));
  ASSERT_TRUE(f.try_evaluate(x, 0.4e-3, Bt, gt));
  EXPECT_EQ(Bt, B);
  EXPECT_EQ(gt, g);
}

// The DEM's entry point: a roller case reads its grid and checks its provenance; a case whose
// roller changed since the field was computed is refused with the key.
TEST(AppliedMagneticField, ForCaseReadsTheGridAndChecksProvenance)
{
  namespace fs = std::filesystem;
  const fs::path dir = magbrush::testing::test_temp_dir("applied");
  Case c;
  c.name = "t";
  c.sleeve = Sleeve{};
  c.sleeve->radius = 12.5e-3;
  c.roller = Roller{};
  c.roller->magnet_radius = 11e-3;
  c.roller->poles = {{"N1", 0.5, 150e3, 10.0}};
  c.applied_field.kind = AppliedField::Kind::roller;
  const auto exact = magbrush::testing::roller_like_field();
  const PolarGrid grid = sample_polar_grid(12.5e-3, 16e-3, 36, 720,
                                           [&](double x, double y) { return exact.A(x, y); });
  const std::string path = (dir / "t_magnetic.h5").string();
  write_magnetic_grid(path, grid, case_provenance(c, FieldKind::magnetic));

  const auto f = AppliedMagneticField::for_case(c, path);
  EXPECT_EQ(f.kind(), AppliedMagneticField::Kind::roller);
  const Vec3 B = f.field({0, 13e-3, 0}, 0.0);
  const auto e = exact.B(0, 13e-3);
  EXPECT_NEAR(B[0], e.B[0], 1e-4 * std::hypot(e.B[0], e.B[1]));
  EXPECT_NEAR(B[1], e.B[1], 1e-4 * std::hypot(e.B[0], e.B[1]));

  c.roller->poles[0].strength = 160e3;
  EXPECT_THROW(AppliedMagneticField::for_case(c, path), ProvenanceMismatch);
  EXPECT_THROW(AppliedMagneticField::for_case(c, (dir / "missing.h5").string()), FieldGridError);
  c.applied_field.kind = AppliedField::Kind::uniform; // no grid needed
  c.applied_field.uniform_magnitude = 0.1;
  EXPECT_EQ(AppliedMagneticField::for_case(c, "unused").kind(), AppliedMagneticField::Kind::uniform);
  fs::remove_all(dir);
}
