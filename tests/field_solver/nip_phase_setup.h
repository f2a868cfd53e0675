// The nip of the phase and near-surface checks, defined once for the test
// (test_nip_phases.cpp) and the benchmark (bench_nip_phases.cpp): Kweon-like geometry (sleeve
// 12.5 mm, drum 15 mm, gap 350 µm, drum on the +x axis), latent image as surface-potential
// strips (dark −800 V, light 0 V, period 1 mm, duty 0.5), sleeve at −650 V; a Cartesian
// window over the gap; the grids the field stage stores for it (bias + K image phases,
// sampled with air_potential, as field_app.cpp does).
#pragma once

#include "fields/field_grid.h"
#include "field_solver/nip_electrostatics.h"

#include <mpi.h>

#include <cmath>
#include <vector>

namespace magbrush::field::testing {

struct NipPhaseSetup
{
  double Rs = 12.5e-3, Rd = 15e-3, gap = 350e-6;
  double bias = -650.0;
  LatentImage image;
  NipDiscretisation disc;
  // The window: x from 100 µm inside the sleeve to 100 µm inside the drum, y = ±0.5 mm.
  double x0 = 0, x1 = 0, y0 = -0.5e-3, y1 = 0.5e-3, h = 10e-6;

  NipPhaseSetup()
  {
    image.kind = LatentImage::Kind::surface_potential;
    image.dark_value = -800.0;
    image.light_value = 0.0;
    image.period = 1e-3;
    image.duty = 0.5;
    disc.degree = 2;
    disc.n_tau = 4;
    disc.n_sigma = 64;
    disc.linear_solver = PotentialProblemDescription::LinearSolver::direct;
    x0 = Rs - 100e-6;
    x1 = Rs + gap + 100e-6;
  }
  NipLayout layout() const { return NipLayout::from(Rs, Rd, gap, 0.0, 0.0); }
  int n_x() const { return 1 + static_cast<int>(std::ceil((x1 - x0) / h - 1e-9)); }
  int n_y() const { return 1 + static_cast<int>(std::ceil((y1 - y0) / h - 1e-9)); }
  std::vector<Vec2> nodes() const
  {
    std::vector<Vec2> p;
    for (int i = 0; i < n_x(); ++i)
      for (int j = 0; j < n_y(); ++j)
        p.push_back({{x0 + (x1 - x0) * i / (n_x() - 1), y0 + (y1 - y0) * j / (n_y() - 1)}});
    return p;
  }
  CartesianGrid empty_grid() const
  {
    CartesianGrid g;
    g.x_min = x0;
    g.x_max = x1;
    g.y_min = y0;
    g.y_max = y1;
    g.n_x = n_x();
    g.n_y = n_y();
    return g;
  }
  // Φ on the window's nodes for the sleeve at `V` and the image (values scaled by `scale`,
  // 0 = image off) carried by u along the drum surface; air_potential or the conductor fill.
  std::vector<double> solve(double V, double scale, double u, bool smooth_extension = true) const
  {
    LatentImage img = image;
    img.dark_value *= scale;
    img.light_value *= scale;
    NipElectrostatics nip(MPI_COMM_WORLD, layout(), 3.0, V, img, disc, u);
    nip.run();
    return smooth_extension ? nip.air_potential(nodes()) : nip.potential(nodes());
  }
  // What the field stage stores with K phase samples.
  NipPotentialGrid stored(int K) const
  {
    NipPotentialGrid g;
    g.bias = empty_grid();
    g.bias.phi = solve(bias, 0.0, 0.0);
    g.image_period = image.period;
    g.drum_center = {{Rs + gap + Rd, 0.0}};
    g.drum_radius = Rd;
    for (int k = 0; k < K; ++k)
      g.image.push_back(solve(0.0, 1.0, k * image.period / K));
    return g;
  }
  // The contrast field: the image's potential contrast across the gap [V/m].
  double contrast_field() const { return std::abs(image.dark_value - image.light_value) / gap; }
  // The drum surface along the window: x of the drum surface at lateral offset y.
  double drum_surface_x(double y) const
  {
    const double xc = Rs + gap + Rd;
    return xc - std::sqrt(Rd * Rd - y * y);
  }
  double sleeve_surface_x(double y) const { return std::sqrt(Rs * Rs - y * y); }
};

} // namespace magbrush::field::testing
