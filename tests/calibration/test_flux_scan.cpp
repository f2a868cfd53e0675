// Unit tests of the gaussmeter-scan reader (calibration/flux_scan.h): header names and units,
// comments, separators, angular origin and direction, and every error with its line number.
#include "calibration/flux_scan.h"
#include "tests/calibration/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

using namespace magbrush;
using namespace magbrush::flux_test;

namespace {

FluxScan parse(const std::string &text, ScanReadOptions options = {})
{
  options.min_points = std::min<size_t>(options.min_points, 3);
  std::istringstream in(text);
  return parse_flux_scan(in, "scan.csv", options);
}

// The message of the ScanError thrown by parsing `text` ("" if none).
std::string error_of(const std::string &text, ScanReadOptions options = {})
{
  try
  {
    std::istringstream in(text);
    parse_flux_scan(in, "scan.csv", options);
  }
  catch (const ScanError &e)
  {
    return e.what();
  }
  return "";
}

bool contains(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

} // namespace

TEST(FluxScan, ReadsTheExampleFile)
{
  const FluxScan s = read_flux_scan(example_scan_path());
  ASSERT_EQ(s.size(), 360u);
  EXPECT_TRUE(s.has_tangential());
  EXPECT_EQ(s.angle_unit, "deg");
  EXPECT_EQ(s.field_unit, "mT");
  EXPECT_EQ(s.angle_column, "angle_deg");
  EXPECT_EQ(s.comments.size(), 5u);
  EXPECT_TRUE(s.notes.empty());
  EXPECT_DOUBLE_EQ(s.angle[1], 1.0 * deg);
  EXPECT_DOUBLE_EQ(s.Bn[0], -99.94e-3);
  EXPECT_DOUBLE_EQ(s.Bt[1], -6.83e-3);
  EXPECT_EQ(s.line[0], 7); // 5 comments, the header, then data
}

TEST(FluxScan, UnderstandsHeaderNamesAndUnits)
{
  // Units in brackets, parentheses, after '_' or '/'; other names; gauss and radians.
  const FluxScan a = parse("theta [rad], B_n (G), B_t (G)\n0, 100, 10\n0.5, 200, 20\n1.0, 300, 30\n");
  EXPECT_DOUBLE_EQ(a.angle[1], 0.5);
  EXPECT_DOUBLE_EQ(a.Bn[1], 200e-4);
  EXPECT_DOUBLE_EQ(a.Bt[2], 30e-4);
  const FluxScan b = parse("deg;Br/T;Btheta/T\n10;0.1;0.01\n20;0.2;0.02\n30;0.3;0.03\n");
  EXPECT_DOUBLE_EQ(b.angle[0], 10 * deg);
  EXPECT_DOUBLE_EQ(b.Bn[2], 0.3);
  EXPECT_EQ(b.angle_unit, "deg");
  // Semicolons with decimal commas (a European spreadsheet export).
  const FluxScan e = parse("angle_deg;Bn_mT;Bt_mT\n0,5;-99,94;-0,68\n1,5;-99,52;-6,83\n2,5;-98,85;-13,98\n");
  EXPECT_DOUBLE_EQ(e.angle[1], 1.5 * deg);
  EXPECT_DOUBLE_EQ(e.Bn[0], -99.94e-3);
  // "B_t" is the tangential component, not a column in tesla.
  const FluxScan c = parse("angle_deg,B_n,B_t\n0,1,2\n1,1,2\n2,1,2\n", {"", "mT"});
  EXPECT_EQ(c.bt_column, "B_t");
  EXPECT_DOUBLE_EQ(c.Bt[0], 2e-3);
  // Any column order, extra columns ignored, kilogauss, Bn-only scan.
  const FluxScan d = parse("Bn_kG,temperature_C,angle_deg\n1.2,21,0\n1.3,21,5\n1.1,21,10\n");
  EXPECT_FALSE(d.has_tangential());
  EXPECT_DOUBLE_EQ(d.Bn[1], 0.13);
  EXPECT_DOUBLE_EQ(d.angle[2], 10 * deg);
}

TEST(FluxScan, HeaderlessBlankSeparatedWithComments)
{
  const FluxScan s = parse("# exported by probe X\n\n  0  -99.9  -0.7\n# mid-file comment\n"
                           "  1  -99.5  -6.8\n  2  -98.9  -14.0\n",
                           {"deg", "mT"});
  EXPECT_EQ(s.size(), 3u);
  EXPECT_EQ(s.comments.size(), 2u);
  EXPECT_DOUBLE_EQ(s.Bt[2], -14.0e-3);
  EXPECT_EQ(s.line[2], 6);
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_TRUE(contains(s.notes[0], "no header"));
}

TEST(FluxScan, AssumesAndOverridesUnitsWithNotes)
{
  const FluxScan s = parse("angle,Bn,Bt\n0,50,2\n90,60,2\n180,70,2\n");
  EXPECT_EQ(s.angle_unit, "deg");
  EXPECT_EQ(s.field_unit, "mT");
  EXPECT_EQ(s.notes.size(), 2u);
  const FluxScan t = parse("angle_deg,Bn_G,Bt_G\n0,1,2\n90,1,2\n180,1,2\n", {"", "mT"});
  EXPECT_DOUBLE_EQ(t.Bn[0], 1e-3);
  ASSERT_EQ(t.notes.size(), 1u);
  EXPECT_TRUE(contains(t.notes[0], "overrides"));
}

TEST(FluxScan, AppliesOffsetAndDirection)
{
  ScanReadOptions o;
  o.angle_offset = 10 * deg;
  const FluxScan s = parse("angle_deg,Bn_mT,Bt_mT\n0,1,2\n5,1,2\n10,1,2\n", o);
  EXPECT_NEAR(s.angle[1], 15 * deg, 1e-15);
  o.clockwise = true;
  const FluxScan c = parse("angle_deg,Bn_mT,Bt_mT\n0,1,2\n5,1,2\n10,1,2\n", o);
  EXPECT_NEAR(c.angle[2], 0.0, 1e-15);  // −10° + 10°
  EXPECT_DOUBLE_EQ(c.Bt[0], -2e-3);     // Bt positive counter-clockwise
  EXPECT_DOUBLE_EQ(c.Bn[0], 1e-3);
  // An encoder that wraps at 360° is unwrapped.
  const FluxScan w = parse("angle_deg,Bn_mT\n350,1\n355,1\n0,1\n5,1\n");
  EXPECT_NEAR(w.angle[3], 365 * deg, 1e-12);
  ASSERT_EQ(w.notes.size(), 1u);
  EXPECT_TRUE(contains(w.notes[0], "wraps around at line 4"));
  // A decreasing scan is fine as it stands.
  EXPECT_NO_THROW(parse("angle_deg,Bn_mT\n10,1\n5,1\n0,1\n"));
}

TEST(FluxScan, ErrorsNameTheFileTheLineAndTheFix)
{
  const std::string head = "angle_deg,Bn_mT,Bt_mT\n";
  ScanReadOptions few;
  few.min_points = 3;
  std::string e = error_of(head + "0,1,2\n1,abc,2\n2,1,2\n", few);
  EXPECT_TRUE(contains(e, "scan.csv:3:")) << e;
  EXPECT_TRUE(contains(e, "'abc'")) << e;
  e = error_of(head + "0,1,2\n1,1\n2,1,2\n", few);
  EXPECT_TRUE(contains(e, "scan.csv:3:") && contains(e, "expected 3 columns")) << e;
  e = error_of(head + "0,1,2\n1,nan,2\n2,1,2\n", few);
  EXPECT_TRUE(contains(e, "scan.csv:3:") && contains(e, "finite")) << e;
  e = error_of("angle_deg,Bt_mT\n0,1\n1,1\n2,1\n", few);
  EXPECT_TRUE(contains(e, "scan.csv:1:") && contains(e, "Bn")) << e;
  e = error_of("Bn_mT,Bt_mT\n0,1\n1,1\n2,1\n", few);
  EXPECT_TRUE(contains(e, "no angle column")) << e;
  e = error_of(head + "0,1,2\n2,1,2\n1,1,2\n3,1,2\n", few);
  EXPECT_TRUE(contains(e, "scan.csv:4:") && contains(e, "strictly increasing")) << e;
  e = error_of(head + "0,1,2\n1,1,2\n1,1,2\n", few);
  EXPECT_TRUE(contains(e, "scan.csv:4:")) << e;
  e = error_of("angle_rad,Bn_mT\n0,1\n4,1\n8,1\n", few);
  EXPECT_TRUE(contains(e, "more than one turn") && contains(e, "--angle-unit deg")) << e;
  e = error_of(head + "0,1,2\n1,1,2\n");
  EXPECT_TRUE(contains(e, "2 data points") && contains(e, "at least 8")) << e;
  e = error_of("# only comments\n");
  EXPECT_TRUE(contains(e, "0 data points")) << e;
  e = error_of("angle_deg,Bn_mT,Bt_G\n0,1,2\n1,1,2\n2,1,2\n", few);
  EXPECT_TRUE(contains(e, "same unit")) << e;
  ScanReadOptions grad;
  grad.angle_unit = "grad";
  grad.min_points = 3;
  e = error_of(head + "0,1,2\n1,1,2\n2,1,2\n", grad);
  EXPECT_TRUE(contains(e, "unknown angle unit 'grad'")) << e;
  EXPECT_THROW(read_flux_scan("/nonexistent/scan.csv"), ScanError);
  try
  {
    read_flux_scan("/nonexistent/scan.csv");
  }
  catch (const ScanError &err)
  {
    EXPECT_TRUE(contains(err.what(), "/nonexistent/scan.csv: cannot open"));
  }
}

TEST(FluxScan, PeriodicInterpolationIsThirdOrderAndWraps)
{
  // sin 3θ + cos θ sampled unevenly over one turn, evaluated across the wrap-around.
  auto f = [](double t) { return std::sin(3 * t) + std::cos(t); };
  double previous = 1e300;
  for (int n : {45, 90, 180, 360})
  {
    std::vector<double> x, y;
    for (int k = 0; k < n; ++k)
    {
      const double t = 2 * M_PI * (k + 0.3 * std::sin(k)) / n - 1.0; // uneven, starts at −1 rad
      x.push_back(t);
      y.push_back(f(t));
    }
    std::vector<double> at;
    for (int k = 0; k < 1000; ++k)
      at.push_back(-7.0 + 14.0 * k / 999.0);
    const auto v = interpolate_periodic(x, y, at);
    double err = 0;
    for (size_t k = 0; k < at.size(); ++k)
      err = std::max(err, std::abs(v[k] - f(at[k])));
    std::printf("  %4d samples: max interpolation error %.2e\n", n, err);
    EXPECT_LT(err, previous / 6.0); // at least O(h^2.6); Hermite with 3-point slopes is O(h³)
    previous = err;
  }
  EXPECT_LT(previous, 1e-5);
}

TEST(FluxScan, FlipsTheTangentialSignOnRequest)
{
  ScanReadOptions o;
  o.flip_tangential = true;
  const FluxScan s = parse("angle_deg,Bn_mT,Bt_mT\n0,1,2\n5,1,2\n10,1,2\n", o);
  EXPECT_DOUBLE_EQ(s.Bt[0], -2e-3);
  EXPECT_DOUBLE_EQ(s.Bn[0], 1e-3);
  o.clockwise = true; // both: the two sign flips cancel
  EXPECT_DOUBLE_EQ(parse("angle_deg,Bn_mT,Bt_mT\n0,1,2\n5,1,2\n10,1,2\n", o).Bt[0], 2e-3);
}
