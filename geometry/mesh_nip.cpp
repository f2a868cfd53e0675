// The nip mesh (see mesh_nip.h): sleeve and drum as holes in the air, the photoconductor as a
// structured graded layer, a structured open-boundary shell, quadrilaterals only.
#include "geometry/mesh_nip.h"

#include "geometry/mesh_tags.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace magbrush {

namespace geo = gmsh::model::geo;

namespace {

std::string mm(double x) { return std::to_string(x * 1e3) + " mm"; }

double angle_of(const Vec2 &v) { return std::atan2(v[1], v[0]); }

// The division of the photoconductor layer along the drum, counter-clockwise from the nip:
// a uniform fine sector across the nip (|s| < window), a sector on each side whose cells grow
// geometrically from mesh_size_gap to the far size, and two uniform far sectors meeting
// opposite the nip. Angles are absolute (CCW from +x, around the drum centre).
std::vector<gmsh_blocks::ArcDivision> layer_sectors(const NipMeshGeometry &g, const FieldSettings &f)
{
  const double R = g.drum_radius;
  const double theta_nip = angle_of({-g.nip_direction[0], -g.nip_direction[1]});
  const double h_gap = f.mesh_size_gap;
  const double h_end = std::max(h_gap, std::min(f.mesh_size_far, 2.0 * M_PI * R / min_segments_per_circle));
  const double b0 = std::min(g.nip_window / R, 0.25 * M_PI);
  const double b1 = std::min(b0 + (h_end - h_gap) / (mesh_grading * R), b0 + 0.75 * (M_PI - b0));
  const int nip_cells = std::max(2, static_cast<int>(std::ceil(2.0 * b0 * R / h_gap)));
  const Progression ramp = graded_division((b1 - b0) * R, h_gap, h_end);
  const int far_cells = std::max(1, static_cast<int>(std::ceil((M_PI - b1) * R / h_end)));
  return {{theta_nip - b0, nip_cells, 1.0},
          {theta_nip + b0, ramp.segments, ramp.ratio},
          {theta_nip + b1, far_cells, 1.0},
          {theta_nip + M_PI, far_cells, 1.0},
          {theta_nip + 2.0 * M_PI - b1, ramp.segments, 1.0 / ramp.ratio}};
}

} // namespace

NipMeshGeometry nip_mesh_geometry(const Case &c)
{
  if (!c.sleeve || !c.drum.present)
    throw std::invalid_argument(std::string("nip mesh: the case has no ") + (!c.sleeve ? "sleeve" : "drum") +
                                "; the nip mesh needs both (drum: present in the case)");
  const Drum &d = c.drum;
  const FieldSettings &f = c.field;
  NipMeshGeometry g;
  g.sleeve_radius = c.sleeve->radius;
  g.drum_radius = d.radius;
  g.pc_thickness = d.pc_thickness;
  g.gap = d.gap;
  if (!(d.gap > 0.0))
    throw std::invalid_argument("nip mesh: drum.gap must be > 0 (the sleeve and the drum may not touch), found " +
                                mm(d.gap));
  if (!(d.radius > 0.0 && d.pc_thickness >= 0.0 && d.pc_thickness < d.radius))
    throw std::invalid_argument("nip mesh: need 0 ≤ drum.pc_thickness (" + mm(d.pc_thickness) +
                                ") < drum radius (" + mm(d.radius) + ")");
  if (!(f.mesh_size_gap > 0.0 && f.mesh_size_far >= f.mesh_size_gap))
    throw std::invalid_argument("nip mesh: need 0 < field.mesh_size_gap (" + mm(f.mesh_size_gap) +
                                ") ≤ field.mesh_size_far (" + mm(f.mesh_size_far) + ")");
  if (!(f.outer_radius_factor > 1.0))
    throw std::invalid_argument("nip mesh: field.outer_radius_factor must be > 1, found " +
                                std::to_string(f.outer_radius_factor));
  g.drum_center = d.center(g.sleeve_radius);
  g.nip_direction = {std::cos(d.angle), std::sin(d.angle)};
  const double mid = g.sleeve_radius + 0.5 * d.gap;
  g.nip_midpoint = {mid * g.nip_direction[0], mid * g.nip_direction[1]};
  // The gap opens as g + s²κ/2 along the surfaces (κ = 1/R_sleeve + 1/R_drum): the fine disk
  // reaches to where it is 3g wide.
  const double kappa = 1.0 / g.sleeve_radius + 1.0 / d.radius;
  g.nip_window = std::sqrt(4.0 * d.gap / kappa);
  g.layer_cells_across = d.pc_thickness > 0.0
                             ? std::max(3, static_cast<int>(std::ceil(d.pc_thickness / f.mesh_size_gap)))
                             : 0;
  // The smallest circle enclosing both disks has the line of centres as a diameter.
  const double centre_distance = g.sleeve_radius + d.gap + d.radius;
  const double lo = -g.sleeve_radius, hi = centre_distance + d.radius;
  const double c_along = 0.5 * (lo + hi), enclosing = 0.5 * (hi - lo);
  g.shell.center = {c_along * g.nip_direction[0], c_along * g.nip_direction[1]};
  g.shell.inner_radius = f.outer_radius_factor * enclosing;
  g.shell.outer_radius = shell_outer_ratio * g.shell.inner_radius;
  return g;
}

OpenBoundaryShell nip_shell(const Case &c) { return nip_mesh_geometry(c).shell; }

std::vector<MeshCircle> nip_mesh_circles(const Case &c)
{
  const NipMeshGeometry g = nip_mesh_geometry(c);
  std::vector<MeshCircle> circles;
  circles.push_back({"sleeve_surface", {0.0, 0.0}, g.sleeve_radius, mesh_tags::sleeve_surface, -1, mesh_tags::air});
  if (g.pc_thickness > 0.0)
  {
    circles.push_back({"drum_surface", g.drum_center, g.drum_radius, -1, mesh_tags::photoconductor, mesh_tags::air});
    circles.push_back({"drum_substrate", g.drum_center, g.drum_radius - g.pc_thickness, mesh_tags::drum_substrate, -1,
                       mesh_tags::photoconductor});
  }
  else
    circles.push_back({"drum_substrate", g.drum_center, g.drum_radius, mesh_tags::drum_substrate, -1, mesh_tags::air});
  circles.push_back({"shell_inner", g.shell.center, g.shell.inner_radius, -1, mesh_tags::air, mesh_tags::shell});
  circles.push_back({"shell_outer", g.shell.center, g.shell.outer_radius, mesh_tags::outer_boundary, mesh_tags::shell, -1});
  return circles;
}

MeshSizeFunction nip_mesh_size(const Case &c)
{
  const NipMeshGeometry g = nip_mesh_geometry(c);
  MeshSizeFunction size(c.field.mesh_size_far, mesh_grading);
  size.add_disk(g.nip_midpoint, g.nip_window, c.field.mesh_size_gap);
  for (const auto &circle : nip_mesh_circles(c))
    if (circle.name != "shell_outer")
      size.add_resolved_circle(circle.center, circle.radius, min_segments_per_circle);
  return size;
}

std::vector<std::pair<std::string, double>> nip_exact_areas(const Case &c)
{
  const NipMeshGeometry g = nip_mesh_geometry(c);
  const double rs = g.sleeve_radius, rd = g.drum_radius, rsub = rd - g.pc_thickness;
  const double ri = g.shell.inner_radius, ro = g.shell.outer_radius;
  std::vector<std::pair<std::string, double>> areas{
      {mesh_tags::region_name(mesh_tags::air), M_PI * (ri * ri - rs * rs - rd * rd)},
      {mesh_tags::region_name(mesh_tags::shell), M_PI * (ro * ro - ri * ri)}};
  if (g.pc_thickness > 0.0)
    areas.emplace_back(mesh_tags::region_name(mesh_tags::photoconductor), M_PI * (rd * rd - rsub * rsub));
  return areas;
}

namespace {

class NipMesher
{
public:
  explicit NipMesher(const Case &c) : case_(c), geometry_(nip_mesh_geometry(c)), size_(nip_mesh_size(c)) {}

  void run(const std::string &msh_path)
  {
    build_sleeve();
    build_drum();
    build_shell();
    build_air();
    geo::synchronize();
    tag_regions_and_boundaries();
    gmsh_blocks::generate_quad_mesh(size_);
    gmsh_blocks::write_msh_atomically(msh_path);
  }

private:
  // The sleeve is a hole: its circle is the biased electrode. Its arcs start at the nip.
  void build_sleeve()
  {
    sleeve_arcs_ = gmsh_blocks::add_circle({0.0, 0.0}, geometry_.sleeve_radius, angle_of(geometry_.nip_direction));
  }

  // With a photoconductor: a structured layer whose inner circle is the grounded substrate.
  // Without: the drum circle itself is the grounded electrode.
  void build_drum()
  {
    const NipMeshGeometry &g = geometry_;
    if (g.pc_thickness > 0.0)
    {
      pc_surfaces_ = gmsh_blocks::add_structured_annulus(g.drum_center, g.drum_radius - g.pc_thickness, g.drum_radius,
                                                         layer_sectors(g, case_.field), g.layer_cells_across,
                                                         substrate_arcs_, drum_surface_arcs_);
    }
    else
    {
      drum_surface_arcs_ = gmsh_blocks::add_circle(g.drum_center, g.drum_radius,
                                                   angle_of({-g.nip_direction[0], -g.nip_direction[1]}));
      substrate_arcs_ = drum_surface_arcs_;
    }
  }

  void build_shell()
  {
    const OpenBoundaryShell &shell = geometry_.shell;
    const double h = size_({shell.center[0] + shell.inner_radius, shell.center[1]});
    const double quarter = 0.5 * M_PI * shell.inner_radius;
    const int segments = std::max(min_segments_per_circle / 4, static_cast<int>(std::ceil(quarter / h)));
    const int layers = std::max(4, static_cast<int>(std::lround((shell.outer_radius - shell.inner_radius) /
                                                                (quarter / segments))));
    std::vector<gmsh_blocks::ArcDivision> quarters;
    for (int k = 0; k < 4; ++k)
      quarters.push_back({0.5 * M_PI * k, segments, 1.0});
    shell_surfaces_ = gmsh_blocks::add_structured_annulus(shell.center, shell.inner_radius, shell.outer_radius,
                                                          quarters, layers, shell_inner_arcs_, outer_arcs_);
  }

  void build_air()
  {
    air_ = geo::addPlaneSurface({geo::addCurveLoop(shell_inner_arcs_), geo::addCurveLoop(sleeve_arcs_),
                                 geo::addCurveLoop(drum_surface_arcs_)});
  }

  void tag_regions_and_boundaries()
  {
    using namespace mesh_tags;
    gmsh_blocks::add_physical_group(2, {air_}, air, region_name(air));
    if (!pc_surfaces_.empty())
      gmsh_blocks::add_physical_group(2, pc_surfaces_, photoconductor, region_name(photoconductor));
    gmsh_blocks::add_physical_group(2, shell_surfaces_, shell, region_name(shell));
    gmsh_blocks::add_physical_group(1, outer_arcs_, outer_boundary, boundary_name(outer_boundary));
    gmsh_blocks::add_physical_group(1, sleeve_arcs_, sleeve_surface, boundary_name(sleeve_surface));
    gmsh_blocks::add_physical_group(1, substrate_arcs_, drum_substrate, boundary_name(drum_substrate));
  }

  const Case &case_;
  NipMeshGeometry geometry_;
  MeshSizeFunction size_;
  std::vector<int> sleeve_arcs_, drum_surface_arcs_, substrate_arcs_, shell_inner_arcs_, outer_arcs_;
  std::vector<int> pc_surfaces_, shell_surfaces_;
  int air_ = -1;
};

} // namespace

MeshSummary write_nip_mesh(const Case &c, const std::string &msh_path, const MeshOptions &options)
{
  NipMesher mesher(c); // validates the case before Gmsh starts
  {
    GmshSession session(options, "nip");
    with_gmsh_errors("meshing the nip into '" + msh_path + "'", [&] { mesher.run(msh_path); });
  }
  MeshSummary summary = read_mesh_summary(msh_path, options);
  const NipMeshGeometry g = nip_mesh_geometry(c);
  for (const auto &[name, area] : nip_exact_areas(c))
    for (auto &r : summary.regions)
      if (r.name == name)
        r.exact_area = area;
  for (auto &b : summary.boundaries)
  {
    if (b.tag == mesh_tags::outer_boundary)
      b.exact_length = 2.0 * M_PI * g.shell.outer_radius;
    else if (b.tag == mesh_tags::sleeve_surface)
      b.exact_length = 2.0 * M_PI * g.sleeve_radius;
    else if (b.tag == mesh_tags::drum_substrate)
      b.exact_length = 2.0 * M_PI * (g.drum_radius - g.pc_thickness);
  }
  return summary;
}

} // namespace magbrush
