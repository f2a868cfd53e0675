// What the roller and nip meshers share: the description of a written mesh (MeshSummary),
// the circles the field solver curves its faces onto (MeshCircle), the open-boundary shell,
// the Gmsh session guard, and the few Gmsh building blocks both meshes are made of.
#pragma once

#include "case/case_model.h"

#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace magbrush {

// ---- the open boundary ----------------------------------------------------------------------
// Both meshes end in an annulus R_in < |x − c| < R_out in which the field solver stretches the
// radial coordinate to infinity at R_out (a shell transformation), so the field inside R_in is
// that of the unbounded plane. R_in = FieldSettings::outer_radius_factor × the radius of a circle
// around c enclosing everything else; R_out = shell_outer_ratio × R_in.
constexpr double shell_outer_ratio = 1.25;

struct OpenBoundaryShell
{
  Vec2 center{{0.0, 0.0}};
  double inner_radius = 0.0;
  double outer_radius = 0.0;
};

// ---- circles of the mesh --------------------------------------------------------------------
// Every curved line of a mesh is an arc of one of these circles. deal.II meshes are read with
// straight faces: the solver attaches a PolarManifold (centre `center`) to the faces on each
// circle (both vertices at distance `radius` from the centre) so that they curve with refinement
// and a higher-order mapping.
struct MeshCircle
{
  std::string name;        // "sleeve_surface", "magnet_surface", "drum_surface", "shell_outer", ...
  Vec2 center{{0.0, 0.0}};
  double radius = 0.0;
  int boundary_id = -1;    // its boundary tag (mesh_tags.h) when it bounds the domain, else −1
  int inside_region = -1;  // region tag just inside (−1: none, outside the domain)
  int outside_region = -1; // region tag just outside
};

// ---- what was written -----------------------------------------------------------------------
struct RegionSummary
{
  std::string name;          // physical-group name
  int tag = 0;               // physical tag = deal.II material_id
  std::size_t n_cells = 0;
  double area = 0.0;         // sum of the cell areas (straight-sided cells) [m²]
  double exact_area = -1.0;  // the area of the exact (curved) region; < 0 unknown
  double min_size = 0.0;     // smallest and largest √(cell area) [m]
  double max_size = 0.0;
};

struct BoundarySummary
{
  std::string name;
  int tag = 0;               // physical tag = deal.II boundary_id
  std::size_t n_faces = 0;
  double length = 0.0;       // sum of the face lengths [m]
  double exact_length = -1.0;
};

struct MeshSummary
{
  std::string path;
  std::size_t n_nodes = 0;
  std::size_t n_quads = 0;
  std::size_t n_other_cells = 0;      // triangles etc.: 0 for a mesh deal.II can read
  std::size_t n_inverted_cells = 0;   // cells with a corner Jacobian ≤ 0
  std::vector<RegionSummary> regions;
  std::vector<BoundarySummary> boundaries;
  double min_element_size = 0.0;      // √(cell area) [m]
  double max_element_size = 0.0;
  double min_quality = 0.0;           // smallest scaled corner Jacobian (1: rectangle, ≤ 0: inverted)

  const RegionSummary *region(const std::string &name) const;     // nullptr if absent
  const BoundarySummary *boundary(const std::string &name) const; // nullptr if absent
};

// Knobs that do not change the mesh.
struct MeshOptions
{
  bool verbose = false; // let Gmsh print its progress on the terminal
};

// Reads a written .msh file back through the Gmsh API and describes it (no exact areas).
MeshSummary read_mesh_summary(const std::string &msh_path, const MeshOptions &options = {});

// A table: per region cells, area, exact area and relative error; per boundary faces and length.
std::string format_mesh_summary(const MeshSummary &summary);

// ---- Gmsh session ---------------------------------------------------------------------------
// Gmsh is one global state per process. A GmshSession initialises it (terminal output off unless
// verbose, no configuration files read) and finalises it on destruction, and holds a process-wide
// lock meanwhile so that two threads never build meshes at the same time. Gmsh errors are thrown
// as exceptions while a session is open.
class GmshSession
{
public:
  explicit GmshSession(const MeshOptions &options = {}, const std::string &model_name = "magbrush");
  ~GmshSession();
  GmshSession(const GmshSession &) = delete;
  GmshSession &operator=(const GmshSession &) = delete;

private:
  std::unique_lock<std::mutex> lock_;
};

// Runs `what` (Gmsh calls) and turns whatever Gmsh throws into a std::runtime_error that says
// what we were doing and Gmsh's last error message.
template <class F>
auto with_gmsh_errors(const std::string &doing, F &&what) -> decltype(what());
[[noreturn]] void rethrow_gmsh_error(const std::string &doing);

template <class F>
auto with_gmsh_errors(const std::string &doing, F &&what) -> decltype(what())
{
  try
  {
    return what();
  }
  catch (...)
  {
    rethrow_gmsh_error(doing);
  }
}

// ---- Gmsh building blocks (built-in "geo" kernel; call synchronize() after) -----------------
namespace gmsh_blocks {

// A full circle as `n_arcs` equal arcs (Gmsh arcs must span less than π) starting at angle
// `start` (CCW from +x). Returns the arc tags in CCW order; `points` gets the arc end points.
std::vector<int> add_circle(const Vec2 &c, double r, double start = 0.0, int n_arcs = 4,
                            std::vector<int> *points = nullptr);

// A closed polygon of straight lines; returns the line tags.
std::vector<int> add_polygon(const std::vector<Vec2> &polygon);

// One sector of a structured annulus: from `start_angle` (CCW from +x) to the start of the
// next sector, divided into `segments` arcs whose lengths grow by `ratio` from one to the next
// (counter-clockwise).
struct ArcDivision
{
  double start_angle = 0.0;
  int segments = 1;
  double ratio = 1.0;
};

// A structured annulus between the circles of radius r_in and r_out around c: one transfinite
// quadrilateral patch per sector (each spanning less than π), the inner and outer arcs divided
// alike so that the grid lines are radial, `layers` cells across. Returns the surface tags;
// `inner_arcs`/`outer_arcs` get the arc tags in CCW order.
std::vector<int> add_structured_annulus(const Vec2 &c, double r_in, double r_out,
                                        const std::vector<ArcDivision> &sectors, int layers,
                                        std::vector<int> &inner_arcs, std::vector<int> &outer_arcs);

// Meshes in 2D with quadrilaterals only (Frontal-Delaunay + Blossom recombination; when a
// surface keeps triangles, once more at twice the size with every cell split into quads) using `size` as the
// target size, then checks that no triangle is left.
void generate_quad_mesh(const std::function<double(const Vec2 &)> &size);

// Adds a named physical group (dim 2: region, dim 1: boundary) with a fixed tag.
void add_physical_group(int dim, const std::vector<int> &entities, int tag, const std::string &name);

// Writes the mesh as MSH 2.2 ASCII (what deal.II 9.4's GridIn::read_msh reads), atomically:
// to a temporary file next to `path`, then renamed. Creates the parent directory.
void write_msh_atomically(const std::string &path);

} // namespace gmsh_blocks

} // namespace magbrush
