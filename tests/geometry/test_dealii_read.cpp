// The meshes as the field solver sees them: deal.II 9.4's GridIn::read_msh reads both, every
// cell a quadrilateral of positive measure, material ids = region tags with the cell counts
// and areas Gmsh wrote, boundary ids = boundary tags on every boundary face.
#include "tests/geometry/dealii_reader.h"
#include "geometry/mesh_nip.h"
#include "geometry/mesh_roller.h"
#include "geometry/mesh_tags.h"
#include "tests/geometry/mesh_test_cases.h"

#include <gtest/gtest.h>

using namespace magbrush;

namespace {
void expect_dealii_sees_the_summary(const MeshSummary &s, const std::map<int, std::size_t> &expected_boundary_ids)
{
  const DealiiMeshCounts d = read_msh_with_dealii(s.path);
  EXPECT_EQ(d.n_cells, s.n_quads);
  EXPECT_EQ(d.n_nonpositive_cells, 0u);
  EXPECT_EQ(d.cells_by_material.size(), s.regions.size());
  for (const auto &r : s.regions)
  {
    EXPECT_EQ(d.cells_by_material.count(r.tag), 1u) << r.name;
    EXPECT_EQ(d.cells_by_material.at(r.tag), r.n_cells) << r.name;
    EXPECT_NEAR(d.area_by_material.at(r.tag) / r.exact_area, 1.0, 1e-3) << r.name;
  }
  // Every boundary face carries one of the boundary tags, as many faces as Gmsh wrote.
  EXPECT_EQ(d.boundary_faces_by_id.size(), expected_boundary_ids.size());
  for (const auto &[id, faces] : expected_boundary_ids)
  {
    ASSERT_EQ(d.boundary_faces_by_id.count(id), 1u) << "boundary id " << id;
    EXPECT_EQ(d.boundary_faces_by_id.at(id), faces) << "boundary id " << id;
  }
  std::printf("  %s: deal.II read %zu cells, %zu vertices\n", s.path.c_str(), d.n_cells, d.n_vertices);
}

std::map<int, std::size_t> faces_by_tag(const MeshSummary &s)
{
  std::map<int, std::size_t> m;
  for (const auto &b : s.boundaries)
    m[b.tag] = b.n_faces;
  return m;
}
} // namespace

TEST(DealiiReadsTheMeshes, Roller)
{
  const Case c = magbrush::testing::coarse_roller_case();
  const MeshSummary s = write_roller_mesh(c, magbrush::testing::scratch_dir("dealii_roller") + "/roller.msh");
  ASSERT_NE(s.region("blade:doctor"), nullptr);
  EXPECT_EQ(s.region("blade:doctor")->tag, mesh_tags::blade_base + 0);
  expect_dealii_sees_the_summary(s, faces_by_tag(s));
  EXPECT_EQ(faces_by_tag(s).count(mesh_tags::outer_boundary), 1u);
}

TEST(DealiiReadsTheMeshes, NipWithLayer)
{
  const Case c = magbrush::testing::coarse_nip_case(20e-6);
  const MeshSummary s = write_nip_mesh(c, magbrush::testing::scratch_dir("dealii_nip") + "/nip.msh");
  const auto faces = faces_by_tag(s);
  for (int id : {mesh_tags::outer_boundary, mesh_tags::sleeve_surface, mesh_tags::drum_substrate})
    EXPECT_EQ(faces.count(id), 1u) << id;
  expect_dealii_sees_the_summary(s, faces);
}

TEST(DealiiReadsTheMeshes, BareNip)
{
  const Case c = magbrush::testing::coarse_nip_case(0.0);
  const MeshSummary s = write_nip_mesh(c, magbrush::testing::scratch_dir("dealii_nip_bare") + "/nip.msh");
  expect_dealii_sees_the_summary(s, faces_by_tag(s));
}
