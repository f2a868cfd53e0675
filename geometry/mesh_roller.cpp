// The roller mesh (see mesh_roller.h): concentric layers, embedded magnetic blades, a
// structured open-boundary shell, quadrilaterals only.
#include "geometry/mesh_roller.h"

#include "geometry/mesh_tags.h"
#include "geometry/wall_primitives.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace magbrush {

namespace geo = gmsh::model::geo;

namespace {

std::string mm(double x) { return std::to_string(x * 1e3) + " mm"; }

// One concentric layer r_in < r < r_out of the roller and its region tag.
struct Layer
{
  double r_in, r_out;
  int tag;
};

// The concentric layers inside the sleeve surface, innermost first, empty ones left out
// (no shaft, a magnet touching the sleeve, a sleeve of zero thickness).
std::vector<Layer> concentric_layers(const RollerMeshGeometry &g)
{
  const std::vector<Layer> all{{0.0, g.shaft_radius, mesh_tags::shaft},
                               {g.shaft_radius, g.magnet_radius, mesh_tags::magnet},
                               {g.magnet_radius, g.sleeve_inner_radius, mesh_tags::air},
                               {g.sleeve_inner_radius, g.sleeve_radius, mesh_tags::sleeve_wall}};
  std::vector<Layer> layers;
  for (const auto &l : all)
    if (l.r_out - l.r_in > 1e-9 * g.sleeve_radius)
      layers.push_back(l);
  return layers;
}

std::string circle_name(double r, const RollerMeshGeometry &g)
{
  if (r == g.shaft_radius)
    return "shaft_surface";
  if (r == g.magnet_radius)
    return "magnet_surface";
  if (r == g.sleeve_radius)
    return "sleeve_surface";
  return "sleeve_inner_surface";
}

// Structured division of the shell: 4 quarter sectors with the size the size function asks
// for at R_in (and at least a quarter of the minimum chords per circle), and square cells.
struct ShellDivision
{
  int segments_per_quarter;
  int layers;
};

ShellDivision shell_division(const OpenBoundaryShell &shell, double size_at_inner)
{
  const double quarter = 0.5 * M_PI * shell.inner_radius;
  const int segments = std::max(min_segments_per_circle / 4, static_cast<int>(std::ceil(quarter / size_at_inner)));
  const double h = quarter / segments;
  const int layers = std::max(4, static_cast<int>(std::lround((shell.outer_radius - shell.inner_radius) / h)));
  return {segments, layers};
}

} // namespace

RollerMeshGeometry roller_mesh_geometry(const Case &c)
{
  if (!c.roller || !c.sleeve)
    throw std::invalid_argument("roller mesh: the case has no " + std::string(!c.roller ? "roller" : "sleeve") +
                                " section; the roller mesh needs both (scene '" + c.scene + "')");
  const Roller &r = *c.roller;
  const Sleeve &s = *c.sleeve;
  RollerMeshGeometry g;
  g.shaft_radius = r.shaft_radius;
  g.magnet_radius = r.magnet_radius;
  g.sleeve_radius = s.radius;
  g.sleeve_inner_radius = s.radius - s.thickness;
  if (!(r.shaft_radius >= 0.0 && r.shaft_radius < r.magnet_radius))
    throw std::invalid_argument("roller mesh: roller.shaft_radius (" + mm(r.shaft_radius) +
                                ") must be ≥ 0 and smaller than roller.magnet_radius (" + mm(r.magnet_radius) + ")");
  if (!(s.thickness >= 0.0 && r.magnet_radius <= g.sleeve_inner_radius * (1.0 + 1e-12)))
    throw std::invalid_argument("roller mesh: the magnet (roller.magnet_radius = " + mm(r.magnet_radius) +
                                ") must fit inside the sleeve bore (sleeve radius − thickness = " +
                                mm(g.sleeve_inner_radius) + ")");
  g.magnet_radius = std::min(g.magnet_radius, g.sleeve_inner_radius);

  const FieldSettings &f = c.field;
  if (!(f.mesh_size_sleeve > 0.0 && f.mesh_size_far >= f.mesh_size_sleeve))
    throw std::invalid_argument("roller mesh: need 0 < field.mesh_size_sleeve (" + mm(f.mesh_size_sleeve) +
                                ") ≤ field.mesh_size_far (" + mm(f.mesh_size_far) + ")");
  if (!(f.outer_radius_factor > 1.0))
    throw std::invalid_argument("roller mesh: field.outer_radius_factor must be > 1 (the open-boundary "
                                "shell starts at this multiple of the sleeve radius), found " +
                                std::to_string(f.outer_radius_factor));
  // The fine band: from inside the magnet (as deep as the magnet is below the sleeve surface,
  // at least 1 mm) to the outer edge of the DEM field grid (sleeve + 3 mm by default).
  g.fine_band_inner = std::max(0.0, g.magnet_radius - std::max(g.sleeve_radius - g.magnet_radius, 1e-3));
  g.fine_band_outer = f.grid_outer_radius > 0.0 ? f.grid_outer_radius : g.sleeve_radius + 3e-3;

  // Everything that must lie in the physical (untransformed) region: the sleeve, the DEM
  // band, every blade and guide.
  double enclosed = std::max(g.sleeve_radius, g.fine_band_outer);
  for (const auto &b : c.blades)
    for (const auto &v : b.polygon)
      enclosed = std::max(enclosed, std::hypot(v[0], v[1]));
  g.shell = {{0.0, 0.0}, f.outer_radius_factor * enclosed, shell_outer_ratio * f.outer_radius_factor * enclosed};

  for (std::size_t i = 0; i < c.blades.size(); ++i)
  {
    const BladeOrGuide &b = c.blades[i];
    if (b.mu_r <= 1.0)
      continue; // non-magnetic: air for the field
    if (b.polygon.size() < 3 || !polygon_is_simple(b.polygon) || polygon_signed_area(b.polygon) == 0.0)
      throw std::invalid_argument("roller mesh: blade '" + b.name +
                                  "': its polygon must have ≥ 3 vertices, an area, and not cross itself");
    const double clearance = point_in_polygon({0.0, 0.0}, b.polygon)
                                 ? -1.0
                                 : distance_to_polygon_boundary({0.0, 0.0}, b.polygon) - g.sleeve_radius;
    if (!(clearance > 1e-9 * g.sleeve_radius))
      throw std::invalid_argument("roller mesh: magnetic blade '" + b.name +
                                  "' touches or cuts the sleeve (its nearest point is " + mm(clearance) +
                                  " from the sleeve surface); move it outward (blades[].gap or profile)");
    for (std::size_t j : g.magnetic_blades)
      if (polygons_overlap(c.blades[j].polygon, b.polygon))
        throw std::invalid_argument("roller mesh: magnetic blades '" + c.blades[j].name + "' and '" + b.name +
                                    "' overlap or touch; magnetic parts must be separate polygons");
    g.magnetic_blades.push_back(i);
  }
  if (g.magnetic_blades.size() > static_cast<std::size_t>(mesh_tags::max_blades))
    throw std::invalid_argument("roller mesh: at most " + std::to_string(mesh_tags::max_blades) +
                                " magnetic blades are supported");
  return g;
}

OpenBoundaryShell roller_shell(const Case &c) { return roller_mesh_geometry(c).shell; }

std::vector<MeshCircle> roller_mesh_circles(const Case &c)
{
  const RollerMeshGeometry g = roller_mesh_geometry(c);
  const std::vector<Layer> layers = concentric_layers(g);
  std::vector<MeshCircle> circles;
  for (std::size_t k = 0; k < layers.size(); ++k)
  {
    const int outside = k + 1 < layers.size() ? layers[k + 1].tag : mesh_tags::air;
    circles.push_back({circle_name(layers[k].r_out, g), {0.0, 0.0}, layers[k].r_out, -1, layers[k].tag, outside});
  }
  circles.push_back({"shell_inner", {0.0, 0.0}, g.shell.inner_radius, -1, mesh_tags::air, mesh_tags::shell});
  circles.push_back({"shell_outer", {0.0, 0.0}, g.shell.outer_radius, mesh_tags::outer_boundary, mesh_tags::shell, -1});
  return circles;
}

MeshSizeFunction roller_mesh_size(const Case &c)
{
  const RollerMeshGeometry g = roller_mesh_geometry(c);
  MeshSizeFunction size(c.field.mesh_size_far, mesh_grading);
  size.add_annulus({0.0, 0.0}, g.fine_band_inner, g.fine_band_outer, c.field.mesh_size_sleeve);
  for (const auto &circle : roller_mesh_circles(c))
    if (circle.name != "shell_outer")
      size.add_resolved_circle(circle.center, circle.radius, min_segments_per_circle);
  for (std::size_t i : g.magnetic_blades)
    size.add_polygon(c.blades[i].polygon, c.field.mesh_size_sleeve);
  return size;
}

std::vector<std::pair<std::string, double>> roller_exact_areas(const Case &c)
{
  const RollerMeshGeometry g = roller_mesh_geometry(c);
  auto annulus = [](double a, double b) { return M_PI * (b * b - a * a); };
  std::map<int, double> by_tag;
  for (const auto &l : concentric_layers(g))
    by_tag[l.tag] += annulus(l.r_in, l.r_out);
  by_tag[mesh_tags::air] += annulus(g.sleeve_radius, g.shell.inner_radius);
  by_tag[mesh_tags::shell] = annulus(g.shell.inner_radius, g.shell.outer_radius);
  std::vector<std::pair<std::string, double>> areas;
  for (const auto &[tag, area] : by_tag)
    areas.emplace_back(mesh_tags::region_name(tag), area);
  for (std::size_t i : g.magnetic_blades)
  {
    const double a = std::abs(polygon_signed_area(c.blades[i].polygon));
    areas.emplace_back(mesh_tags::blade_region_name(c.blades[i].name), a);
    for (auto &[name, area] : areas)
      if (name == "air")
        area -= a;
  }
  return areas;
}

namespace {

// Builds the roller geometry in Gmsh's built-in kernel, tags it, meshes it and writes it.
class RollerMesher
{
public:
  explicit RollerMesher(const Case &c)
    : case_(c), geometry_(roller_mesh_geometry(c)), size_(roller_mesh_size(c))
  {
  }

  void run(const std::string &msh_path)
  {
    build_concentric_layers();
    build_shell();
    build_outer_air_and_blades();
    geo::synchronize();
    tag_regions_and_boundary();
    gmsh_blocks::generate_quad_mesh(size_);
    gmsh_blocks::write_msh_atomically(msh_path);
  }

private:
  // Shaft, magnet, inner air gap and sleeve wall: each an annulus between two circles, each
  // circle one set of curves shared by the two layers it separates (a conforming interface).
  void build_concentric_layers()
  {
    int inner_loop = -1;
    for (const auto &layer : concentric_layers(geometry_))
    {
      const int outer_loop = geo::addCurveLoop(gmsh_blocks::add_circle({0.0, 0.0}, layer.r_out));
      std::vector<int> loops{outer_loop};
      if (inner_loop > 0)
        loops.push_back(inner_loop);
      surfaces_[layer.tag].push_back(geo::addPlaneSurface(loops));
      inner_loop = outer_loop;
    }
    sleeve_loop_ = inner_loop;
  }

  // The open-boundary shell: a structured annulus of 4 quarter patches.
  void build_shell()
  {
    const OpenBoundaryShell &shell = geometry_.shell;
    const ShellDivision d = shell_division(shell, size_({shell.inner_radius, 0.0}));
    std::vector<gmsh_blocks::ArcDivision> quarters;
    for (int k = 0; k < 4; ++k)
      quarters.push_back({0.5 * M_PI * k, d.segments_per_quarter, 1.0});
    surfaces_[mesh_tags::shell] = gmsh_blocks::add_structured_annulus(
        shell.center, shell.inner_radius, shell.outer_radius, quarters, d.layers, shell_inner_arcs_, outer_arcs_);
  }

  // The air between the sleeve and the shell, with each magnetic blade cut out of it and
  // meshed as its own region (the blade outline is shared: conforming).
  void build_outer_air_and_blades()
  {
    std::vector<int> loops{geo::addCurveLoop(shell_inner_arcs_), sleeve_loop_};
    for (std::size_t i : geometry_.magnetic_blades)
    {
      const int loop = geo::addCurveLoop(gmsh_blocks::add_polygon(counter_clockwise(case_.blades[i].polygon)));
      loops.push_back(loop);
      surfaces_[mesh_tags::blade_base + static_cast<int>(i)].push_back(geo::addPlaneSurface({loop}));
    }
    surfaces_[mesh_tags::air].push_back(geo::addPlaneSurface(loops));
  }

  void tag_regions_and_boundary()
  {
    for (const auto &[tag, surfaces] : surfaces_)
    {
      const bool blade = tag >= mesh_tags::blade_base;
      const std::string name = blade ? mesh_tags::blade_region_name(case_.blades[tag - mesh_tags::blade_base].name)
                                     : mesh_tags::region_name(tag);
      gmsh_blocks::add_physical_group(2, surfaces, tag, name);
    }
    gmsh_blocks::add_physical_group(1, outer_arcs_, mesh_tags::outer_boundary,
                                    mesh_tags::boundary_name(mesh_tags::outer_boundary));
  }

  const Case &case_;
  RollerMeshGeometry geometry_;
  MeshSizeFunction size_;
  std::map<int, std::vector<int>> surfaces_; // region tag → Gmsh surfaces
  int sleeve_loop_ = -1;
  std::vector<int> shell_inner_arcs_, outer_arcs_;
};

} // namespace

MeshSummary write_roller_mesh(const Case &c, const std::string &msh_path, const MeshOptions &options)
{
  RollerMesher mesher(c); // validates the case before Gmsh starts
  {
    GmshSession session(options, "roller");
    with_gmsh_errors("meshing the roller into '" + msh_path + "'", [&] { mesher.run(msh_path); });
  }
  MeshSummary summary = read_mesh_summary(msh_path, options);
  for (const auto &[name, area] : roller_exact_areas(c))
    for (auto &r : summary.regions)
      if (r.name == name)
        r.exact_area = area;
  for (auto &b : summary.boundaries)
    if (b.tag == mesh_tags::outer_boundary)
      b.exact_length = 2.0 * M_PI * roller_shell(c).outer_radius;
  return summary;
}

} // namespace magbrush
