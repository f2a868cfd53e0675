#include "field_solver/nip_electrostatics.h"

#include <cmath>
#include <stdexcept>

namespace magbrush::field {

namespace {
constexpr double eps0 = 8.8541878128e-12;
constexpr double pi = 3.14159265358979323846;

double wrap(double a)
{
  a = std::fmod(a + pi, 2.0 * pi);
  if (a <= 0.0)
    a += 2.0 * pi;
  return a - pi;
}
} // namespace

double latent_image_value(const LatentImage &image, double s)
{
  if (image.solid())
    return image.light_value; // a solid area, whatever the period
  if (!image.striped())
    return image.dark_value;
  // s' ∈ [−P/2, P/2): the place within the period; e: the distance inside the exposed strip
  // from its nearer edge (negative outside it).
  const double P = image.period;
  const double v = s / P + 0.5;
  const double s_local = (v - std::floor(v) - 0.5) * P;
  const double e = 0.5 * image.duty * P - std::abs(s_local);
  const double w = image.edge_width;
  if (w <= 0.0)
    return e > 0.0 ? image.light_value : image.dark_value;
  const double S = e >= 0.5 * w ? 1.0 : e <= -0.5 * w ? 0.0 : 0.5 * (1.0 + std::sin(pi * e / w));
  return image.dark_value + (image.light_value - image.dark_value) * S;
}

NipElectrostatics::NipElectrostatics(MPI_Comm communicator_in, const NipLayout &layout,
                                     double layer_eps_r_in, double bias_in,
                                     const LatentImage &image_in,
                                     const NipDiscretisation &disc, double image_shift_in)
  : communicator(communicator_in)
  , nip(layout)
  , layer_eps_r(layer_eps_r_in)
  , bias(bias_in)
  , image(image_in)
  , image_shift(image_shift_in)
  , discretisation(disc)
  , triangulation(communicator, dealii::Triangulation<2>::none, false,
                  dealii::parallel::shared::Triangulation<2>::partition_metis)
{
  if (!(layer_eps_r >= 1.0) || !std::isfinite(layer_eps_r))
    throw std::invalid_argument("nip field: drum.pc_eps_r must be ≥ 1, found " +
                                std::to_string(layer_eps_r));
  if (image.kind == LatentImage::Kind::surface_charge && !(nip.layer_thickness > 0.0))
    throw std::invalid_argument("nip field: a latent image given as surface charge needs a "
                                "photoconductor layer (drum.pc_thickness > 0)");
}

NipElectrostatics::~NipElectrostatics() = default;

double NipElectrostatics::arc_length_from_nip(const Point<2> &x) const
{
  const double phi = std::atan2(x[1] - nip.drum_center[1], x[0] - nip.drum_center[0]);
  return nip.drum_radius * wrap(phi - (nip.drum_angle + pi));
}

double NipElectrostatics::image_at(const Point<2> &x) const
{
  return latent_image_value(image, arc_length_from_nip(x) - image_shift);
}

PotentialProblemDescription NipElectrostatics::describe() const
{
  PotentialProblemDescription d;
  d.name = "nip field";
  d.degree = discretisation.degree;
  d.solver_tolerance = discretisation.solver_tolerance;
  d.linear_solver = discretisation.linear_solver;
  d.linear_algebra = discretisation.linear_algebra;
  d.estimate_error = false; // the Kelly indicator only for the VTU (write_vtu)
  d.coefficient[nip_region::air] = eps0;
  d.coefficient[nip_region::photoconductor] = eps0 * layer_eps_r;
  const double V = bias;
  d.dirichlet[nip_boundary::sleeve] = [V](const Point<2> &) { return V; };
  if (image.kind == LatentImage::Kind::surface_potential)
    d.dirichlet[nip_boundary::drum] = [this](const Point<2> &x) { return image_at(x); };
  else
    d.dirichlet[nip_boundary::drum] = [](const Point<2> &) { return 0.0; };
  if (image.kind == LatentImage::Kind::surface_charge)
    d.surface_charges.push_back({nip_region::photoconductor, nip_region::air,
                                 [this](const Point<2> &x) { return image_at(x); }});
  return d;
}

void NipElectrostatics::run()
{
  const bool mesh_layer = image.kind != LatentImage::Kind::surface_potential;
  NipLayout layout = nip;
  if (!mesh_layer)
    layout.layer_thickness = 0.0;
  triangulation.clear();
  make_nip_mesh(triangulation, layout, discretisation.n_tau, discretisation.n_sigma,
                mesh_layer ? discretisation.n_layer : 0);
  triangulation.refine_global(discretisation.refinements);
  solver = std::make_unique<PotentialProblem>(triangulation, describe());
  solver->run();
}

std::vector<double> NipElectrostatics::potential(const std::vector<Vec2> &points) const
{
  const bool mesh_layer =
    image.kind != LatentImage::Kind::surface_potential && nip.layer_thickness > 0.0;
  const double substrate = nip.drum_radius - (mesh_layer ? nip.layer_thickness : 0.0);
  std::vector<double> values(points.size(), 0.0);
  std::vector<Point<2>> inside;
  std::vector<std::size_t> index;
  for (std::size_t k = 0; k < points.size(); ++k)
  {
    const double rs = std::hypot(points[k][0], points[k][1]);
    const double rd =
      std::hypot(points[k][0] - nip.drum_center[0], points[k][1] - nip.drum_center[1]);
    if (rs < nip.sleeve_radius)
      values[k] = bias;
    else if (rd < substrate)
      values[k] = image.kind == LatentImage::Kind::surface_potential
                    ? image_at(Point<2>(points[k][0], points[k][1]))
                    : 0.0;
    else
    {
      inside.emplace_back(points[k][0], points[k][1]);
      index.push_back(k);
    }
  }
  std::vector<bool> found;
  const auto v = solver->values_at(inside, &found);
  for (std::size_t i = 0; i < index.size(); ++i)
  {
    if (found[i])
    {
      values[index[i]] = v[i];
      continue;
    }
    // Not in any cell: a point a hair outside the polynomial approximation of a curved
    // conductor surface takes the conductor's value; anything else is an error.
    const Vec2 &x = points[index[i]];
    const double ds = std::hypot(x[0], x[1]) - nip.sleeve_radius;
    const double dd =
      std::hypot(x[0] - nip.drum_center[0], x[1] - nip.drum_center[1]) - substrate;
    const double band = 1e-3 * (nip.bipolar.center_left + nip.bipolar.center_right -
                                nip.sleeve_radius - nip.drum_radius);
    if (ds < band && ds <= dd)
      values[index[i]] = bias;
    else if (dd < band)
      values[index[i]] = image.kind == LatentImage::Kind::surface_potential
                           ? image_at(Point<2>(x[0], x[1]))
                           : 0.0;
    else
      throw std::runtime_error("nip field: the point (" + std::to_string(x[0]) + ", " +
                               std::to_string(x[1]) + ") m lies outside the solved region; "
                               "the electric grid window must stay near the nip");
  }
  return values;
}

std::vector<double> NipElectrostatics::air_potential(const std::vector<Vec2> &points) const
{
  // Every point below a surface is mapped to its nearest surface point (radially: both
  // surfaces are circles), moved a hair into the air so that it lies in an air cell of the
  // curved mapping; Φ and ∇Φ there give the Taylor extension.
  const double gap = nip.bipolar.center_left + nip.bipolar.center_right - nip.sleeve_radius -
                     nip.drum_radius;
  const double hair = 1e-6 * gap;
  std::vector<double> values(points.size(), 0.0);
  std::vector<Vec2> air;
  std::vector<Point<2>> anchor;
  std::vector<std::size_t> air_index, anchor_index;
  for (std::size_t k = 0; k < points.size(); ++k)
  {
    const Vec2 &x = points[k];
    const double rs = std::hypot(x[0], x[1]);
    const double dx = x[0] - nip.drum_center[0], dy = x[1] - nip.drum_center[1];
    const double rd = std::hypot(dx, dy);
    if (rs < nip.sleeve_radius)
    {
      const double ux = rs > 0.0 ? x[0] / rs : 1.0, uy = rs > 0.0 ? x[1] / rs : 0.0;
      anchor.emplace_back((nip.sleeve_radius + hair) * ux, (nip.sleeve_radius + hair) * uy);
      anchor_index.push_back(k);
    }
    else if (rd < nip.drum_radius)
    {
      const double ux = rd > 0.0 ? dx / rd : 1.0, uy = rd > 0.0 ? dy / rd : 0.0;
      anchor.emplace_back(nip.drum_center[0] + (nip.drum_radius + hair) * ux,
                          nip.drum_center[1] + (nip.drum_radius + hair) * uy);
      anchor_index.push_back(k);
    }
    else
    {
      air.push_back(x);
      air_index.push_back(k);
    }
  }
  const std::vector<double> v_air = potential(air);
  for (std::size_t i = 0; i < air_index.size(); ++i)
    values[air_index[i]] = v_air[i];
  // The curved mapping approximates the circles by polynomials: an anchor a hair outside the
  // exact circle can still lie outside the mesh. Such anchors move further into the air (at
  // most 1 % of the gap), the others stay.
  std::vector<double> v_anchor;
  for (double lift = hair;; lift *= 10.0)
  {
    std::vector<bool> found;
    v_anchor = solver->values_at(anchor, &found);
    bool all = true;
    for (std::size_t i = 0; i < anchor.size(); ++i)
      if (!found[i])
      {
        all = false;
        const Vec2 &x = points[anchor_index[i]];
        const bool sleeve = std::hypot(x[0], x[1]) < nip.sleeve_radius;
        const double cx = sleeve ? 0.0 : nip.drum_center[0], cy = sleeve ? 0.0 : nip.drum_center[1];
        const double r = std::hypot(anchor[i][0] - cx, anchor[i][1] - cy);
        const double scale = (r + 9.0 * lift) / r;
        anchor[i] = Point<2>(cx + (anchor[i][0] - cx) * scale, cy + (anchor[i][1] - cy) * scale);
      }
    if (all)
      break;
    if (lift > 1e-2 * gap)
      throw std::runtime_error("nip field: the surface points of the smooth extension lie "
                               "outside the mesh even 1 % of the gap into the air");
  }
  const auto g_anchor = solver->gradients_at(anchor);
  for (std::size_t i = 0; i < anchor_index.size(); ++i)
  {
    const Vec2 &x = points[anchor_index[i]];
    values[anchor_index[i]] = v_anchor[i] + g_anchor[i][0] * (x[0] - anchor[i][0]) +
                              g_anchor[i][1] * (x[1] - anchor[i][1]);
  }
  return values;
}

std::vector<Vec2> NipElectrostatics::electric_field(const std::vector<Vec2> &points) const
{
  std::vector<Point<2>> p;
  for (const auto &x : points)
    p.emplace_back(x[0], x[1]);
  const auto g = solver->gradients_at(p);
  std::vector<Vec2> E;
  for (const auto &gr : g)
    E.push_back({{-gr[0], -gr[1]}});
  return E;
}

void NipElectrostatics::write_vtu(const std::string &directory,
                                  const std::string &basename) const
{
  solver->estimate();
  solver->write_vtu(directory, basename, "electric");
}

} // namespace magbrush::field
