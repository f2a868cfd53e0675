#include "field_solver/field_app.h"

#include "case/case_hash.h"
#include "fields/zero_electric_field.h"
#include "common/atomic_file.h"
#include "fields/field_grid.h"
#include "fields/multipole_ring.h"
#include "field_solver/nip_electrostatics.h"
#include "field_solver/roller_magnetostatics.h"

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>

namespace magbrush::field {

namespace {

constexpr double pi = 3.14159265358979323846;

bool is_root(MPI_Comm comm) { return dealii::Utilities::MPI::this_mpi_process(comm) == 0; }

double seconds_since(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// "up to date" when the stored file's hash equals the case's; anything else (no file, an
// unreadable or foreign file, another hash) means recompute, and the reason is printed.
bool stored_field_is_current(const std::string &path, const std::string &hash,
                             const std::string &what, MPI_Comm comm)
{
  int current = 0;
  std::string reason;
  if (is_root(comm))
  {
    if (!std::filesystem::exists(path))
      reason = "no stored " + what + " field yet";
    else
      try
      {
        const GridFileInfo info = read_grid_info(path);
        if (info.provenance.case_hash == hash)
          current = 1;
        else
          reason = "the " + what + " inputs changed (stored hash " +
                   info.provenance.case_hash + ", case " + hash + ")";
      }
      catch (const std::exception &e)
      {
        reason = "the stored file cannot be used (" + std::string(e.what()) + ")";
      }
    if (current)
      std::cout << "magbrush-field: " << what << " field up to date (" << path << ", hash "
                << hash << ")" << std::endl;
    else
      std::cout << "magbrush-field: computing the " << what << " field: " << reason
                << std::endl;
  }
  MPI_Bcast(&current, 1, MPI_INT, 0, comm);
  return current == 1;
}

void write_profile_csv(const std::string &path, double radius,
                       const RollerMagnetostatics::Profile &p, const Case &c)
{
  write_file_atomically(path, [&](std::ostream &out) {
    out << "# Computed sleeve flux profile of case '" << c.name << "' (magbrush-field, FE_Q("
        << c.field.element_degree << ")), radius " << radius * 1e3 << " mm.\n"
        << "# angle counter-clockwise from +x; Bn positive outward, Bt positive "
           "counter-clockwise.\n"
        << "angle_deg,Bn_T,Bt_T\n";
    out.precision(10);
    for (std::size_t k = 0; k < p.angle.size(); ++k)
      out << p.angle[k] * 180.0 / pi << "," << p.Bn[k] << "," << p.Bt[k] << "\n";
  });
}

// Largest |ΔB| on a circle between the FE solution and the exact multipole ring, relative to
// the peak: the field's own error estimate when nothing but the roller is magnetic.
double ring_error_on(const RollerMagnetostatics::Profile &p, const Roller &roller, double r)
{
  const MultipoleRing ring(roller);
  std::vector<double> Bn, Bt;
  ring.profile(r, p.angle, Bn, Bt);
  double diff = 0.0, peak = 0.0;
  for (std::size_t k = 0; k < Bn.size(); ++k)
  {
    diff = std::max(diff, std::hypot(p.Bn[k] - Bn[k], p.Bt[k] - Bt[k]));
    peak = std::max(peak, std::hypot(Bn[k], Bt[k]));
  }
  return peak > 0.0 ? diff / peak : 0.0;
}

// On one process the 2D systems are solved fastest and most robustly by a sparse direct
// factorisation: against the iron's μr and the shell's anisotropy CG needs over a hundred
// iterations with Trilinos' ML, 20-30 with PETSc's BoomerAMG, and is slower than MUMPS with
// either (the test LinearAlgebraBackends.* prints both on the default cases); in parallel
// CG + AMG scales.
PotentialProblemDescription::LinearSolver preferred_solver(MPI_Comm comm)
{
  return dealii::Utilities::MPI::n_mpi_processes(comm) == 1
           ? PotentialProblemDescription::LinearSolver::direct
           : PotentialProblemDescription::LinearSolver::cg_amg;
}

// The backend and the solver that ran, as the log names them: "PETSc MUMPS (sparse direct)",
// "Trilinos CG + ML AMG 57 iterations".
std::string solver_summary(const SolveReport &r)
{
  const LinearAlgebraNames names = names_of(r.linear_algebra);
  return std::string(names.backend) + " " +
         (r.linear_solver == PotentialProblemDescription::LinearSolver::direct
            ? std::string(names.direct_solver) + " (sparse direct)"
            : std::string(names.iterative_solver) + " " + std::to_string(r.iterations) +
                " iterations");
}

} // namespace

// Cells around: the sleeve-surface element size asked for, counting the p nodes per element
// edge (an FE_Q(p) element of size p·h resolves like p linear elements of size h). Radially
// the layered mesh keeps cells about square.
RollerDiscretisation roller_discretisation(const Case &c)
{
  RollerDiscretisation d;
  const FieldSettings &f = c.field;
  d.degree = static_cast<unsigned int>(f.element_degree);
  const double R = c.sleeve->radius;
  const double h = f.mesh_size_sleeve * d.degree;
  d.n_angular = 4 * static_cast<unsigned int>(std::ceil(2.0 * pi * R / h / 4.0));
  d.n_angular = std::max(d.n_angular, 16u);
  d.outer_radius_factor = f.outer_radius_factor;
  if (f.probe_radius > 0.0)
    d.extra_circles.push_back(f.probe_radius);
  d.extra_circles.push_back(polar_grid_layout(c).r_max);
  return d;
}

bool compute_magnetic_field(const Case &c, const FieldRunOptions &options, MPI_Comm comm)
{
  if (!c.roller || !c.sleeve)
  {
    if (is_root(comm))
      std::cout << "magbrush-field: no roller in this case: no magnetic field to compute"
                << std::endl;
    return false;
  }
  const std::string h5 = field_file(c, "magnetic.h5");
  const std::string hash = field_hash(c, FieldKind::magnetic);
  if (!options.force && stored_field_is_current(h5, hash, "magnetic", comm))
    return false;

  const auto t0 = std::chrono::steady_clock::now();
  const PolarGridLayout layout = polar_grid_layout(c);
  RollerDiscretisation disc = roller_discretisation(c);
  disc.linear_solver = preferred_solver(comm);
  if (layout.r_max >= disc.outer_radius_factor * c.sleeve->radius)
    throw std::runtime_error(
      "the magnetic grid reaches r = " + std::to_string(layout.r_max) +
      " m, beyond the start of the open-boundary shell at " +
      std::to_string(disc.outer_radius_factor * c.sleeve->radius) +
      " m; raise field.outer_radius_factor or lower field.grid_outer_radius");

  // A soft-magnetic blade breaks the rotational symmetry of the layered mesh: then the solver
  // reads the Gmsh roller mesh with the blade as its own region (geometry/mesh_roller.h).
  const bool magnetic_blade = std::any_of(c.blades.begin(), c.blades.end(),
                                          [](const BladeOrGuide &b) { return b.mu_r > 1.0; });
  std::unique_ptr<RollerMagnetostatics> solver_ptr;
  if (magnetic_blade)
    solver_ptr = std::make_unique<RollerMagnetostatics>(
      comm, RollerGeometry::from(*c.roller, *c.sleeve),
      gaussian_pole_magnetisation(c.roller->poles), disc,
      write_roller_mesh_file(c, field_file(c, "magnetic_mesh.msh"), disc.degree, comm));
  else
    solver_ptr = std::make_unique<RollerMagnetostatics>(
      comm, RollerGeometry::from(*c.roller, *c.sleeve),
      gaussian_pole_magnetisation(c.roller->poles), disc);
  RollerMagnetostatics &solver = *solver_ptr;
  solver.run();
  const SolveReport &report = solver.problem().report();

  // The grid: A_z at every node, evaluated in one batch.
  std::vector<Vec2> nodes;
  nodes.reserve(static_cast<std::size_t>(layout.n_r) * layout.n_theta);
  PolarGrid grid;
  grid.r_min = layout.r_min;
  grid.r_max = layout.r_max;
  grid.n_r = layout.n_r;
  grid.n_theta = layout.n_theta;
  for (int i = 0; i < grid.n_r; ++i)
    for (int j = 0; j < grid.n_theta; ++j)
      nodes.push_back({{grid.r(i) * std::cos(grid.theta(j)), grid.r(i) * std::sin(grid.theta(j))}});
  const auto t_sample = std::chrono::steady_clock::now();
  grid.A_z = solver.vector_potential(nodes);
  const double sample_seconds = seconds_since(t_sample);

  const auto sleeve_profile = solver.profile(c.sleeve->radius, 360);
  const double probe_radius = c.field.probe_radius > 0 ? c.field.probe_radius : c.sleeve->radius;
  const auto probe_profile = solver.profile(probe_radius, 360);
  const double error = ring_error_on(sleeve_profile, *c.roller, c.sleeve->radius);

  if (options.vtu)
    solver.write_vtu(c.field.output_dir, c.name + "_magnetic");
  if (is_root(comm))
  {
    GridProvenance provenance;
    provenance.case_hash = hash;
    provenance.case_inputs = field_inputs(c, FieldKind::magnetic);
    provenance.mesh_sizes = {{"sleeve", 2.0 * pi * c.sleeve->radius / disc.n_angular /
                                          (1u << disc.refinements)}};
    provenance.element_degree = static_cast<int>(disc.degree);
    provenance.error_estimate = error;
    write_magnetic_grid(h5, grid, provenance);
    write_profile_csv(field_file(c, "profile_sleeve.csv"), c.sleeve->radius, sleeve_profile, c);
    write_profile_csv(field_file(c, "profile_probe.csv"), probe_radius, probe_profile, c);
    std::printf("magbrush-field: magnetic field%s: %u cells, %llu unknowns (FE_Q(%u)), %s; "
                "max |dB|/peak on the sleeve vs the exact multipole ring: %.2e%s; "
                "%.2f s\n  wrote %s (%d x %d polar grid), %s, %s%s\n",
                magnetic_blade ? (" on the Gmsh mesh " + field_file(c, "magnetic_mesh.msh")).c_str() : "",
                report.n_cells, static_cast<unsigned long long>(report.n_dofs), disc.degree,
                solver_summary(report).c_str(), error,
                magnetic_blade ? " (includes the soft-magnetic blade's effect: not an error estimate)" : "",
                seconds_since(t0), h5.c_str(), grid.n_r,
                grid.n_theta, field_file(c, "profile_sleeve.csv").c_str(),
                field_file(c, "profile_probe.csv").c_str(),
                options.vtu ? (", " + field_file(c, "magnetic_0.pvtu")).c_str() : "");
    std::printf("  time: setup %.2f s, assembly %.2f s, solve %.2f s, grid sampling %.2f s\n",
                report.setup_seconds, report.assemble_seconds, report.solve_seconds,
                sample_seconds);
    std::fflush(stdout);
  }
  return true;
}

// Cells across the gap and around from the gap mesh size (p nodes per element edge, as for
// the roller); cells near the nip are about square because the bipolar map is conformal.
NipDiscretisation nip_discretisation(const Case &c, const NipLayout &layout)
{
  NipDiscretisation d;
  d.degree = static_cast<unsigned int>(c.field.element_degree);
  const double h = c.field.mesh_size_gap * d.degree;
  d.n_tau = std::max(2u, static_cast<unsigned int>(std::ceil(c.drum.gap / h)));
  const double nip_metric = layout.bipolar.focus / (std::cosh(layout.bipolar.tau_right) + 1.0);
  d.n_sigma = std::max(32u, 4 * static_cast<unsigned int>(
                                  std::ceil(2.0 * pi * nip_metric / h / 4.0)));
  d.n_layer = std::max(1u, static_cast<unsigned int>(std::ceil(c.drum.pc_thickness / h)));
  return d;
}

bool compute_electric_field(const Case &c, const FieldRunOptions &options, MPI_Comm comm)
{
  if (!c.electric.enabled)
  {
    if (is_root(comm))
      std::cout << "magbrush-field: electric field not enabled in this case" << std::endl;
    return false;
  }
  if (!c.sleeve || !c.drum.present)
    throw std::runtime_error("electric.enabled is set, but the nip field needs a sleeve and "
                             "a drum (drum.present); add the drum or disable electric");
  if (electric_field_is_zero(c))
  {
    if (is_root(comm))
      std::cout << "magbrush-field: electric field: skipped, it is zero (electric.bias = 0 V and no latent "
                   "image); the DEM runs no qE"
                << std::endl;
    return false;
  }

  const std::string h5 = field_file(c, "electric.h5");
  const std::string hash = field_hash(c, FieldKind::electric);
  if (!options.force && stored_field_is_current(h5, hash, "electric", comm))
    return false;

  const auto t0 = std::chrono::steady_clock::now();
  const NipLayout layout = NipLayout::from(c.sleeve->radius, c.drum.radius, c.drum.gap,
                                           c.drum.angle, c.drum.pc_thickness);
  NipDiscretisation disc = nip_discretisation(c, layout);
  disc.linear_solver = preferred_solver(comm);

  // The window: a square over the nip centred on the gap's midpoint, 2 mm + the gap to each
  // side, nodes at field.grid_electric_spacing (or finer). Nodes inside the sleeve or below the
  // drum surface carry the smooth extension of the air solution (air_potential), so that the
  // spline is accurate up to the surfaces.
  const double half = 2e-3 + c.drum.gap;
  const double rc = c.sleeve->radius + 0.5 * c.drum.gap;
  const double xc = rc * std::cos(c.drum.angle), yc = rc * std::sin(c.drum.angle);
  const int n = std::max(
    4, 1 + static_cast<int>(std::ceil(2.0 * half / c.field.grid_electric_spacing - 1e-9)));
  std::vector<Vec2> nodes;
  nodes.reserve(static_cast<std::size_t>(n) * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      nodes.push_back({{xc - half + 2.0 * half * i / (n - 1), yc - half + 2.0 * half * j / (n - 1)}});
  NipPotentialGrid grid;
  grid.bias.x_min = xc - half;
  grid.bias.x_max = xc + half;
  grid.bias.y_min = yc - half;
  grid.bias.y_max = yc + half;
  grid.bias.n_x = grid.bias.n_y = n;

  // The problem is linear: the bias alone (the image's values set to zero, so the mesh is the
  // same), then the image alone (sleeve grounded) at each phase u_k = k P / K of its travel.
  const LatentImage &image = c.electric.image;
  LatentImage no_image = image;
  no_image.dark_value = no_image.light_value = 0.0;
  // A uniform image (solid or dark) looks the same at every phase: one solve.
  const bool moving = image.striped() && image.kind != LatentImage::Kind::none;
  const int K = moving ? c.field.electric_phase_samples : 1;
  grid.image_period = moving ? image.period : 0.0;
  grid.drum_center = layout.drum_center;
  grid.drum_radius = c.drum.radius;
  SolveReport report;
  double solve_seconds = 0.0, sample_seconds = 0.0;
  const auto solve_and_sample = [&](double bias, const LatentImage &img, double shift) {
    const auto t_solve = std::chrono::steady_clock::now();
    NipElectrostatics solver(comm, layout, c.drum.pc_eps_r, bias, img, disc, shift);
    solver.run();
    report = solver.problem().report();
    solve_seconds += seconds_since(t_solve);
    const auto t_sample = std::chrono::steady_clock::now();
    std::vector<double> phi = solver.air_potential(nodes);
    sample_seconds += seconds_since(t_sample);
    return phi;
  };
  grid.bias.phi = solve_and_sample(c.electric.bias, no_image, 0.0);
  for (int k = 0; k < K; ++k)
  {
    if (image.kind == LatentImage::Kind::none)
      grid.image.emplace_back(grid.bias.phi.size(), 0.0);
    else
      grid.image.push_back(solve_and_sample(0.0, image, k * grid.image_period / K));
  }
  if (options.vtu) // for ParaView: the whole field at phase 0 (one more solve)
  {
    NipElectrostatics total(comm, layout, c.drum.pc_eps_r, c.electric.bias, image, disc);
    total.run();
    total.write_vtu(c.field.output_dir, c.name + "_electric");
  }

  if (is_root(comm))
  {
    GridProvenance provenance;
    provenance.case_hash = hash;
    provenance.case_inputs = field_inputs(c, FieldKind::electric);
    provenance.mesh_sizes = {{"gap", c.drum.gap / disc.n_tau}};
    provenance.element_degree = static_cast<int>(disc.degree);
    write_electric_grid(h5, grid, provenance);
    std::printf("magbrush-field: electric field: %u cells, %llu unknowns (FE_Q(%u)), %s; bias + "
                "%d image phase%s over %.4g mm; %.2f s\n  wrote %s (%d x %d window over the nip)%s\n",
                report.n_cells, static_cast<unsigned long long>(report.n_dofs), disc.degree,
                solver_summary(report).c_str(), K, K == 1 ? "" : "s", grid.image_period * 1e3,
                seconds_since(t0), h5.c_str(), n, n,
                options.vtu ? (", " + field_file(c, "electric_0.pvtu")).c_str() : "");
    std::printf("  time: solves %.2f s, grid sampling %.2f s\n", solve_seconds, sample_seconds);
    std::fflush(stdout);
  }
  return true;
}

} // namespace magbrush::field
