// Accuracy against cost of the stored nip field the DEM's qE term uses (docs/electrostatics.md):
//  1. the phase sampling: K image phases and the interpolation in phase (linear,
//     trigonometric, co-moving), error of E against direct solves at phases between the
//     samples, against the field stage's time to build the grids and the DEM's time per lookup;
//  2. the grid spacing h: error of E through the spline against the finite-element field
//     itself, against the sampling time and the memory.
// The nip of tests/field_solver/nip_phase_setup.h with strip edges of 100 µm (a sharp edge is
// placed at the mesh nodes by the field stage, which no phase sampling can follow; the edge
// width lets the mesh resolve it, see docs/electrostatics.md). Errors relative to the contrast
// field |V_dark − V_light| / gap, over the gap from the sleeve down to 40 µm from the drum.
#include "tests/field_solver/nip_phase_setup.h"

#include "fields/cartesian_field_interpolator.h"
#include "fields/nip_potential_field.h"

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cmath>
#include <cstdio>

using namespace magbrush;
using namespace magbrush::field;
using namespace magbrush::field::testing;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<Vec3> gap_points(const NipPhaseSetup &s, double d_drum)
{
  std::vector<Vec3> p;
  for (double y = -0.35e-3; y <= 0.35e-3 + 1e-12; y += 0.05e-3)
    for (double x = s.sleeve_surface_x(y); x <= s.drum_surface_x(y) - d_drum; x += 5e-6)
      p.push_back({{x, y, 0.0}});
  return p;
}

} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  NipPhaseSetup s;
  s.image.edge_width = 100e-6;
  s.disc.refinements = 2;
  const auto points = gap_points(s, 40e-6);
  const double Ec = s.contrast_field();

  // Direct solves at phases between the samples of every K below (odd multiples of P/64).
  std::vector<double> phases;
  std::vector<NipPotentialField> direct;
  NipPotentialGrid bias_only;
  {
    bias_only.bias = s.empty_grid();
    bias_only.bias.phi = s.solve(s.bias, 0.0, 0.0);
    for (const int m : {5, 21, 43})
    {
      const double u = m * s.image.period / 64.0;
      NipPotentialGrid g = bias_only;
      g.image.push_back(s.solve(0.0, 1.0, u));
      phases.push_back(u);
      direct.emplace_back(g, NipPotentialField::PhaseInterpolation::linear);
    }
  }

  std::printf("# phase sampling: gap 350 um, P = 1 mm, edges 100 um, 4 cells of FE_Q(2) across "
              "the gap (x4 refined), grid h = 10 um (%d x %d); max |dE| / E_contrast (%.3g V/m) at 3 phases\n",
              s.n_x(), s.n_y(), Ec);
  std::printf("%4s %14s %12s %12s %14s\n", "K", "interpolation", "max |dE|/Ec", "build [s]",
              "lookup [ns]");
  for (const int K : {4, 8, 16, 32})
  {
    const auto t_build = std::chrono::steady_clock::now();
    const NipPotentialGrid stored = s.stored(K);
    const double build = seconds_since(t_build);
    for (const auto phase : {NipPotentialField::PhaseInterpolation::linear,
                             NipPotentialField::PhaseInterpolation::trigonometric,
                             NipPotentialField::PhaseInterpolation::co_moving})
    {
      const NipPotentialField field(stored, phase);
      auto w = field.make_phase_weights();
      double err = 0.0;
      for (std::size_t p = 0; p < phases.size(); ++p)
      {
        field.phase_weights(phases[p], w);
        auto w_ref = direct[p].make_phase_weights();
        direct[p].phase_weights(0.0, w_ref);
        for (const Vec3 &x : points)
        {
          Vec3 E, E_ref;
          field.evaluate(x, w, E);
          direct[p].evaluate(x, w_ref, E_ref);
          err = std::max(err, std::hypot(E[0] - E_ref[0], E[1] - E_ref[1]) / Ec);
        }
      }
      // The DEM's cost per charged particle: one lookup (weights filled once per step).
      field.phase_weights(phases[1], w);
      const int repeats = 200;
      double sink = 0.0;
      const auto t_look = std::chrono::steady_clock::now();
      for (int r = 0; r < repeats; ++r)
        for (const Vec3 &x : points)
        {
          Vec3 E;
          field.evaluate(x, w, E);
          sink += E[0];
        }
      const double ns = 1e9 * seconds_since(t_look) / (repeats * static_cast<double>(points.size()));
      std::printf("%4d %14s %12.2e %12.2f %14.1f%s\n", K, field.interpolation_name(), err, build, ns,
                  sink == 12345.0 ? " " : "");
    }
  }

  // The grid spacing: the spline of the bias solution against the finite-element field.
  std::printf("\n# grid spacing: max |dE| / E_contrast of the spline of Phi_bias against the FE "
              "field, same points\n%8s %10s %12s %12s %12s\n", "h [um]", "nodes", "max |dE|/Ec",
              "sample [s]", "memory [MB]");
  LatentImage off = s.image;
  off.dark_value = off.light_value = 0.0;
  NipElectrostatics nip(MPI_COMM_WORLD, s.layout(), 3.0, s.bias, off, s.disc);
  nip.run();
  std::vector<Vec2> p2;
  for (const Vec3 &x : points)
    p2.push_back({{x[0], x[1]}});
  const std::vector<Vec2> E_fe = nip.electric_field(p2);
  for (const double h : {40e-6, 20e-6, 10e-6, 5e-6})
  {
    NipPhaseSetup g = s;
    g.h = h;
    const auto t0 = std::chrono::steady_clock::now();
    CartesianGrid grid = g.empty_grid();
    grid.phi = nip.air_potential(g.nodes());
    const double sample = seconds_since(t0);
    const CartesianFieldInterpolator interp(grid);
    double err = 0.0;
    for (std::size_t k = 0; k < points.size(); ++k)
    {
      const Vec3 E = interp.field(points[k]);
      err = std::max(err, std::hypot(E[0] - E_fe[k][0], E[1] - E_fe[k][1]) / Ec);
    }
    std::printf("%8.0f %10zu %12.2e %12.2f %12.2f\n", h * 1e6, grid.phi.size(), err, sample,
                grid.memory_bytes() * 4 / 1e6);
  }
  return 0;
}
