// deal.II's GridIn::read_msh on a magbrush mesh (see dealii_reader.h).
#include "tests/geometry/dealii_reader.h"

#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/tria.h>

#include <fstream>
#include <stdexcept>

DealiiMeshCounts read_msh_with_dealii(const std::string &path)
{
  dealii::Triangulation<2> tria;
  dealii::GridIn<2> grid_in;
  grid_in.attach_triangulation(tria);
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error("cannot open " + path);
  grid_in.read_msh(in);

  DealiiMeshCounts counts;
  counts.n_cells = tria.n_active_cells();
  counts.n_vertices = tria.n_used_vertices();
  for (const auto &cell : tria.active_cell_iterators())
  {
    const int material = cell->material_id();
    ++counts.cells_by_material[material];
    const double measure = cell->measure();
    counts.area_by_material[material] += measure;
    if (!(measure > 0.0))
      ++counts.n_nonpositive_cells;
    for (const auto f : cell->face_indices())
      if (cell->face(f)->at_boundary())
        ++counts.boundary_faces_by_id[cell->face(f)->boundary_id()];
  }
  return counts;
}
