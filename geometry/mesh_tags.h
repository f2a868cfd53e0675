// The fixed numeric tags of the roller and nip meshes: the contract between geometry/ and
// the field solver.
//
// Gmsh writes each region (a physical group of surfaces) and each boundary (a physical group
// of curves) under a numeric tag and a name. deal.II's GridIn::read_msh turns the region tag
// of a cell into its material_id and the tag of a boundary line into the boundary_id of that
// face. Both ids are unsigned chars in practice (< 255), so the tags are small and fixed here,
// never chosen at run time, so that the solver can switch on them.
//
// Only true domain boundaries carry a boundary tag: an interior interface (magnet surface,
// sleeve wall, photoconductor surface) cannot carry a boundary_id in deal.II. The solver finds
// those faces geometrically from the circle list (mesh_common.h: MeshCircle).
//
// The same physical meaning has the same tag in both meshes (air is 4, the open-boundary shell
// is 5, the outer boundary is 1), so a solver never needs to know which mesh it reads.
#pragma once

#include <string>

namespace magbrush::mesh_tags {

// ---- regions (cell material_id) ------------------------------------------------------------
constexpr int shaft = 1;          // roller: soft-iron shaft disk r < R_shaft (mu_r = shaft_mu_r)
constexpr int magnet = 2;         // roller: magnet annulus R_shaft < r < R_magnet (carries M)
constexpr int sleeve_wall = 3;    // roller: non-magnetic sleeve wall R_sleeve - t < r < R_sleeve
constexpr int air = 4;            // both: air (roller: the magnet-sleeve gap and the outside)
constexpr int shell = 5;          // both: the open-boundary shell annulus R_in < r < R_out
constexpr int photoconductor = 6; // nip: photoconductor layer R_drum - t_pc < |x - c_drum| < R_drum
// roller: a soft-magnetic blade or guide (mu_r > 1) is region blade_base + its index in
// Case::blades, so the solver reads its mu_r from c.blades[material_id - blade_base].
// Non-magnetic blades are not meshed (they are air for the field).
constexpr int blade_base = 20;
constexpr int max_blades = 200;   // blade_base + index stays below 255

// ---- boundaries (face boundary_id) ---------------------------------------------------------
constexpr int outer_boundary = 1; // both: the outer circle of the shell (r = R_out, "infinity")
constexpr int sleeve_surface = 2; // nip: the sleeve surface, electrode at V_bias
constexpr int drum_substrate = 3; // nip: the grounded drum substrate (r = R_drum - t_pc; the
                                  //      drum surface itself when t_pc = 0)

// ---- names of the physical groups ----------------------------------------------------------
inline std::string region_name(int tag)
{
  switch (tag)
  {
    case shaft: return "shaft";
    case magnet: return "magnet";
    case sleeve_wall: return "sleeve_wall";
    case air: return "air";
    case shell: return "shell";
    case photoconductor: return "photoconductor";
    default: return tag >= blade_base && tag < blade_base + max_blades
                        ? "blade_" + std::to_string(tag - blade_base)
                        : "region_" + std::to_string(tag);
  }
}

inline std::string boundary_name(int tag)
{
  switch (tag)
  {
    case outer_boundary: return "outer_boundary";
    case sleeve_surface: return "sleeve_surface";
    case drum_substrate: return "drum_substrate";
    default: return "boundary_" + std::to_string(tag);
  }
}

// The physical-group name of a magnetic blade: "blade:" + its name in the case.
inline std::string blade_region_name(const std::string &blade_name) { return "blade:" + blade_name; }

} // namespace magbrush::mesh_tags
