// The roller and nip meshes: physical groups, exact areas, quadrilaterals only with positive
// Jacobians, the photoconductor layer resolved across, sizes graded as asked, the circles and
// shells as documented, the wall primitives in the same place, and clear errors.
#include "geometry/mesh_common.h"
#include "geometry/mesh_nip.h"
#include "geometry/mesh_roller.h"
#include "geometry/mesh_tags.h"
#include "tests/geometry/mesh_test_cases.h"
#include "geometry/wall_primitives.h"

#include <gmsh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

using namespace magbrush;
using magbrush::testing::coarse_nip_case;
using magbrush::testing::coarse_roller_case;
using magbrush::testing::scratch_dir;

namespace {

// One cell as read back from the file through the Gmsh API.
struct Cell
{
  int region;
  std::vector<Vec2> corners;
  Vec2 centroid() const
  {
    Vec2 c{0, 0};
    for (const auto &v : corners)
      c = {c[0] + v[0] / corners.size(), c[1] + v[1] / corners.size()};
    return c;
  }
  double area() const
  {
    double a = 0;
    for (size_t k = 0; k < corners.size(); ++k)
      a += 0.5 * (corners[k][0] * corners[(k + 1) % corners.size()][1] -
                  corners[(k + 1) % corners.size()][0] * corners[k][1]);
    return a;
  }
  bool contains(const Vec2 &p) const
  {
    for (size_t k = 0; k < corners.size(); ++k)
    {
      const Vec2 &a = corners[k], &b = corners[(k + 1) % corners.size()];
      if ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) < 0)
        return false;
    }
    return true;
  }
};

struct ReadBack
{
  std::vector<Cell> cells;
  std::vector<Vec2> nodes;
  std::map<int, std::string> group_names; // (dim * 1000 + tag) → name
};

ReadBack read_back(const std::string &path)
{
  ReadBack r;
  GmshSession session;
  gmsh::open(path);
  std::vector<std::size_t> tags;
  std::vector<double> xyz, par;
  gmsh::model::mesh::getNodes(tags, xyz, par, -1, -1, false, false);
  std::map<std::size_t, Vec2> by_tag;
  for (size_t i = 0; i < tags.size(); ++i)
  {
    by_tag[tags[i]] = {xyz[3 * i], xyz[3 * i + 1]};
    r.nodes.push_back(by_tag[tags[i]]);
  }
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto &[dim, tag] : groups)
  {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    r.group_names[dim * 1000 + tag] = name;
    if (dim != 2)
      continue;
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int e : entities)
    {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> et, nt;
      gmsh::model::mesh::getElements(types, et, nt, 2, e);
      for (size_t t = 0; t < types.size(); ++t)
      {
        const size_t nn = types[t] == 3 ? 4 : 3;
        for (size_t k = 0; k < et[t].size(); ++k)
        {
          Cell cell{tag, {}};
          for (size_t j = 0; j < nn; ++j)
            cell.corners.push_back(by_tag.at(nt[t][nn * k + j]));
          r.cells.push_back(cell);
        }
      }
    }
  }
  return r;
}

double quantile(std::vector<double> v, double q)
{
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * (v.size() - 1))];
}

// Element sizes against the analytic size function the mesh was built from: √(area) / h(x).
std::vector<double> size_ratios(const ReadBack &r, const MeshSizeFunction &h, int region)
{
  std::vector<double> ratios;
  for (const auto &cell : r.cells)
    if (region < 0 || cell.region == region)
      ratios.push_back(std::sqrt(cell.area()) / h(cell.centroid()));
  return ratios;
}

void expect_clean_quads(const MeshSummary &s)
{
  EXPECT_GT(s.n_quads, 0u);
  EXPECT_EQ(s.n_other_cells, 0u) << "deal.II needs quadrilaterals only";
  EXPECT_EQ(s.n_inverted_cells, 0u);
  EXPECT_GT(s.min_quality, 0.3) << "smallest scaled corner Jacobian";
}

void expect_areas_exact(const MeshSummary &s, double tolerance)
{
  for (const auto &r : s.regions)
  {
    ASSERT_GT(r.exact_area, 0.0) << r.name;
    EXPECT_NEAR(r.area / r.exact_area, 1.0, tolerance) << r.name;
    std::printf("  %-14s area %.6e exact %.6e rel %+.2e (%zu cells)\n", r.name.c_str(), r.area, r.exact_area,
                r.area / r.exact_area - 1, r.n_cells);
  }
}

// Nodes of the mesh lying on a circle (relative tolerance 1e-9).
size_t nodes_on(const ReadBack &r, const MeshCircle &c)
{
  size_t n = 0;
  for (const auto &p : r.nodes)
    n += std::abs(std::hypot(p[0] - c.center[0], p[1] - c.center[1]) - c.radius) < 1e-9 * c.radius;
  return n;
}

struct RollerFixture : ::testing::Test
{
  static void SetUpTestSuite()
  {
    c = new Case(coarse_roller_case());
    path = scratch_dir("roller") + "/roller.msh";
    summary = new MeshSummary(write_roller_mesh(*c, path));
    mesh = new ReadBack(read_back(path));
  }
  static void TearDownTestSuite()
  {
    std::filesystem::remove_all(std::filesystem::path(path).parent_path());
    delete c;
    delete summary;
    delete mesh;
  }
  static Case *c;
  static std::string path;
  static MeshSummary *summary;
  static ReadBack *mesh;
};
Case *RollerFixture::c = nullptr;
std::string RollerFixture::path;
MeshSummary *RollerFixture::summary = nullptr;
ReadBack *RollerFixture::mesh = nullptr;

} // namespace

TEST_F(RollerFixture, EveryPhysicalGroupIsThereWithItsTagAndName)
{
  const std::map<int, std::string> expected{{2001, "shaft"},        {2002, "magnet"}, {2003, "sleeve_wall"},
                                            {2004, "air"},          {2005, "shell"},  {2020, "blade:doctor"},
                                            {1001, "outer_boundary"}};
  EXPECT_EQ(mesh->group_names, expected) << "the non-magnetic guide (blade 1) must not be a region";
}

TEST_F(RollerFixture, AllQuadsPositiveJacobian)
{
  expect_clean_quads(*summary);
  for (const auto &cell : mesh->cells)
    ASSERT_EQ(cell.corners.size(), 4u);
}

TEST_F(RollerFixture, RegionAreasMatchTheExactAnnuliAndPolygon)
{
  expect_areas_exact(*summary, 1e-3);
  // The blade is a polygon: straight edges are exact.
  const double blade = std::abs(polygon_signed_area(c->blades[0].polygon));
  EXPECT_NEAR(summary->region("blade:doctor")->area / blade, 1.0, 1e-12);
  const BoundarySummary *outer = summary->boundary("outer_boundary");
  ASSERT_NE(outer, nullptr);
  EXPECT_NEAR(outer->length / outer->exact_length, 1.0, 1e-3);
}

TEST_F(RollerFixture, ShellIsTheDocumentedAnnulus)
{
  const OpenBoundaryShell shell = roller_shell(*c);
  // Enclosed radius: the farthest blade vertex (the doctor blade's corner (0.75, −16.5) mm).
  const double enclosed = std::hypot(0.75e-3, 16.5e-3);
  EXPECT_NEAR(shell.inner_radius, c->field.outer_radius_factor * enclosed, 1e-12);
  EXPECT_NEAR(shell.outer_radius, shell_outer_ratio * shell.inner_radius, 1e-12);
  // Structured: every shell cell spans the same radial step (to the few % by which the split
  // into quads moves mid-arc nodes onto the circle when the subdivision fallback was used).
  double dr_min = 1, dr_max = 0;
  for (const auto &cell : mesh->cells)
    if (cell.region == mesh_tags::shell)
    {
      std::vector<double> r;
      for (const auto &v : cell.corners)
        r.push_back(std::hypot(v[0], v[1]));
      const double dr = *std::max_element(r.begin(), r.end()) - *std::min_element(r.begin(), r.end());
      dr_min = std::min(dr_min, dr), dr_max = std::max(dr_max, dr);
    }
  EXPECT_NEAR(dr_min / dr_max, 1.0, 0.03);
}

TEST_F(RollerFixture, CirclesCarryMeshNodes)
{
  const auto circles = roller_mesh_circles(*c);
  std::vector<std::string> names;
  for (const auto &circle : circles)
  {
    names.push_back(circle.name);
    EXPECT_GE(nodes_on(*mesh, circle), static_cast<size_t>(min_segments_per_circle)) << circle.name;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"shaft_surface", "magnet_surface", "sleeve_inner_surface",
                                             "sleeve_surface", "shell_inner", "shell_outer"}));
  EXPECT_EQ(circles.back().boundary_id, mesh_tags::outer_boundary);
}

TEST_F(RollerFixture, SizesFollowTheGradedSizeFunction)
{
  const MeshSizeFunction h = roller_mesh_size(*c);
  // Unstructured regions: √(cell area) / target size.
  for (int region : {mesh_tags::magnet, mesh_tags::air})
  {
    const auto ratios = size_ratios(*mesh, h, region);
    const double q05 = quantile(ratios, 0.05), q50 = quantile(ratios, 0.5), q95 = quantile(ratios, 0.95);
    std::printf("  region %d: size/target 5%% %.2f  median %.2f  95%% %.2f\n", region, q05, q50, q95);
    EXPECT_GT(q50, 0.6);
    EXPECT_LT(q50, 1.4);
    EXPECT_GT(q05, 0.35);
    EXPECT_LT(q95, 2.0);
  }
  // Next to the sleeve surface (outside, within one target size) the cells are mesh_size_sleeve.
  std::vector<double> near;
  for (const auto &cell : mesh->cells)
  {
    const Vec2 x = cell.centroid();
    const double r = std::hypot(x[0], x[1]);
    if (cell.region == mesh_tags::air && r > c->sleeve->radius && r < c->sleeve->radius + c->field.mesh_size_sleeve)
      near.push_back(std::sqrt(cell.area()) / c->field.mesh_size_sleeve);
  }
  ASSERT_GT(near.size(), 50u);
  EXPECT_GT(quantile(near, 0.5), 0.6);
  EXPECT_LT(quantile(near, 0.5), 1.4);
  // Far away (next to the shell) they have grown to mesh_size_far, within the circle rule.
  std::vector<double> far;
  const double r_in = roller_shell(*c).inner_radius;
  for (const auto &cell : mesh->cells)
  {
    const Vec2 x = cell.centroid();
    if (cell.region == mesh_tags::air && std::hypot(x[0], x[1]) > 0.9 * r_in)
      far.push_back(std::sqrt(cell.area()));
  }
  ASSERT_FALSE(far.empty());
  EXPECT_GT(quantile(far, 0.5), 0.5 * std::min(c->field.mesh_size_far, 2 * M_PI * r_in / min_segments_per_circle));
}

TEST_F(RollerFixture, WallPrimitivesAgreeWithTheMesh)
{
  const WallSet walls = build_wall_primitives(*c);
  const CylinderWall *sleeve = walls.cylinder("sleeve");
  ASSERT_NE(sleeve, nullptr);
  MeshCircle surface;
  for (const auto &circle : roller_mesh_circles(*c))
    if (circle.name == "sleeve_surface")
      surface = circle;
  EXPECT_EQ(sleeve->radius, surface.radius);
  EXPECT_EQ(sleeve->center, surface.center);
  EXPECT_GE(nodes_on(*mesh, {"", sleeve->center, sleeve->radius}), static_cast<size_t>(min_segments_per_circle));
  // The prism of the magnetic blade has the area of its mesh region.
  ASSERT_EQ(walls.prisms.size(), 2u);
  const double prism_area = polygon_signed_area(walls.prisms[0].polygon);
  EXPECT_GT(prism_area, 0.0) << "prisms are counter-clockwise";
  EXPECT_NEAR(summary->region("blade:doctor")->area / prism_area, 1.0, 1e-12);
}

TEST_F(RollerFixture, WritesAtomicallyLeavingNoTemporaryFile)
{
  size_t files = 0;
  for (const auto &e : std::filesystem::directory_iterator(std::filesystem::path(path).parent_path()))
  {
    ++files;
    EXPECT_EQ(e.path().filename(), "roller.msh");
  }
  EXPECT_EQ(files, 1u);
  // The summary read back from the file equals the one written.
  const MeshSummary again = read_mesh_summary(path);
  EXPECT_EQ(again.n_quads, summary->n_quads);
  EXPECT_EQ(again.n_nodes, summary->n_nodes);
}

TEST(RollerMesh, WithoutShaftAndWithMagnetTouchingTheSleeve)
{
  Case c = coarse_roller_case();
  c.roller->shaft_radius = 0.0;
  c.roller->magnet_radius = c.sleeve->radius - c.sleeve->thickness;
  c.blades.clear();
  const MeshSummary s = write_roller_mesh(c, scratch_dir("roller_plain") + "/roller.msh");
  expect_clean_quads(s);
  EXPECT_EQ(s.region("shaft"), nullptr);
  expect_areas_exact(s, 1e-3);
}

TEST(RollerMesh, BadGeometryIsRefusedWithAMessage)
{
  Case c = coarse_roller_case();
  c.blades[0].polygon = {{-0.75e-3, -9.5e-3}, {-0.75e-3, -16.5e-3}, {0.75e-3, -16.5e-3}, {0.75e-3, -9.5e-3}};
  try
  {
    write_roller_mesh(c, scratch_dir("roller_bad") + "/roller.msh");
    FAIL() << "a magnetic blade cutting the sleeve must be refused";
  }
  catch (const std::invalid_argument &e)
  {
    EXPECT_NE(std::string(e.what()).find("doctor"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("sleeve"), std::string::npos) << e.what();
  }
  Case d = coarse_roller_case();
  d.field.outer_radius_factor = 1.0;
  EXPECT_THROW(roller_mesh_geometry(d), std::invalid_argument);
  Case e = coarse_roller_case();
  e.roller.reset();
  EXPECT_THROW(write_roller_mesh(e, scratch_dir("roller_none") + "/roller.msh"), std::invalid_argument);
}

// ---- nip ------------------------------------------------------------------------------------

TEST(NipMesh, WithPhotoconductorLayer)
{
  const Case c = coarse_nip_case(20e-6);
  const std::string path = scratch_dir("nip_layer") + "/nip.msh";
  const MeshSummary s = write_nip_mesh(c, path);
  expect_clean_quads(s);
  expect_areas_exact(s, 1e-3);
  const ReadBack mesh = read_back(path);
  const std::map<int, std::string> expected{{2004, "air"}, {2005, "shell"}, {2006, "photoconductor"},
                                            {1001, "outer_boundary"}, {1002, "sleeve_surface"},
                                            {1003, "drum_substrate"}};
  EXPECT_EQ(mesh.group_names, expected);
  for (const auto &b : s.boundaries)
    EXPECT_NEAR(b.length / b.exact_length, 1.0, 1e-3) << b.name;

  // Through the layer on the line of centres (the middle of the gap) there are ≥ 3 cells.
  const NipMeshGeometry g = nip_mesh_geometry(c);
  EXPECT_GE(g.layer_cells_across, 3);
  std::set<const Cell *> hit;
  for (int k = 0; k < 200; ++k)
  {
    const double r = g.drum_radius - g.pc_thickness * (k + 0.5) / 200;
    const Vec2 p{g.drum_center[0] - r * g.nip_direction[0], g.drum_center[1] - r * g.nip_direction[1]};
    for (const auto &cell : mesh.cells)
      if (cell.region == mesh_tags::photoconductor && cell.contains(p))
        hit.insert(&cell);
  }
  std::printf("  photoconductor cells across the layer at the nip: %zu\n", hit.size());
  EXPECT_GE(hit.size(), 3u);

  // In the gap the cells are mesh_size_gap; the air follows the graded size function.
  std::vector<double> gap;
  for (const auto &cell : mesh.cells)
  {
    const Vec2 x = cell.centroid();
    if (cell.region == mesh_tags::air &&
        std::hypot(x[0] - g.nip_midpoint[0], x[1] - g.nip_midpoint[1]) < 0.5 * g.gap)
      gap.push_back(std::sqrt(cell.area()) / c.field.mesh_size_gap);
  }
  ASSERT_GT(gap.size(), 10u);
  std::printf("  gap cells: %zu, size/mesh_size_gap median %.2f\n", gap.size(), quantile(gap, 0.5));
  EXPECT_GT(quantile(gap, 0.5), 0.6);
  EXPECT_LT(quantile(gap, 0.5), 1.4);
  const auto ratios = size_ratios(mesh, nip_mesh_size(c), mesh_tags::air);
  std::printf("  air: size/target 5%% %.2f median %.2f 95%% %.2f\n", quantile(ratios, 0.05),
              quantile(ratios, 0.5), quantile(ratios, 0.95));
  EXPECT_GT(quantile(ratios, 0.5), 0.6);
  EXPECT_LT(quantile(ratios, 0.5), 1.4);
  EXPECT_LT(quantile(ratios, 0.95), 2.0);
}

TEST(NipMesh, BareDrumIsTheGroundedElectrode)
{
  const Case c = coarse_nip_case(0.0);
  const std::string path = scratch_dir("nip_bare") + "/nip.msh";
  const MeshSummary s = write_nip_mesh(c, path);
  expect_clean_quads(s);
  expect_areas_exact(s, 1e-3);
  EXPECT_EQ(s.region("photoconductor"), nullptr);
  const BoundarySummary *drum = s.boundary("drum_substrate");
  ASSERT_NE(drum, nullptr);
  EXPECT_NEAR(drum->length / (2 * M_PI * c.drum.radius), 1.0, 1e-3);
}

TEST(NipMesh, ShellCirclesAndWallsAgree)
{
  const Case c = coarse_nip_case(20e-6);
  const NipMeshGeometry g = nip_mesh_geometry(c);
  // The shell encloses the sleeve and the drum with the factor's margin.
  const double enclosing = 0.5 * (2 * c.sleeve->radius + c.drum.gap + 2 * c.drum.radius);
  EXPECT_NEAR(g.shell.inner_radius, c.field.outer_radius_factor * enclosing, 1e-15);
  EXPECT_NEAR(g.shell.outer_radius, shell_outer_ratio * g.shell.inner_radius, 1e-15);
  for (const Vec2 &centre : {Vec2{0.0, 0.0}, g.drum_center})
  {
    const double r = centre == g.drum_center ? g.drum_radius : g.sleeve_radius;
    EXPECT_LT(std::hypot(centre[0] - g.shell.center[0], centre[1] - g.shell.center[1]) + r,
              enclosing * (1 + 1e-12));
  }
  // The DEM's drum cylinder is where the mesh's drum surface is.
  const WallSet walls = build_wall_primitives(c);
  const CylinderWall *drum = walls.cylinder("drum");
  ASSERT_NE(drum, nullptr);
  bool found = false;
  for (const auto &circle : nip_mesh_circles(c))
    if (circle.name == "drum_surface")
    {
      found = true;
      EXPECT_NEAR(circle.center[0], drum->center[0], 1e-15);
      EXPECT_NEAR(circle.center[1], drum->center[1], 1e-15);
      EXPECT_EQ(circle.radius, drum->radius);
    }
  EXPECT_TRUE(found);
  EXPECT_NEAR(std::hypot(drum->center[0], drum->center[1]), c.sleeve->radius + c.drum.gap + c.drum.radius, 1e-15);
}

TEST(NipMesh, MissingDrumIsRefused)
{
  Case c = coarse_nip_case(0.0);
  c.drum.present = false;
  EXPECT_THROW(write_nip_mesh(c, scratch_dir("nip_none") + "/nip.msh"), std::invalid_argument);
  Case d = coarse_nip_case(0.0);
  d.drum.gap = 0.0;
  EXPECT_THROW(nip_mesh_geometry(d), std::invalid_argument);
}

TEST(MeshSize, GradedDivisionReproducesALinearRamp)
{
  // From 1 to 10 over 50: the exact geometric series has r = (50 − 1)/(50 − 10) = 1.225 and
  // n = 1 + ln 10 / ln r; the integer division must end within a few % of both sizes.
  const Progression p = graded_division(50.0, 1.0, 10.0);
  double sum = 0, h = 1.0, last = 0;
  for (int k = 0; k < p.segments; ++k, h *= p.ratio)
    sum += h, last = h;
  EXPECT_NEAR(p.ratio, 1.225, 0.02);
  EXPECT_NEAR(last, 10.0, 0.5);
  EXPECT_NEAR(sum / 50.0, 1.0, 0.05);
  EXPECT_EQ(graded_division(10.0, 1.0, 1.0).segments, 10);
  MeshSizeFunction f(1.0, 0.5);
  f.add_annulus({0, 0}, 1.0, 2.0, 0.1);
  EXPECT_DOUBLE_EQ(f({1.5, 0.0}), 0.1);
  EXPECT_DOUBLE_EQ(f({3.0, 0.0}), 0.6);
  EXPECT_DOUBLE_EQ(f({10.0, 0.0}), 1.0);
}
