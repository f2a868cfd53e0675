#include "field_solver/layered_meshes.h"

#include <deal.II/base/point.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold.h>
#include <deal.II/grid/manifold_lib.h>
#include <deal.II/grid/tria_description.h>

#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

namespace magbrush::field {

using namespace dealii;

namespace {

constexpr double pi = 3.14159265358979323846;

// Cells per layer so that the cells are about as long radially as they are wide.
unsigned int radial_cells_for(const AnnularLayer &layer, double inner_radius,
                              unsigned int n_angular)
{
  if (layer.radial_cells > 0)
    return layer.radial_cells;
  const double width = 0.5 * (inner_radius + layer.outer_radius) * 2.0 * pi / n_angular;
  const double n = std::round((layer.outer_radius - inner_radius) / width);
  return static_cast<unsigned int>(std::max(1.0, n));
}

// The chart of the bipolar coordinates; mapping every refinement through it keeps the
// cylinders and the coordinate lines exact.
class BipolarChart : public ChartManifold<2, 2, 2>
{
public:
  explicit BipolarChart(const BipolarGeometry &g) : geometry(g) {}

  std::unique_ptr<Manifold<2, 2>> clone() const override
  {
    return std::make_unique<BipolarChart>(geometry);
  }

  Point<2> pull_back(const Point<2> &x) const override
  {
    const auto w = geometry.to_bipolar(x[0], x[1]);
    return Point<2>(w[0], w[1]);
  }

  Point<2> push_forward(const Point<2> &w) const override
  {
    const auto x = geometry.to_cartesian(w[0], w[1]);
    return Point<2>(x[0], x[1]);
  }

  // z = a coth(w/2) is holomorphic: dz/dw = −a / (2 sinh²(w/2)) = p + iq gives the
  // Jacobian [[p, −q], [q, p]].
  DerivativeForm<1, 2, 2> push_forward_gradient(const Point<2> &w) const override
  {
    const std::complex<double> half(0.5 * w[0], 0.5 * w[1]);
    const std::complex<double> s = std::sinh(half);
    const std::complex<double> d = -geometry.focus / (2.0 * s * s);
    DerivativeForm<1, 2, 2> J;
    J[0][0] = d.real();
    J[0][1] = -d.imag();
    J[1][0] = d.imag();
    J[1][1] = d.real();
    return J;
  }

private:
  BipolarGeometry geometry;
};

} // namespace

// The O-grid: a square of (n/4)² cells in the middle, rings of 4·(n/4) cells that blend the
// square's boundary into the first circle, then polar rings out to the last circle. Ring
// vertex k sits at angle −π/4 + 2πk/n so that the square's corners meet the diagonals.
void make_layered_disk(Triangulation<2> &triangulation, const std::vector<AnnularLayer> &layers,
                       unsigned int n_angular)
{
  if (layers.empty())
    throw std::invalid_argument("layered disk: at least one layer is needed");
  if (n_angular < 8 || n_angular % 4 != 0)
    throw std::invalid_argument("layered disk: the number of cells around must be a multiple "
                                "of 4 and at least 8, found " + std::to_string(n_angular));
  for (std::size_t k = 0; k < layers.size(); ++k)
  {
    const double inner = k == 0 ? 0.0 : layers[k - 1].outer_radius;
    if (!(layers[k].outer_radius > inner))
      throw std::invalid_argument(
        "layered disk: layer " + std::to_string(k) + " has zero or negative thickness (from " +
        std::to_string(inner) + " m to " + std::to_string(layers[k].outer_radius) +
        " m); radii must increase outward");
  }

  const unsigned int m = n_angular / 4;
  const double R0 = layers[0].outer_radius;
  const double h = 0.45 * R0; // half-width of the core square
  std::vector<Point<2>> vertices;
  std::vector<CellData<2>> cells;

  auto angle = [&](unsigned int k) { return -0.25 * pi + 2.0 * pi * k / n_angular; };

  // Core square.
  for (unsigned int j = 0; j <= m; ++j)
    for (unsigned int i = 0; i <= m; ++i)
      vertices.emplace_back(-h + 2.0 * h * i / m, -h + 2.0 * h * j / m);
  auto square_index = [&](unsigned int i, unsigned int j) { return i + (m + 1) * j; };
  for (unsigned int j = 0; j < m; ++j)
    for (unsigned int i = 0; i < m; ++i)
    {
      CellData<2> c;
      c.vertices = {square_index(i, j), square_index(i + 1, j), square_index(i, j + 1),
                    square_index(i + 1, j + 1)};
      c.material_id = layers[0].material;
      c.manifold_id = 1;
      cells.push_back(c);
    }

  // The square's boundary, counter-clockwise from the corner (h, −h).
  std::vector<unsigned int> ring(n_angular);
  for (unsigned int k = 0; k < n_angular; ++k)
  {
    const unsigned int side = k / m, t = k % m;
    ring[k] = side == 0 ? square_index(m, t)
            : side == 1 ? square_index(m - t, m)
            : side == 2 ? square_index(0, m - t)
                        : square_index(t, 0);
  }

  auto add_ring_cells = [&](const std::vector<unsigned int> &inner,
                            const std::vector<unsigned int> &outer, types::material_id material,
                            types::manifold_id manifold) {
    for (unsigned int k = 0; k < n_angular; ++k)
    {
      const unsigned int k1 = (k + 1) % n_angular;
      CellData<2> c; // x: outward, y: counter-clockwise (positive orientation)
      c.vertices = {inner[k], outer[k], inner[k1], outer[k1]};
      c.material_id = material;
      c.manifold_id = manifold;
      cells.push_back(c);
    }
  };

  // Blend from the square to the first circle.
  const unsigned int n_blend = radial_cells_for({R0, 0, layers[0].radial_cells}, 0.55 * R0,
                                                n_angular);
  std::vector<Point<2>> square_boundary(n_angular);
  for (unsigned int k = 0; k < n_angular; ++k)
    square_boundary[k] = vertices[ring[k]];
  for (unsigned int l = 1; l <= n_blend; ++l)
  {
    const double s = static_cast<double>(l) / n_blend;
    std::vector<unsigned int> next(n_angular);
    for (unsigned int k = 0; k < n_angular; ++k)
    {
      const Point<2> on_circle(R0 * std::cos(angle(k)), R0 * std::sin(angle(k)));
      next[k] = vertices.size();
      vertices.push_back((1.0 - s) * square_boundary[k] + s * on_circle);
    }
    add_ring_cells(ring, next, layers[0].material, 1);
    ring = next;
  }

  // Polar layers.
  for (std::size_t layer = 1; layer < layers.size(); ++layer)
  {
    const double r_in = layers[layer - 1].outer_radius, r_out = layers[layer].outer_radius;
    const unsigned int n_r = radial_cells_for(layers[layer], r_in, n_angular);
    for (unsigned int l = 1; l <= n_r; ++l)
    {
      const double r = r_in + (r_out - r_in) * l / n_r;
      std::vector<unsigned int> next(n_angular);
      for (unsigned int k = 0; k < n_angular; ++k)
      {
        next[k] = vertices.size();
        vertices.emplace_back(r * std::cos(angle(k)), r * std::sin(angle(k)));
      }
      add_ring_cells(ring, next, layers[layer].material, 0);
      ring = next;
    }
  }

  // deal.II needs the lines of neighbouring quads oriented consistently (the O-grid's square
  // and its first ring are not, as written).
  GridTools::consistently_order_cells(cells);
  triangulation.create_triangulation(vertices, cells, SubCellData());

  // The polar cells (and with them the circles they share with the core) get the exact
  // circle; the core stays flat inside: its cells' interior points are then blended from
  // their (curved) boundary by the mapping itself, which is as good as a transfinite manifold
  // and far cheaper to evaluate. The last blend ring's outer faces are on R0.
  for (const auto &cell : triangulation.active_cell_iterators())
    if (cell->manifold_id() == 1)
      cell->set_all_manifold_ids(numbers::flat_manifold_id);
  for (const auto &cell : triangulation.active_cell_iterators())
    if (cell->manifold_id() == 0)
      cell->set_all_manifold_ids(0);
  for (const auto &cell : triangulation.active_cell_iterators())
    for (const unsigned int f : cell->face_indices())
    {
      const auto face = cell->face(f);
      if (std::abs(face->vertex(0).norm() - R0) < 1e-10 * R0 &&
          std::abs(face->vertex(1).norm() - R0) < 1e-10 * R0)
        face->set_manifold_id(0);
    }

  triangulation.set_manifold(0, SphericalManifold<2>(Point<2>()));
}

void make_layered_slab(Triangulation<2> &triangulation, double width, unsigned int n_x,
                       const std::vector<double> &layer_thicknesses,
                       const std::vector<types::material_id> &materials,
                       const std::vector<unsigned int> &cells)
{
  if (layer_thicknesses.empty() || materials.size() != layer_thicknesses.size() ||
      cells.size() != layer_thicknesses.size())
    throw std::invalid_argument("layered slab: thicknesses, materials and cell counts must be "
                                "given for every layer");
  std::vector<std::vector<double>> steps(2);
  steps[0].assign(n_x, width / n_x);
  std::vector<double> tops;
  double y = 0.0;
  for (std::size_t k = 0; k < layer_thicknesses.size(); ++k)
  {
    if (!(layer_thicknesses[k] > 0.0) || cells[k] == 0)
      throw std::invalid_argument("layered slab: layer " + std::to_string(k) +
                                  " has zero thickness or no cells");
    for (unsigned int c = 0; c < cells[k]; ++c)
      steps[1].push_back(layer_thicknesses[k] / cells[k]);
    y += layer_thicknesses[k];
    tops.push_back(y);
  }
  GridGenerator::subdivided_hyper_rectangle(triangulation, steps, Point<2>(0.0, 0.0),
                                            Point<2>(width, y), true);
  for (const auto &cell : triangulation.active_cell_iterators())
  {
    std::size_t k = 0;
    while (k + 1 < tops.size() && cell->center()[1] > tops[k])
      ++k;
    cell->set_material_id(materials[k]);
  }
}

BipolarGeometry BipolarGeometry::from_cylinders(double radius_left, double radius_right,
                                                double gap, double sigma_cut)
{
  if (!(radius_left > 0.0 && radius_right > 0.0 && gap > 0.0))
    throw std::invalid_argument("two cylinders: radii and gap must be positive");
  const double d = radius_left + radius_right + gap;
  const double q = d * d - radius_left * radius_left - radius_right * radius_right;
  BipolarGeometry g;
  g.focus = std::sqrt((q * q - 4.0 * radius_left * radius_left * radius_right * radius_right) /
                      (4.0 * d * d));
  g.tau_right = std::asinh(g.focus / radius_right);
  g.tau_left = -std::asinh(g.focus / radius_left);
  g.center_right = std::sqrt(g.focus * g.focus + radius_right * radius_right);
  g.center_left = std::sqrt(g.focus * g.focus + radius_left * radius_left);
  g.sigma_cut = sigma_cut;
  return g;
}

std::array<double, 2> BipolarGeometry::to_cartesian(double tau, double sigma) const
{
  const std::complex<double> half(0.5 * tau, 0.5 * sigma);
  const std::complex<double> z = focus * std::cosh(half) / std::sinh(half);
  return {{z.real(), z.imag()}};
}

std::array<double, 2> BipolarGeometry::to_bipolar(double x, double y) const
{
  const std::complex<double> z(x, y);
  const std::complex<double> w = std::log((z + focus) / (z - focus));
  double sigma = w.imag();
  if (sigma < 0.0)
    sigma += 2.0 * pi;
  return {{w.real(), sigma}};
}

void make_bipolar_two_cylinders(Triangulation<2> &triangulation,
                                const BipolarGeometry &geometry, unsigned int n_tau,
                                unsigned int n_sigma)
{
  GridGenerator::subdivided_hyper_rectangle(
    triangulation, {n_tau, n_sigma}, Point<2>(geometry.tau_left, geometry.sigma_cut),
    Point<2>(geometry.tau_right, 2.0 * pi - geometry.sigma_cut), true);
  for (const auto &cell : triangulation.active_cell_iterators())
    cell->set_material_id(0); // colorize numbers the cells too: one region here
  GridTools::transform(
    [&](const Point<2> &w) {
      const auto x = geometry.to_cartesian(w[0], w[1]);
      return Point<2>(x[0], x[1]);
    },
    triangulation);
  triangulation.set_all_manifold_ids(0);
  triangulation.set_manifold(0, BipolarChart(geometry));
}

// ---------------------------------------------------------------------------------------
// The production nip.

namespace {

// The bipolar chart seen from the roller frame: x_roller = Q (x_b − c_r e_x), Q the rotation
// by (drum angle − π), which puts the sleeve centre at the origin and the drum centre in the
// direction of the drum angle.
class PlacedBipolarChart : public ChartManifold<2, 2, 2>
{
public:
  PlacedBipolarChart(const BipolarGeometry &g, double drum_angle)
    : geometry(g), rotation(drum_angle - pi)
  {}

  std::unique_ptr<Manifold<2, 2>> clone() const override
  {
    return std::make_unique<PlacedBipolarChart>(geometry, rotation + pi);
  }

  Point<2> to_roller(const std::array<double, 2> &xb) const
  {
    const double x = xb[0] - geometry.center_right, y = xb[1];
    const double c = std::cos(rotation), s = std::sin(rotation);
    return Point<2>(c * x - s * y, s * x + c * y);
  }

  std::array<double, 2> to_bipolar_frame(const Point<2> &p) const
  {
    const double c = std::cos(rotation), s = std::sin(rotation);
    return {{c * p[0] + s * p[1] + geometry.center_right, -s * p[0] + c * p[1]}};
  }

  Point<2> pull_back(const Point<2> &x) const override
  {
    const auto xb = to_bipolar_frame(x);
    const auto w = geometry.to_bipolar(xb[0], xb[1]);
    return Point<2>(w[0], w[1]);
  }

  Point<2> push_forward(const Point<2> &w) const override
  {
    return to_roller(geometry.to_cartesian(w[0], w[1]));
  }

  DerivativeForm<1, 2, 2> push_forward_gradient(const Point<2> &w) const override
  {
    const std::complex<double> half(0.5 * w[0], 0.5 * w[1]);
    const std::complex<double> s = std::sinh(half);
    const std::complex<double> d =
      -geometry.focus / (2.0 * s * s) * std::polar(1.0, rotation);
    DerivativeForm<1, 2, 2> J;
    J[0][0] = d.real();
    J[0][1] = -d.imag();
    J[1][0] = d.imag();
    J[1][1] = d.real();
    return J;
  }

private:
  BipolarGeometry geometry;
  double rotation;
};

} // namespace

NipLayout NipLayout::from(double sleeve_radius, double drum_radius, double gap,
                          double drum_angle, double layer_thickness, double sigma_cut)
{
  if (!(layer_thickness >= 0.0 && layer_thickness < drum_radius))
    throw std::invalid_argument("nip mesh: the photoconductor thickness must lie in "
                                "[0, drum radius), found " + std::to_string(layer_thickness));
  NipLayout n;
  n.sleeve_radius = sleeve_radius;
  n.drum_radius = drum_radius;
  n.layer_thickness = layer_thickness;
  n.drum_angle = drum_angle;
  n.bipolar = BipolarGeometry::from_cylinders(drum_radius, sleeve_radius, gap, sigma_cut);
  const double D = sleeve_radius + gap + drum_radius;
  n.drum_center = {{D * std::cos(drum_angle), D * std::sin(drum_angle)}};
  return n;
}

void make_nip_mesh(Triangulation<2> &triangulation, const NipLayout &nip, unsigned int n_tau,
                   unsigned int n_sigma, unsigned int n_layer)
{
  const BipolarGeometry &g = nip.bipolar;
  const PlacedBipolarChart chart(g, nip.drum_angle);
  const bool with_layer = nip.layer_thickness > 0.0 && n_layer > 0;
  const Point<2> drum_center(nip.drum_center[0], nip.drum_center[1]);

  // Air: the (τ, σ) rectangle from the drum surface (τ_left) to the sleeve (τ_right).
  std::vector<Point<2>> vertices;
  auto air_index = [&](unsigned int i, unsigned int j) { return i + (n_tau + 1) * j; };
  for (unsigned int j = 0; j <= n_sigma; ++j)
    for (unsigned int i = 0; i <= n_tau; ++i)
    {
      const double tau = g.tau_left + (g.tau_right - g.tau_left) * i / n_tau;
      const double sigma = g.sigma_cut + (2.0 * pi - 2.0 * g.sigma_cut) * j / n_sigma;
      vertices.push_back(chart.push_forward(Point<2>(tau, sigma)));
    }
  std::vector<CellData<2>> cells;
  for (unsigned int j = 0; j < n_sigma; ++j)
    for (unsigned int i = 0; i < n_tau; ++i)
    {
      CellData<2> c;
      c.vertices = {air_index(i, j), air_index(i + 1, j), air_index(i, j + 1),
                    air_index(i + 1, j + 1)};
      c.material_id = nip_region::air;
      c.manifold_id = 0;
      cells.push_back(c);
    }

  // Photoconductor: rings under the drum-surface vertices, at the same angles.
  if (with_layer)
  {
    std::vector<unsigned int> outer(n_sigma + 1);
    for (unsigned int j = 0; j <= n_sigma; ++j)
      outer[j] = air_index(0, j);
    for (unsigned int k = 1; k <= n_layer; ++k)
    {
      const double r = nip.drum_radius - nip.layer_thickness * k / n_layer;
      std::vector<unsigned int> inner(n_sigma + 1);
      for (unsigned int j = 0; j <= n_sigma; ++j)
      {
        const Tensor<1, 2> d = vertices[outer[j]] - drum_center;
        inner[j] = vertices.size();
        vertices.push_back(drum_center + (r / d.norm()) * d);
      }
      for (unsigned int j = 0; j < n_sigma; ++j)
      {
        CellData<2> c; // x: away from the drum centre, y: increasing σ (as the air cells)
        c.vertices = {inner[j], outer[j], inner[j + 1], outer[j + 1]};
        c.material_id = nip_region::photoconductor;
        c.manifold_id = 1;
        cells.push_back(c);
      }
      outer = inner;
    }
  }
  GridTools::consistently_order_cells(cells);
  triangulation.create_triangulation(vertices, cells, SubCellData());

  for (const auto &cell : triangulation.active_cell_iterators())
    if (cell->manifold_id() == 0)
      cell->set_all_manifold_ids(0);
  for (const auto &cell : triangulation.active_cell_iterators())
    if (cell->manifold_id() == 1)
      cell->set_all_manifold_ids(1);

  // Boundary ids by geometry: both vertices on the sleeve, on the substrate, else the cut.
  const auto on_circle = [](const Point<2> &p, const Point<2> &c, double R) {
    return std::abs((p - c).norm() - R) < 1e-9 * R;
  };
  const Point<2> origin;
  const double substrate = nip.drum_radius - (with_layer ? nip.layer_thickness : 0.0);
  for (const auto &cell : triangulation.active_cell_iterators())
    for (const unsigned int f : cell->face_indices())
      if (cell->face(f)->at_boundary())
      {
        const auto face = cell->face(f);
        if (on_circle(face->vertex(0), origin, nip.sleeve_radius) &&
            on_circle(face->vertex(1), origin, nip.sleeve_radius))
          face->set_boundary_id(nip_boundary::sleeve);
        else if (on_circle(face->vertex(0), drum_center, substrate) &&
                 on_circle(face->vertex(1), drum_center, substrate))
          face->set_boundary_id(nip_boundary::drum);
        else
          face->set_boundary_id(nip_boundary::far);
      }

  triangulation.set_manifold(0, chart);
  triangulation.set_manifold(1, SphericalManifold<2>(drum_center));
}

} // namespace magbrush::field
