// The Gmsh session guard, the mesh building blocks and the summary of a written mesh
// (see mesh_common.h).
#include "geometry/mesh_common.h"

#include "geometry/mesh_tags.h"

#include "common/atomic_file.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <fcntl.h>
#include <unistd.h>
#include <unordered_map>

namespace magbrush {

namespace fs = std::filesystem;
namespace geo = gmsh::model::geo;

// ---- summary --------------------------------------------------------------------------------

const RegionSummary *MeshSummary::region(const std::string &name) const
{
  for (const auto &r : regions)
    if (r.name == name)
      return &r;
  return nullptr;
}

const BoundarySummary *MeshSummary::boundary(const std::string &name) const
{
  for (const auto &b : boundaries)
    if (b.name == name)
      return &b;
  return nullptr;
}

namespace {

// Gmsh element types of linear cells (MSH numbering).
constexpr int gmsh_line = 1, gmsh_triangle = 2, gmsh_quad = 3;

struct CellGeometry
{
  double area = 0.0;
  double min_scaled_jacobian = 1.0;
};

// Area (shoelace) and the smallest scaled corner Jacobian of a straight-sided polygonal cell
// with counter-clockwise vertices: sin of the corner angle, negative at a reflex or inverted
// corner.
CellGeometry cell_geometry(const std::vector<Vec2> &v)
{
  CellGeometry g;
  const size_t n = v.size();
  for (size_t k = 0; k < n; ++k)
  {
    const Vec2 &p = v[k], &next = v[(k + 1) % n], &prev = v[(k + n - 1) % n];
    g.area += 0.5 * (p[0] * next[1] - next[0] * p[1]);
    const double ax = next[0] - p[0], ay = next[1] - p[1], bx = prev[0] - p[0], by = prev[1] - p[1];
    const double la = std::hypot(ax, ay), lb = std::hypot(bx, by);
    g.min_scaled_jacobian =
        std::min(g.min_scaled_jacobian, la > 0 && lb > 0 ? (ax * by - ay * bx) / (la * lb) : -1.0);
  }
  return g;
}

int nodes_per_element(int type) { return type == gmsh_line ? 2 : type == gmsh_triangle ? 3 : type == gmsh_quad ? 4 : 0; }

MeshSummary summarize_current_model(const std::string &path)
{
  MeshSummary s;
  s.path = path;
  std::vector<std::size_t> node_tags;
  std::vector<double> coords, params;
  gmsh::model::mesh::getNodes(node_tags, coords, params, -1, -1, false, false);
  s.n_nodes = node_tags.size();
  std::unordered_map<std::size_t, Vec2> xy;
  xy.reserve(node_tags.size());
  for (size_t i = 0; i < node_tags.size(); ++i)
    xy[node_tags[i]] = {coords[3 * i], coords[3 * i + 1]};

  s.min_element_size = INFINITY;
  s.max_element_size = 0.0;
  s.min_quality = INFINITY;
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto &[dim, tag] : groups)
  {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    RegionSummary region{name, tag, 0, 0.0, -1.0, INFINITY, 0.0};
    BoundarySummary boundary{name, tag, 0, 0.0, -1.0};
    for (int entity : entities)
    {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> element_tags, element_nodes;
      gmsh::model::mesh::getElements(types, element_tags, element_nodes, dim, entity);
      for (size_t t = 0; t < types.size(); ++t)
      {
        const int nn = nodes_per_element(types[t]);
        if (nn == 0)
          throw std::runtime_error("mesh '" + path + "': unexpected element type " +
                                   std::to_string(types[t]) + " in group '" + name +
                                   "' (expected linear quads and lines)");
        for (size_t e = 0; e < element_tags[t].size(); ++e)
        {
          std::vector<Vec2> v(nn);
          for (int k = 0; k < nn; ++k)
            v[k] = xy.at(element_nodes[t][nn * e + k]);
          if (dim == 1)
          {
            ++boundary.n_faces;
            boundary.length += std::hypot(v[1][0] - v[0][0], v[1][1] - v[0][1]);
            continue;
          }
          const CellGeometry g = cell_geometry(v);
          (types[t] == gmsh_quad ? s.n_quads : s.n_other_cells) += 1;
          if (g.min_scaled_jacobian <= 0.0)
            ++s.n_inverted_cells;
          ++region.n_cells;
          region.area += g.area;
          const double h = std::sqrt(std::abs(g.area));
          region.min_size = std::min(region.min_size, h);
          region.max_size = std::max(region.max_size, h);
          s.min_quality = std::min(s.min_quality, g.min_scaled_jacobian);
        }
      }
    }
    if (dim == 2)
    {
      s.min_element_size = std::min(s.min_element_size, region.min_size);
      s.max_element_size = std::max(s.max_element_size, region.max_size);
      s.regions.push_back(region);
    }
    else if (dim == 1)
      s.boundaries.push_back(boundary);
  }
  return s;
}

std::mutex &gmsh_mutex()
{
  static std::mutex m;
  return m;
}

} // namespace

MeshSummary read_mesh_summary(const std::string &msh_path, const MeshOptions &options)
{
  if (!fs::exists(msh_path))
    throw std::runtime_error("mesh file '" + msh_path + "' does not exist; write it first with "
                             "`magbrush mesh CASE`");
  GmshSession session(options, "readback");
  return with_gmsh_errors("reading mesh '" + msh_path + "'", [&] {
    gmsh::open(msh_path);
    return summarize_current_model(msh_path);
  });
}

std::string format_mesh_summary(const MeshSummary &s)
{
  std::ostringstream out;
  out << s.path << ": " << s.n_nodes << " nodes, " << s.n_quads << " quadrilaterals";
  if (s.n_other_cells)
    out << ", " << s.n_other_cells << " OTHER CELLS (not quadrilaterals)";
  if (s.n_inverted_cells)
    out << ", " << s.n_inverted_cells << " INVERTED CELLS";
  out << "\n  element size " << std::setprecision(3) << s.min_element_size * 1e3 << " .. "
      << s.max_element_size * 1e3 << " mm (sqrt of cell area), min scaled Jacobian "
      << s.min_quality << "\n";
  out << "  region            tag    cells    area [mm^2]   exact [mm^2]   rel. error\n";
  for (const auto &r : s.regions)
  {
    char line[200];
    if (r.exact_area > 0)
      std::snprintf(line, sizeof line, "  %-16s %4d %8zu %14.6g %14.6g %12.2e\n", r.name.c_str(),
                    r.tag, r.n_cells, r.area * 1e6, r.exact_area * 1e6,
                    (r.area - r.exact_area) / r.exact_area);
    else
      std::snprintf(line, sizeof line, "  %-16s %4d %8zu %14.6g %14s %12s\n", r.name.c_str(), r.tag,
                    r.n_cells, r.area * 1e6, "-", "-");
    out << line;
  }
  out << "  boundary          tag    faces    length [mm]   exact [mm]\n";
  for (const auto &b : s.boundaries)
  {
    char line[200];
    std::snprintf(line, sizeof line, "  %-16s %4d %8zu %14.6g %14.6g\n", b.name.c_str(), b.tag,
                  b.n_faces, b.length * 1e3, b.exact_length * 1e3);
    out << line;
  }
  return out.str();
}

// ---- Gmsh session ---------------------------------------------------------------------------

GmshSession::GmshSession(const MeshOptions &options, const std::string &model_name)
  : lock_(gmsh_mutex())
{
  with_gmsh_errors("starting Gmsh", [&] {
    gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
    gmsh::option::setNumber("General.Terminal", options.verbose ? 1 : 0);
    gmsh::option::setNumber("General.Verbosity", options.verbose ? 5 : 1);
    // One thread: a Gmsh error thrown inside one of its OpenMP regions could not be caught.
    gmsh::option::setNumber("General.NumThreads", 1);
    gmsh::model::add(model_name);
  });
}

GmshSession::~GmshSession()
{
  try
  {
    gmsh::finalize();
  }
  catch (...)
  {
    // Nothing sensible to do while unwinding; Gmsh's state is reset by the next initialize.
  }
}

void rethrow_gmsh_error(const std::string &doing)
{
  std::string message;
  try
  {
    throw;
  }
  catch (const std::exception &e)
  {
    message = e.what();
  }
  catch (...)
  {
  }
  std::string last;
  try
  {
    gmsh::logger::getLastError(last);
  }
  catch (...)
  {
  }
  if (!last.empty() && message.find(last) == std::string::npos)
    message += (message.empty() ? "" : "; ") + last;
  throw std::runtime_error(doing + " failed: " + (message.empty() ? "Gmsh gave no message" : message));
}

// ---- building blocks ------------------------------------------------------------------------

namespace gmsh_blocks {

std::vector<int> add_circle(const Vec2 &c, double r, double start, int n_arcs, std::vector<int> *points)
{
  const int centre = geo::addPoint(c[0], c[1], 0.0);
  std::vector<int> p(n_arcs), arcs(n_arcs);
  for (int k = 0; k < n_arcs; ++k)
  {
    const double a = start + 2.0 * M_PI * k / n_arcs;
    p[k] = geo::addPoint(c[0] + r * std::cos(a), c[1] + r * std::sin(a), 0.0);
  }
  for (int k = 0; k < n_arcs; ++k)
    arcs[k] = geo::addCircleArc(p[k], centre, p[(k + 1) % n_arcs]);
  if (points)
    *points = p;
  return arcs;
}

std::vector<int> add_polygon(const std::vector<Vec2> &polygon)
{
  std::vector<int> p, lines;
  for (const auto &v : polygon)
    p.push_back(geo::addPoint(v[0], v[1], 0.0));
  for (size_t k = 0; k < p.size(); ++k)
    lines.push_back(geo::addLine(p[k], p[(k + 1) % p.size()]));
  return lines;
}

std::vector<int> add_structured_annulus(const Vec2 &c, double r_in, double r_out,
                                        const std::vector<ArcDivision> &sectors, int layers,
                                        std::vector<int> &inner_arcs, std::vector<int> &outer_arcs)
{
  const size_t n = sectors.size();
  if (n < 3)
    throw std::invalid_argument("structured annulus: at least 3 sectors (arcs span < 180 deg)");
  const int centre = geo::addPoint(c[0], c[1], 0.0);
  std::vector<int> pin(n), pout(n), radial(n), surfaces(n);
  inner_arcs.assign(n, 0);
  outer_arcs.assign(n, 0);
  for (size_t k = 0; k < n; ++k)
  {
    const double a = sectors[k].start_angle;
    const double end = k + 1 < n ? sectors[k + 1].start_angle : sectors[0].start_angle + 2.0 * M_PI;
    if (!(end > a) || end - a >= M_PI * (1.0 - 1e-9))
      throw std::invalid_argument("structured annulus: sector " + std::to_string(k) +
                                  " spans " + std::to_string((end - a) * 180.0 / M_PI) +
                                  " deg; each sector must span between 0 and 180 deg");
    pin[k] = geo::addPoint(c[0] + r_in * std::cos(a), c[1] + r_in * std::sin(a), 0.0);
    pout[k] = geo::addPoint(c[0] + r_out * std::cos(a), c[1] + r_out * std::sin(a), 0.0);
  }
  for (size_t k = 0; k < n; ++k)
  {
    const size_t next = (k + 1) % n;
    inner_arcs[k] = geo::addCircleArc(pin[k], centre, pin[next]);
    outer_arcs[k] = geo::addCircleArc(pout[k], centre, pout[next]);
    radial[k] = geo::addLine(pin[k], pout[k]);
    for (int arc : {inner_arcs[k], outer_arcs[k]})
      geo::mesh::setTransfiniteCurve(arc, sectors[k].segments + 1, "Progression", sectors[k].ratio);
    geo::mesh::setTransfiniteCurve(radial[k], layers + 1);
  }
  for (size_t k = 0; k < n; ++k)
  {
    const size_t next = (k + 1) % n;
    const int loop = geo::addCurveLoop({inner_arcs[k], radial[next], -outer_arcs[k], -radial[k]});
    surfaces[k] = geo::addPlaneSurface({loop});
    geo::mesh::setTransfiniteSurface(surfaces[k], "Left", {pin[k], pout[k], pout[next], pin[next]});
    geo::mesh::setRecombine(2, surfaces[k]);
    // Gmsh's transfinite quads come out clockwise here; deal.II wants counter-clockwise cells
    // (the tests check every corner Jacobian).
    geo::mesh::setReverse(2, surfaces[k], true);
  }
  return surfaces;
}

namespace {
// Gmsh's Blossom matcher prints warnings with printf, past General.Terminal = 0. While it runs
// without --verbose, standard output goes to /dev/null (process-wide: meant for the CLI and
// the tests, where nothing else prints meanwhile).
class QuietStdout
{
public:
  explicit QuietStdout(bool active)
  {
    if (!active)
      return;
    std::fflush(stdout);
    saved_ = ::dup(STDOUT_FILENO);
    const int null = ::open("/dev/null", O_WRONLY);
    if (saved_ >= 0 && null >= 0)
      ::dup2(null, STDOUT_FILENO);
    if (null >= 0)
      ::close(null);
  }
  ~QuietStdout()
  {
    if (saved_ < 0)
      return;
    std::fflush(stdout);
    ::dup2(saved_, STDOUT_FILENO);
    ::close(saved_);
  }
  QuietStdout(const QuietStdout &) = delete;
  QuietStdout &operator=(const QuietStdout &) = delete;

private:
  int saved_ = -1;
};

std::size_t count_triangles()
{
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> tags, nodes;
  gmsh::model::mesh::getElements(types, tags, nodes, 2, -1);
  std::size_t n = 0;
  for (size_t t = 0; t < types.size(); ++t)
    if (types[t] != gmsh_quad)
      n += tags[t].size();
  return n;
}
} // namespace

void generate_quad_mesh(const std::function<double(const Vec2 &)> &size)
{
  // Sizes come from `size` alone (no point sizes, no curvature sizing, no propagation from
  // the boundary), so the mesh follows the analytic size function the tests check.
  gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.ElementOrder", 1); // deal.II curves the faces itself
  // Frontal-Delaunay (6) triangles recombined into quads by Blossom matching (1). Gmsh 4.8's
  // "Frontal-Delaunay for quads" (8) stalls with a size callback, so it is not used.
  gmsh::option::setNumber("Mesh.Algorithm", 6);
  gmsh::option::setNumber("Mesh.RecombineAll", 1);
  gmsh::option::setNumber("Mesh.RecombinationAlgorithm", 1);
  double terminal = 0.0;
  gmsh::option::getNumber("General.Terminal", terminal);
  QuietStdout quiet(terminal == 0.0);
  gmsh::model::mesh::setSizeCallback(
      [size](int, int, double x, double y, double) { return size({x, y}); });
  gmsh::model::mesh::generate(2);
  if (count_triangles() > 0)
  {
    // Blossom could not pair every triangle (a surface with an odd number of boundary
    // segments). Fallback: mesh at twice the size and split every cell into quadrilaterals
    // (a triangle into 3, a quad into 4). The structured parts are split too, which only
    // refines them. (Gmsh's full-quad recombination is not used: it fails on transfinite
    // curves with an odd number of segments.)
    gmsh::model::mesh::clear();
    gmsh::model::mesh::setSizeCallback(
        [size](int, int, double x, double y, double) { return 2.0 * size({x, y}); });
    gmsh::option::setNumber("Mesh.SubdivisionAlgorithm", 1);
    gmsh::model::mesh::generate(2);
    gmsh::option::setNumber("Mesh.SubdivisionAlgorithm", 0);
  }
  gmsh::model::mesh::removeSizeCallback();
  if (const std::size_t n = count_triangles(); n > 0)
    throw std::runtime_error("the mesh still has " + std::to_string(n) +
                             " triangles after subdivision into quadrilaterals; deal.II needs "
                             "quadrilaterals only (try a slightly different mesh size)");
}

void add_physical_group(int dim, const std::vector<int> &entities, int tag, const std::string &name)
{
  gmsh::model::addPhysicalGroup(dim, entities, tag);
  gmsh::model::setPhysicalName(dim, tag, name);
}

void write_msh_atomically(const std::string &path)
{
  const fs::path target(path);
  if (target.has_parent_path())
    fs::create_directories(target.parent_path());
  // Gmsh picks the format from the extension, so the temporary name ends in .msh as well.
  AtomicFile file(path, AtomicFile::Extension::kept);
  gmsh::option::setNumber("Mesh.MshFileVersion", 2.2);
  gmsh::option::setNumber("Mesh.Binary", 0);
  gmsh::option::setNumber("Mesh.SaveAll", 0); // only the elements of physical groups
  gmsh::write(file.temp_path());
  file.commit();
}

} // namespace gmsh_blocks

} // namespace magbrush
