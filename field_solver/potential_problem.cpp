#include "field_solver/potential_problem.h"

#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/mpi_remote_point_evaluation.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>
#include <deal.II/numerics/error_estimator.h>
#include <deal.II/numerics/vector_tools.h>
#include <deal.II/numerics/vector_tools_evaluate.h>

#include <chrono>
#include <set>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <variant>

namespace magbrush::field {

using namespace dealii;

namespace {

double seconds_since(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Calls f with the linear system that setup_system made, in whichever backend it is: the code
// in f is written once and compiled for both.
template <class LinearSystemVariant, class F>
void with_system(LinearSystemVariant &system, F &&f)
{
  std::visit(
    [&](auto &s) {
      if constexpr (std::is_same_v<std::decay_t<decltype(s)>, std::monostate>)
        throw std::logic_error("PotentialProblem: setup_system() must come first");
      else
        f(s);
    },
    system);
}

std::string point_string(const Point<2> &p)
{
  std::ostringstream s;
  s << "(" << p[0] << ", " << p[1] << ") m";
  return s.str();
}

// B = curl(A ẑ) = (∂A/∂y, −∂A/∂x) for the magnetic potential, E = −∇Φ for the electric one,
// plus the magnitude, computed from the exact gradient of the FE solution at output points.
class FieldFromGradient : public DataPostprocessor<2>
{
public:
  explicit FieldFromGradient(bool magnetic) : magnetic(magnetic) {}

  void evaluate_scalar_field(const DataPostprocessorInputs::Scalar<2> &inputs,
                             std::vector<Vector<double>> &computed) const override
  {
    for (unsigned int q = 0; q < inputs.solution_gradients.size(); ++q)
    {
      const Tensor<1, 2> &g = inputs.solution_gradients[q];
      const double vx = magnetic ? g[1] : -g[0];
      const double vy = magnetic ? -g[0] : -g[1];
      computed[q](0) = vx;
      computed[q](1) = vy;
      computed[q](2) = std::hypot(vx, vy);
    }
  }

  std::vector<std::string> get_names() const override
  {
    const std::string v = magnetic ? "B" : "E";
    return {v, v, v + "_magnitude"};
  }

  std::vector<DataComponentInterpretation::DataComponentInterpretation>
  get_data_component_interpretation() const override
  {
    return {DataComponentInterpretation::component_is_part_of_vector,
            DataComponentInterpretation::component_is_part_of_vector,
            DataComponentInterpretation::component_is_scalar};
  }

  UpdateFlags get_needed_update_flags() const override { return update_gradients; }

private:
  bool magnetic;
};

} // namespace

PotentialProblem::PotentialProblem(parallel::shared::Triangulation<2> &triangulation,
                                   PotentialProblemDescription description_in)
  : mpi_communicator(triangulation.get_communicator())
  , triangulation(triangulation)
  , description(std::move(description_in))
  , fe(std::max(1u, description.degree))
  , curved_mapping(std::max(1u, description.degree))
  , dofs(triangulation)
{
  if (description.degree < 1 || description.degree > 6)
    throw std::invalid_argument(description.name + ": element degree must be 1..6, found " +
                                std::to_string(description.degree) +
                                "; set field.element_degree (2 is the default)");
}

void PotentialProblem::run()
{
  setup_system();
  assemble_system();
  solve();
  if (description.estimate_error)
    estimate();
}

// Check the description against the mesh before any work: every region needs a coefficient,
// every Dirichlet boundary must exist (a misnumbered one leaves the problem singular).
void PotentialProblem::setup_system()
{
  const auto start = std::chrono::steady_clock::now();

  std::set<BoundaryId> boundaries_in_mesh;
  for (const auto &cell : triangulation.active_cell_iterators())
  {
    const MaterialId m = cell->material_id();
    const bool is_shell = description.shell && description.shell->material == m;
    if (!is_shell && description.coefficient.find(m) == description.coefficient.end())
      throw std::runtime_error(description.name + ": the mesh has a cell in region " +
                               std::to_string(m) + " at " + point_string(cell->center()) +
                               " but no coefficient (μr/εr) is given for that region; "
                               "check the mesh's physical groups against the case");
    if (cell->measure() <= 0.0)
      throw std::runtime_error(description.name + ": cell at " +
                               point_string(cell->center()) + " in region " +
                               std::to_string(m) + " has zero or negative area; "
                               "the mesh is degenerate (check thin layers and gaps)");
    for (const unsigned int f : cell->face_indices())
      if (cell->face(f)->at_boundary())
        boundaries_in_mesh.insert(cell->face(f)->boundary_id());
  }
  for (const auto &[id, value] : description.dirichlet)
    if (boundaries_in_mesh.count(id) == 0)
      throw std::runtime_error(description.name + ": Dirichlet condition on boundary " +
                               std::to_string(id) + ", but the mesh has no such boundary");
  for (const auto &[id, value] : description.coefficient)
    if (!(value > 0.0) || !std::isfinite(value))
      throw std::runtime_error(description.name + ": coefficient of region " +
                               std::to_string(id) + " must be positive and finite, found " +
                               std::to_string(value));

  curved_mapping.initialize(MappingQ<2>(fe.degree), triangulation);
  dofs.distribute_dofs(fe);
  locally_owned_dofs = dofs.locally_owned_dofs();
  DoFTools::extract_locally_relevant_dofs(dofs, locally_relevant_dofs);

  // Periodicity first, then Dirichlet values (interpolate_boundary_values leaves dofs that
  // are already constrained alone, so slab corners follow their periodic partner).
  constraints.clear();
  constraints.reinit(locally_relevant_dofs);
  DoFTools::make_hanging_node_constraints(dofs, constraints);
  for (const auto &pair : description.periodic)
    DoFTools::make_periodicity_constraints(dofs, pair.left, pair.right, pair.direction,
                                           constraints);
  for (const auto &[id, value] : description.dirichlet)
  {
    const ScalarFunctionFromFunctionObject<2> g(value);
    VectorTools::interpolate_boundary_values(curved_mapping, dofs, id, g, constraints);
  }
  constraints.close();

  DynamicSparsityPattern dsp(locally_relevant_dofs);
  DoFTools::make_sparsity_pattern(dofs, dsp, constraints, false);
  SparsityTools::distribute_sparsity_pattern(dsp, locally_owned_dofs, mpi_communicator,
                                             locally_relevant_dofs);
  if (description.linear_algebra == LinearAlgebraBackend::petsc)
    linear_system.emplace<LinearSystem<LinearAlgebraBackend::petsc>>();
  else
    linear_system.emplace<LinearSystem<LinearAlgebraBackend::trilinos>>();
  with_system(linear_system, [&](auto &system) {
    system.matrix.reinit(locally_owned_dofs, locally_owned_dofs, dsp, mpi_communicator);
    system.rhs.reinit(locally_owned_dofs, mpi_communicator);
  });
  ghosted_solution.reinit(locally_owned_dofs, locally_relevant_dofs, mpi_communicator);

  solve_report.linear_algebra = description.linear_algebra;
  solve_report.linear_solver = description.linear_solver;
  solve_report.n_dofs = dofs.n_dofs();
  solve_report.n_cells = triangulation.n_active_cells();
  solve_report.setup_seconds = seconds_since(start);
}

Tensor<2, 2> PotentialProblem::coefficient_at(const Point<2> &x, MaterialId material) const
{
  Tensor<2, 2> K;
  if (description.shell && description.shell->material == material)
  {
    const auto k = description.shell->transformation.relative_tensor(x[0], x[1]);
    const double c = description.shell->coefficient;
    K[0][0] = c * k[0];
    K[0][1] = K[1][0] = c * k[1];
    K[1][1] = c * k[2];
    return K;
  }
  const double c = description.coefficient.at(material);
  K[0][0] = K[1][1] = c;
  return K;
}

// ∫ K ∇φ_j·∇φ_i and ∫ s·∇φ_i per cell, then the interface charges; constraints are applied
// while copying into the global system (inhomogeneous Dirichlet values included).
void PotentialProblem::assemble_system()
{
  const auto start = std::chrono::steady_clock::now();
  const QGauss<2> quadrature(fe.degree + 2);
  FEValues<2> fe_values(curved_mapping, fe, quadrature,
                        update_values | update_gradients | update_quadrature_points |
                          update_JxW_values);
  const unsigned int n = fe.n_dofs_per_cell();
  FullMatrix<double> cell_matrix(n, n);
  Vector<double> cell_rhs(n);
  std::vector<types::global_dof_index> local_dof_indices(n);

  with_system(linear_system, [&](auto &system) {
    system.matrix = 0;
    system.rhs = 0;
    for (const auto &cell : dofs.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      cell_matrix = 0;
      cell_rhs = 0;
      fe_values.reinit(cell);
      const MaterialId material = cell->material_id();
      for (const unsigned int q : fe_values.quadrature_point_indices())
      {
        const Point<2> &x = fe_values.quadrature_point(q);
        const Tensor<2, 2> K = coefficient_at(x, material);
        const Tensor<1, 2> s =
          description.vector_source ? description.vector_source(x, material) : Tensor<1, 2>();
        const double JxW = fe_values.JxW(q);
        for (unsigned int i = 0; i < n; ++i)
        {
          const Tensor<1, 2> K_grad_i = K * fe_values.shape_grad(i, q);
          for (unsigned int j = 0; j < n; ++j)
            cell_matrix(i, j) += K_grad_i * fe_values.shape_grad(j, q) * JxW;
          cell_rhs(i) += s * fe_values.shape_grad(i, q) * JxW;
        }
      }
      assemble_surface_charges(cell, cell_rhs);
      cell->get_dof_indices(local_dof_indices);
      constraints.distribute_local_to_global(cell_matrix, cell_rhs, local_dof_indices,
                                             system.matrix, system.rhs);
    }
    system.matrix.compress(VectorOperation::add);
    system.rhs.compress(VectorOperation::add);
  });
  solve_report.assemble_seconds = seconds_since(start);
}

// A surface charge σ on the interface between `inner` and `outer` regions is the jump
// [ε ∂Φ/∂n] = σ; in the weak form it is the face integral ∫ σ v ds, taken once, from the
// inner side.
void PotentialProblem::assemble_surface_charges(const DoFHandler<2>::active_cell_iterator &cell,
                                                Vector<double> &cell_rhs) const
{
  if (description.surface_charges.empty())
    return;
  const QGauss<1> face_quadrature(fe.degree + 2);
  FEFaceValues<2> face_values(curved_mapping, fe, face_quadrature,
                              update_values | update_quadrature_points | update_JxW_values);
  for (const auto &charge : description.surface_charges)
  {
    if (cell->material_id() != charge.inner)
      continue;
    for (const unsigned int f : cell->face_indices())
    {
      if (cell->at_boundary(f) || cell->neighbor(f)->material_id() != charge.outer)
        continue;
      face_values.reinit(cell, f);
      for (const unsigned int q : face_values.quadrature_point_indices())
      {
        const double sigma = charge.density(face_values.quadrature_point(q));
        for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
          cell_rhs(i) += sigma * face_values.shape_value(i, q) * face_values.JxW(q);
      }
    }
  }
}

// MUMPS, or CG with algebraic multigrid (the operator is symmetric positive definite), in the
// backend of the system (linear_system.h). Failure is reported with what was reached and what
// to change. The solution, its constraints distributed, is copied into deal.II's own ghosted
// vector, from which everything after the solve reads.
void PotentialProblem::solve()
{
  const auto start = std::chrono::steady_clock::now();
  const LinearAlgebraNames names = names_of(description.linear_algebra);
  with_system(linear_system, [&](const auto &system) {
    using BackendVector = typename std::decay_t<decltype(system)>::Vector;
    BackendVector distributed_solution(locally_owned_dofs, mpi_communicator);
    const double rhs_norm = system.rhs.l2_norm();
    if (rhs_norm == 0.0)
    {
      distributed_solution = 0;
      solve_report.iterations = 0;
      solve_report.residual = 0.0;
    }
    else if (description.linear_solver == PotentialProblemDescription::LinearSolver::direct)
    {
      system.solve_direct(distributed_solution);
      // the residual of the factorised solve, for the report
      BackendVector residual(locally_owned_dofs, mpi_communicator);
      system.matrix.vmult(residual, distributed_solution);
      residual -= system.rhs;
      solve_report.iterations = 1;
      solve_report.residual = residual.l2_norm();
      if (!(solve_report.residual <= 1e-8 * rhs_norm))
        throw std::runtime_error(
          description.name + ": the direct solver's (" + names.backend + " " +
          names.direct_solver + ") residual " + std::to_string(solve_report.residual) +
          " is not small against the right-hand side " + std::to_string(rhs_norm) +
          "; the system is singular or badly scaled (check that every region touches a "
          "Dirichlet boundary or is coupled to one)");
    }
    else
    {
      SolverControl control(description.max_iterations,
                            description.solver_tolerance * rhs_norm, false, false);
      try
      {
        system.solve_cg_amg(distributed_solution, control, fe.degree);
      }
      catch (const SolverControl::NoConvergence &e)
      {
        std::ostringstream msg;
        msg << description.name << ": the linear solver (" << names.backend << " "
            << names.iterative_solver << ") did not converge: after " << e.last_step
            << " iterations the residual is " << e.last_residual << " (relative "
            << e.last_residual / rhs_norm << ", wanted " << description.solver_tolerance
            << ", " << solve_report.n_dofs
            << " unknowns). Check that every region has a sensible μr/εr (very large "
               "contrasts slow AMG down), that the mesh has no sliver cells, or raise the "
               "iteration limit.";
        throw std::runtime_error(msg.str());
      }
      solve_report.iterations = control.last_step();
      solve_report.residual = control.last_value();
    }
    constraints.distribute(distributed_solution);
    std::vector<types::global_dof_index> owned;
    locally_owned_dofs.fill_index_vector(owned);
    distributed_solution.extract_subvector_to(owned.begin(), owned.end(),
                                              ghosted_solution.begin());
  });
  ghosted_solution.update_ghost_values();
  solve_report.solve_seconds = seconds_since(start);
}

// Kelly's jump indicator per cell (for output and for the log; the verification tests use
// exact errors instead).
void PotentialProblem::estimate()
{
  error_indicator.reinit(triangulation.n_active_cells());
  KellyErrorEstimator<2>::estimate(curved_mapping, dofs, QGauss<1>(fe.degree + 1), {},
                                   ghosted_solution, error_indicator, ComponentMask(), nullptr,
                                   numbers::invalid_unsigned_int,
                                   triangulation.locally_owned_subdomain());
  const double local = error_indicator.norm_sqr();
  solve_report.estimated_error = std::sqrt(Utilities::MPI::sum(local, mpi_communicator));
}

std::vector<double> PotentialProblem::values_at(const std::vector<Point<2>> &points,
                                                std::vector<bool> *found) const
{
  Utilities::MPI::RemotePointEvaluation<2> cache;
  auto values = VectorTools::point_values<1>(curved_mapping, dofs, ghosted_solution, points,
                                             cache);
  if (found)
  {
    // a point found in no cell has an empty range of owners
    const auto &ptrs = cache.get_point_ptrs();
    found->assign(points.size(), true);
    if (!cache.all_points_found())
      for (std::size_t i = 0; i < points.size(); ++i)
        (*found)[i] = ptrs[i + 1] > ptrs[i];
    return values;
  }
  if (!cache.all_points_found())
    throw std::runtime_error(description.name +
                             ": some evaluation points lie outside the mesh; the sampling "
                             "grid must stay inside the solved domain");
  return values;
}

std::vector<Tensor<1, 2>>
PotentialProblem::gradients_at(const std::vector<Point<2>> &points) const
{
  Utilities::MPI::RemotePointEvaluation<2> cache;
  auto gradients = VectorTools::point_gradients<1>(curved_mapping, dofs, ghosted_solution,
                                                   points, cache);
  if (!cache.all_points_found())
    throw std::runtime_error(description.name +
                             ": some evaluation points lie outside the mesh; the sampling "
                             "grid must stay inside the solved domain");
  return gradients;
}

double PotentialProblem::energy_integral() const
{
  const QGauss<2> quadrature(fe.degree + 2);
  FEValues<2> fe_values(curved_mapping, fe, quadrature,
                        update_gradients | update_quadrature_points | update_JxW_values);
  std::vector<Tensor<1, 2>> gradients(quadrature.size());
  double local = 0.0;
  for (const auto &cell : dofs.active_cell_iterators())
  {
    if (!cell->is_locally_owned())
      continue;
    fe_values.reinit(cell);
    fe_values.get_function_gradients(ghosted_solution, gradients);
    for (const unsigned int q : fe_values.quadrature_point_indices())
      local += gradients[q] * (coefficient_at(fe_values.quadrature_point(q),
                                              cell->material_id()) *
                               gradients[q]) *
               fe_values.JxW(q);
  }
  return Utilities::MPI::sum(local, mpi_communicator);
}

void PotentialProblem::write_vtu(const std::string &directory, const std::string &basename,
                                 const std::string &field_kind) const
{
  const bool magnetic = field_kind == "magnetic";
  const FieldFromGradient derived_field(magnetic);

  Vector<float> region(triangulation.n_active_cells());
  Vector<float> subdomain(triangulation.n_active_cells());
  for (const auto &cell : triangulation.active_cell_iterators())
  {
    region(cell->active_cell_index()) = cell->material_id();
    subdomain(cell->active_cell_index()) = cell->subdomain_id();
  }

  DataOut<2> data_out;
  data_out.attach_dof_handler(dofs);
  data_out.add_data_vector(ghosted_solution, magnetic ? "A" : "Phi");
  data_out.add_data_vector(ghosted_solution, derived_field);
  data_out.add_data_vector(region, "region");
  data_out.add_data_vector(subdomain, "subdomain");
  if (error_indicator.size() == triangulation.n_active_cells())
    data_out.add_data_vector(error_indicator, "kelly_indicator");
  data_out.build_patches(curved_mapping, fe.degree, DataOut<2>::curved_inner_cells);
  data_out.write_vtu_with_pvtu_record(directory + "/", basename, 0, mpi_communicator, 0, 1);
}

} // namespace magbrush::field
