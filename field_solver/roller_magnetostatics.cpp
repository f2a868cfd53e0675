#include "field_solver/roller_magnetostatics.h"

#include "field_solver/layered_meshes.h"
#include "geometry/mesh_roller.h"
#include "geometry/mesh_tags.h"
#include "field_solver/pole_magnetisation.h"

#include <deal.II/base/mpi.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/manifold_lib.h>
#include <deal.II/grid/tria.h>

#include <fstream>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::field {

namespace {
constexpr double mu0 = 4.0e-7 * 3.14159265358979323846;
constexpr double pi = 3.14159265358979323846;
} // namespace

RollerGeometry RollerGeometry::from(const Roller &roller, const Sleeve &sleeve)
{
  RollerGeometry g;
  g.shaft_radius = roller.shaft_radius;
  g.shaft_mu_r = roller.shaft_mu_r;
  g.magnet_radius = roller.magnet_radius;
  g.magnet_mu_r = roller.magnet_mu_r;
  g.sleeve_radius = sleeve.radius;
  return g;
}

Magnetisation gaussian_pole_magnetisation(const std::vector<Pole> &poles)
{
  return [poles](double x, double y) {
    const double theta = std::atan2(y, x);
    const double m = radial_magnetisation(poles, theta);
    const double r = std::hypot(x, y);
    return r > 0.0 ? Vec2{{m * x / r, m * y / r}} : Vec2{{0.0, 0.0}};
  };
}

RollerMeshFile write_roller_mesh_file(const Case &c, const std::string &msh_path,
                                      unsigned int degree, MPI_Comm communicator)
{
  Case scaled = c;
  scaled.field.mesh_size_sleeve = c.field.mesh_size_sleeve * std::max(1u, degree);
  scaled.field.mesh_size_far = std::max(scaled.field.mesh_size_far, scaled.field.mesh_size_sleeve);
  RollerMeshFile f;
  f.path = msh_path;
  f.circles = roller_mesh_circles(scaled);
  f.shell = roller_shell(scaled);
  for (const auto &blade : c.blades)
    f.blade_mu_r.push_back(blade.mu_r);
  if (dealii::Utilities::MPI::this_mpi_process(communicator) == 0)
    write_roller_mesh(scaled, msh_path);
  MPI_Barrier(communicator);
  return f;
}

RollerMagnetostatics::RollerMagnetostatics(MPI_Comm communicator_in,
                                           const RollerGeometry &geometry,
                                           Magnetisation magnetisation_in,
                                           const RollerDiscretisation &discretisation_in,
                                           RollerMeshFile mesh_file_in)
  : RollerMagnetostatics(communicator_in, geometry, std::move(magnetisation_in),
                         discretisation_in)
{
  for (const double mu : mesh_file_in.blade_mu_r)
    if (!(mu >= 1.0) || !std::isfinite(mu))
      throw std::invalid_argument("roller field: blade mu_r must be finite and >= 1, found " +
                                  std::to_string(mu));
  mesh_file = std::move(mesh_file_in);
}

RollerMagnetostatics::RollerMagnetostatics(MPI_Comm communicator_in,
                                           const RollerGeometry &geometry,
                                           Magnetisation magnetisation_in,
                                           const RollerDiscretisation &discretisation_in)
  : communicator(communicator_in)
  , roller(geometry)
  , magnetisation(std::move(magnetisation_in))
  , discretisation(discretisation_in)
  , triangulation(communicator, dealii::Triangulation<2>::none, false,
                  dealii::parallel::shared::Triangulation<2>::partition_metis)
{
  const auto fail = [](const std::string &what) {
    throw std::invalid_argument("roller field: " + what);
  };
  if (!(roller.magnet_radius > 0.0))
    fail("roller.magnet_radius must be positive, found " + std::to_string(roller.magnet_radius));
  if (roller.shaft_radius < 0.0 || roller.shaft_radius >= roller.magnet_radius)
    fail("roller.shaft_radius must lie in [0, magnet_radius), found " +
         std::to_string(roller.shaft_radius) + " m (magnet radius " +
         std::to_string(roller.magnet_radius) + " m)");
  if (!(roller.sleeve_radius > roller.magnet_radius))
    fail("the sleeve radius (" + std::to_string(roller.sleeve_radius) +
         " m) must exceed the magnet radius (" + std::to_string(roller.magnet_radius) + " m)");
  if (!(roller.magnet_mu_r >= 1.0) || !(roller.shaft_mu_r >= 1.0) ||
      !std::isfinite(roller.shaft_mu_r))
    fail("μr of magnet and shaft must be finite and ≥ 1 (for ideal iron use e.g. 1e4)");
  if (!(discretisation.outer_radius_factor > 1.0))
    fail("field.outer_radius_factor must exceed 1 (the shell starts outside the sleeve), "
         "found " + std::to_string(discretisation.outer_radius_factor));
}

RollerMagnetostatics::~RollerMagnetostatics() = default;

double RollerMagnetostatics::shell_inner_radius() const
{
  if (mesh_file)
    return mesh_file->shell.inner_radius;
  return discretisation.outer_radius_factor * roller.sleeve_radius;
}

// Circles: [shaft], magnet, sleeve surface, requested extra circles, shell start, shell end.
void RollerMagnetostatics::make_mesh()
{
  const double R1 = shell_inner_radius();
  const double R2 = discretisation.shell_ratio * R1;
  std::vector<AnnularLayer> layers;
  if (roller.shaft_radius > 0.0)
    layers.push_back({roller.shaft_radius, roller_region::shaft, 0});
  layers.push_back({roller.magnet_radius, roller_region::magnet, 0});

  std::vector<double> circles{roller.sleeve_radius};
  for (const double r : discretisation.extra_circles)
    if (r > roller.magnet_radius * (1 + 1e-9) && r < R1 * (1 - 1e-9))
      circles.push_back(r);
  std::sort(circles.begin(), circles.end());
  circles.erase(std::unique(circles.begin(), circles.end(),
                            [&](double a, double b) { return b - a < 1e-9 * R1; }),
                circles.end());
  for (const double r : circles)
    layers.push_back({r, roller_region::air, 0});
  layers.push_back({R1, roller_region::air, 0});
  // The shell only carries the decaying exterior: cells three times longer radially than
  // wide are enough there.
  const double shell_width = 0.5 * (R1 + R2) * 2.0 * 3.14159265358979323846 /
                             discretisation.n_angular;
  const unsigned int shell_cells =
    std::max(2u, static_cast<unsigned int>(std::round((R2 - R1) / (3.0 * shell_width))));
  layers.push_back({R2, roller_region::shell, shell_cells});

  triangulation.clear();
  make_layered_disk(triangulation, layers, discretisation.n_angular);
  triangulation.refine_global(discretisation.refinements);
}

// The Gmsh mesh: cells and ids as written; each face whose two vertices lie on one of the
// mesh circles gets that circle's SphericalManifold (manifold id = circle index), so that
// refinement and the MappingQ(p) follow the circle. Cells stay flat: MappingQ blends their
// interior from the curved perimeter.
void RollerMagnetostatics::read_mesh_file()
{
  triangulation.clear();
  {
    dealii::GridIn<2> grid_in;
    grid_in.attach_triangulation(triangulation);
    std::ifstream in(mesh_file->path);
    if (!in)
      throw std::runtime_error("roller field: cannot open the roller mesh '" + mesh_file->path +
                               "'");
    grid_in.read_msh(in);
  }
  const auto &circles = mesh_file->circles;
  for (const auto &cell : triangulation.active_cell_iterators())
    for (const auto f : cell->face_indices())
    {
      const auto face = cell->face(f);
      for (std::size_t k = 0; k < circles.size(); ++k)
      {
        const Point<2> c(circles[k].center[0], circles[k].center[1]);
        const double R = circles[k].radius, tol = 1e-7 * R;
        if (std::abs(face->vertex(0).distance(c) - R) < tol &&
            std::abs(face->vertex(1).distance(c) - R) < tol &&
            face->vertex(0).distance(face->vertex(1)) < R)
        {
          face->set_manifold_id(static_cast<dealii::types::manifold_id>(k));
          break;
        }
      }
    }
  for (std::size_t k = 0; k < circles.size(); ++k)
    triangulation.set_manifold(static_cast<dealii::types::manifold_id>(k),
                               dealii::SphericalManifold<2>(
                                 Point<2>(circles[k].center[0], circles[k].center[1])));
  triangulation.refine_global(discretisation.refinements);
}

PotentialProblemDescription RollerMagnetostatics::describe() const
{
  PotentialProblemDescription d;
  d.name = "roller field";
  d.degree = discretisation.degree;
  d.solver_tolerance = discretisation.solver_tolerance;
  d.linear_solver = discretisation.linear_solver;
  d.linear_algebra = discretisation.linear_algebra;
  d.estimate_error = false; // the Kelly indicator only for the VTU (write_vtu)
  MaterialId magnet_region = roller_region::magnet;
  if (mesh_file)
  {
    namespace tags = mesh_tags;
    d.coefficient[tags::shaft] = 1.0 / (mu0 * roller.shaft_mu_r);
    d.coefficient[tags::magnet] = 1.0 / (mu0 * roller.magnet_mu_r);
    d.coefficient[tags::sleeve_wall] = 1.0 / mu0;
    d.coefficient[tags::air] = 1.0 / mu0;
    for (std::size_t i = 0; i < mesh_file->blade_mu_r.size(); ++i)
      d.coefficient[static_cast<MaterialId>(tags::blade_base + i)] =
        1.0 / (mu0 * mesh_file->blade_mu_r[i]);
    const OpenBoundaryShell &s = mesh_file->shell;
    d.shell = ShellRegion{tags::shell, 1.0 / mu0,
                          ShellTransformation(s.inner_radius, s.outer_radius, s.center[0],
                                              s.center[1])};
    magnet_region = tags::magnet;
    d.dirichlet[tags::outer_boundary] = [](const Point<2> &) { return 0.0; };
  }
  else
  {
    d.coefficient[roller_region::shaft] = 1.0 / (mu0 * roller.shaft_mu_r);
    d.coefficient[roller_region::magnet] = 1.0 / (mu0 * roller.magnet_mu_r);
    d.coefficient[roller_region::air] = 1.0 / mu0;
    const double R1 = shell_inner_radius();
    d.shell = ShellRegion{roller_region::shell, 1.0 / mu0,
                          ShellTransformation(R1, discretisation.shell_ratio * R1)};
    d.dirichlet[0] = [](const Point<2> &) { return 0.0; }; // A = 0 at R2 ≙ infinity
  }
  // ∫ (M_x ∂v/∂y − M_y ∂v/∂x)/μr = ∫ s·∇v with s = (−M_y, M_x)/μr, in the magnet only.
  const Magnetisation M = magnetisation;
  const double mu_magnet = roller.magnet_mu_r;
  d.vector_source = [M, mu_magnet, magnet_region](const Point<2> &x, MaterialId material) {
    Tensor<1, 2> s;
    if (material == magnet_region)
    {
      const Vec2 m = M(x[0], x[1]);
      s[0] = -m[1] / mu_magnet;
      s[1] = m[0] / mu_magnet;
    }
    return s;
  };
  return d;
}

void RollerMagnetostatics::run()
{
  if (mesh_file)
    read_mesh_file();
  else
    make_mesh();
  potential = std::make_unique<PotentialProblem>(triangulation, describe());
  potential->run();
}

std::vector<Vec2> RollerMagnetostatics::flux_density(const std::vector<Vec2> &points) const
{
  std::vector<Point<2>> p(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    p[i] = Point<2>(points[i][0], points[i][1]);
  const auto gradients = potential->gradients_at(p);
  std::vector<Vec2> B(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    B[i] = {{gradients[i][1], -gradients[i][0]}};
  return B;
}

std::vector<double> RollerMagnetostatics::vector_potential(const std::vector<Vec2> &points) const
{
  std::vector<Point<2>> p(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    p[i] = Point<2>(points[i][0], points[i][1]);
  return potential->values_at(p);
}

RollerMagnetostatics::Profile RollerMagnetostatics::profile(double radius,
                                                            unsigned int n_angles) const
{
  Profile out;
  std::vector<Vec2> points(n_angles);
  for (unsigned int k = 0; k < n_angles; ++k)
  {
    const double theta = 2.0 * pi * k / n_angles;
    out.angle.push_back(theta);
    points[k] = {{radius * std::cos(theta), radius * std::sin(theta)}};
  }
  const auto B = flux_density(points);
  for (unsigned int k = 0; k < n_angles; ++k)
  {
    const double c = std::cos(out.angle[k]), s = std::sin(out.angle[k]);
    out.Bn.push_back(B[k][0] * c + B[k][1] * s);
    out.Bt.push_back(-B[k][0] * s + B[k][1] * c);
  }
  return out;
}

void RollerMagnetostatics::write_vtu(const std::string &directory,
                                     const std::string &basename) const
{
  potential->estimate();
  potential->write_vtu(directory, basename, "magnetic");
}

} // namespace magbrush::field
