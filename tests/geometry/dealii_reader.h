// Reads a .msh file with deal.II's GridIn (as the field solver does) and counts what it found.
#pragma once

#include <cstddef>
#include <map>
#include <string>

struct DealiiMeshCounts
{
  std::size_t n_cells = 0;
  std::size_t n_vertices = 0;
  std::map<int, std::size_t> cells_by_material;      // material_id → cells
  std::map<int, double> area_by_material;            // material_id → Σ cell measure
  std::map<int, std::size_t> boundary_faces_by_id;   // boundary_id → faces
  std::size_t n_nonpositive_cells = 0;               // cells with measure ≤ 0
};

DealiiMeshCounts read_msh_with_dealii(const std::string &path);
