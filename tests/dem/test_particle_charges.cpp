// The particles' charges (dem/particle_charges.h): toner q = (q/m) m with a spread and a
// wrong-sign fraction, carriers carrying the counter-charge, and charges that change no
// particle's size or place. Statistical checks are stated with their sigma.
#include "dem/dem_system.h"
#include "dem/particle_charges.h"
#include "dem/snapshot_writer.h"

#include "case/case_parser.h"

#include "tests/case_error.h"

#include "tests/test_temp_dir.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <fstream>

#include <cmath>
#include <numeric>
#include <string>

using namespace magbrush;

namespace {
std::string developer(const std::string &toner_extra, const std::string &carrier_extra = "")
{
  return R"(
name: developer
scene: box
materials:
  carrier: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 5000 kg/m^3, friction: 0.45, damping: 0.6}
  toner: {youngs_modulus: 1e3 MPa, poisson_ratio: 0.35, density: 1100 kg/m^3, friction: 0.45, damping: 0.6}
  wall: {youngs_modulus: 5e4 MPa, poisson_ratio: 0.3, friction: 0.35, damping: 0.6}
planes:
  - {name: floor, point: [0 mm, 0 mm, 0 mm], normal: [0, 0, 1], material: wall}
populations:
  - {name: carrier, kind: carrier, material: carrier, diameter: 40 um, diameter_std: 4 um, count: 200, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 1 mm]])" +
         carrier_extra + R"(}
  - {name: toner, kind: toner, material: toner, diameter: 7 um, diameter_std: 1 um, count: 4000, charge_to_mass: -30 uC/g, insert_box: [[0 mm, 0 mm, 0 mm], [1 mm, 1 mm, 1 mm]])" +
         toner_extra + R"(}
dem: {gravity: [0, 0, 0]}
)";
}

dem::ParticleState inserted(const std::string &yaml)
{
  const Case c = parse_case_text(yaml, "developer.yaml");
  dem::DemSystem system(c);
  system.insert_particles();
  return system.particles();
}

double qm_of(const dem::ParticleState &s, std::size_t k) { return s.charge[k] / s.mass[k]; }
} // namespace

TEST(ParticleCharges, TonerWithoutSpreadCarriesExactlyQOverMTimesItsMass)
{
  const auto s = inserted(developer(""));
  std::size_t toner = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s.species[k] == 1)
    {
      ++toner;
      EXPECT_NEAR(qm_of(s, k), -30e-6 / 1e-3, 1e-12 * 0.03);
    }
    else
      EXPECT_EQ(s.charge[k], 0.0); // carriers are neutral unless counter-charged
  EXPECT_EQ(toner, 4000u);
}

TEST(ParticleCharges, SpreadHasTheRequestedMeanAndDeviationAndNeverFlipsTheSign)
{
  // σ = 5 µC/g against a mean of −30 µC/g: the truncation at 0 lies 6σ away, so the sample
  // moments must match the normal distribution's. n = 4000: the mean within 4 standard errors
  // (4 σ/√n), the deviation within 4 × σ/√(2n).
  const auto s = inserted(developer(", charge_to_mass_std: 5 uC/g"));
  double sum = 0, sum2 = 0;
  long n = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s.species[k] == 1)
    {
      const double qm = qm_of(s, k) * 1e3; // C/kg → µC/g
      EXPECT_LT(qm, 0.0);
      sum += qm;
      sum2 += qm * qm;
      ++n;
    }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, -30.0, 4.0 * 5.0 / std::sqrt(double(n)));
  EXPECT_NEAR(sd, 5.0, 4.0 * 5.0 / std::sqrt(2.0 * n));
}

TEST(ParticleCharges, WrongSignFractionIsDrawnPerParticle)
{
  // Binomial(4000, 0.05): 200 ± 13.8; assert within 4 sigma.
  const auto s = inserted(developer(", wrong_sign_fraction: 5 %"));
  long wrong = 0, n = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s.species[k] == 1)
    {
      ++n;
      if (s.charge[k] > 0.0)
      {
        ++wrong;
        EXPECT_NEAR(qm_of(s, k), 30e-6 / 1e-3, 1e-12 * 0.03); // same magnitude, reversed
      }
    }
  const double expected = 0.05 * n, sigma = std::sqrt(n * 0.05 * 0.95);
  EXPECT_NEAR(double(wrong), expected, 4.0 * sigma);
}

TEST(ParticleCharges, CounterChargedCarriersMakeTheDeveloperNeutralSharedBySurfaceArea)
{
  const auto s = inserted(developer(", charge_to_mass_std: 5 uC/g, wrong_sign_fraction: 2 %", ", counter_charge: true"));
  double total = 0, magnitude = 0, toner = 0;
  double per_area = 0;
  bool first = true;
  for (std::size_t k = 0; k < s.size(); ++k)
  {
    total += s.charge[k];
    magnitude += std::abs(s.charge[k]);
    if (s.species[k] == 1)
      toner += s.charge[k];
    else
    {
      const double ratio = s.charge[k] / (s.radius[k] * s.radius[k]);
      if (first)
        per_area = ratio, first = false;
      EXPECT_NEAR(ratio, per_area, 1e-12 * std::abs(per_area));
    }
  }
  EXPECT_LT(toner, 0.0);
  EXPECT_GT(per_area, 0.0); // carriers positive against negative toner
  EXPECT_LE(std::abs(total), 1e-12 * magnitude);
}

TEST(ParticleCharges, ChargesChangeNoParticleSizeOrPlace)
{
  const auto plain = inserted(developer(""));
  const auto charged =
    inserted(developer(", charge_to_mass_std: 5 uC/g, wrong_sign_fraction: 5 %", ", counter_charge: true"));
  ASSERT_EQ(plain.size(), charged.size());
  EXPECT_EQ(plain.x, charged.x);
  EXPECT_EQ(plain.y, charged.y);
  EXPECT_EQ(plain.z, charged.z);
  EXPECT_EQ(plain.radius, charged.radius);
  EXPECT_NE(plain.charge, charged.charge);
}

TEST(ParticleCharges, BadChargeInputIsRefusedWithTheKey)
{
  auto error_of = [](const std::string &yaml) { return magbrush::testing::case_error_of(yaml, "developer.yaml"); };
  // A q/m in the wrong unit names the key and the unit expected.
  std::string yaml = developer("");
  yaml.replace(yaml.find("-30 uC/g"), 8, "-30 uC");
  const std::string unit = error_of(yaml);
  EXPECT_NE(unit.find("charge_to_mass"), std::string::npos) << unit;
  EXPECT_NE(unit.find("developer.yaml"), std::string::npos) << unit;
  // The counter-charge is the carriers'.
  const std::string toner = error_of(developer(", counter_charge: true"));
  EXPECT_NE(toner.find("counter_charge"), std::string::npos) << toner;
  // A fraction beyond 1.
  const std::string fraction = error_of(developer(", wrong_sign_fraction: 1.5"));
  EXPECT_NE(fraction.find("wrong_sign_fraction"), std::string::npos) << fraction;
  // A spread larger than the mean.
  const std::string spread = error_of(developer(", charge_to_mass_std: 40 uC/g"));
  EXPECT_NE(spread.find("charge_to_mass_std"), std::string::npos) << spread;
}

TEST(ParticleCharges, SnapshotsCarryTheChargeForParaView)
{
  const Case c = parse_case_text(developer(", wrong_sign_fraction: 5 %", ", counter_charge: true"), "developer.yaml");
  dem::DemSystem system(c);
  system.insert_particles();
  system.initialize();
  const auto dir = magbrush::testing::test_temp_dir("particle_charges");
  dem::SnapshotWriter(dir.string()).write(system);
  std::vector<std::filesystem::path> files;
  for (const auto &e : std::filesystem::directory_iterator(dir / "snapshots"))
    files.push_back(e.path());
  ASSERT_EQ(files.size(), 1u);
  const hid_t f = H5Fopen(files[0].c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  auto read = [&](const char *name, hid_t type, void *out) {
    const hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    ASSERT_GE(d, 0) << name;
    H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out);
    H5Dclose(d);
  };
  const auto &p = system.particles();
  std::vector<double> q(p.size());
  std::vector<std::int32_t> id(p.size());
  read("charge", H5T_NATIVE_DOUBLE, q.data());
  read("id", H5T_NATIVE_INT32, id.data());
  H5Fclose(f);
  std::vector<double> by_id(p.size());
  for (std::size_t k = 0; k < p.size(); ++k)
    by_id[static_cast<std::size_t>(p.id[k])] = p.charge[k];
  for (std::size_t k = 0; k < p.size(); ++k)
    ASSERT_EQ(q[k], by_id[static_cast<std::size_t>(id[k])]) << "snapshot row " << k;
  std::ifstream x(dir / "particles.xdmf");
  const std::string xdmf((std::istreambuf_iterator<char>(x)), std::istreambuf_iterator<char>());
  EXPECT_NE(xdmf.find("<Attribute Name=\"charge\""), std::string::npos);
  std::filesystem::remove_all(dir);
}
