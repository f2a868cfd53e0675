// Quadrilateral meshes built with deal.II alone (no Gmsh), with exact curved geometry:
//
//  * make_layered_disk: concentric annuli around an O-grid core — the roller cross-section
//    (shaft, magnet, gap, sleeve, air, open-boundary shell). Every circle is a mesh line on a
//    SphericalManifold, so refinement stays on the circles.
//  * make_layered_slab: a periodic strip of horizontal layers (photoconductor, air gap) for the
//    planar nip checks.
//  * make_bipolar_two_cylinders: the exterior of two cylinders meshed in bipolar coordinates
//    (τ, σ), cut along a thin wedge σ < σ_cut that reaches infinity. Cylinders are the
//    coordinate lines τ = const, so the mesh is exact, graded toward the gap by itself, and the
//    two-cylinder potential is linear in τ.
//
// Boundary ids and material ids are documented on each builder.
#pragma once

#include <deal.II/grid/tria.h>

#include <array>
#include <vector>

namespace magbrush::field {

struct AnnularLayer
{
  double outer_radius = 0.0;             // [m]; layers are given from the centre outward
  dealii::types::material_id material = 0;
  unsigned int radial_cells = 0;         // 0: chosen so that cells are roughly square
};

// The first layer is the disk 0 ≤ r < layers[0].outer_radius (an O-grid), each further one the
// annulus from the previous radius. n_angular (a multiple of 4, ≥ 8) cells around. The outer
// circle gets boundary id 0. Manifold ids: 0 = circles (SphericalManifold at the origin);
// the core is flat inside (its curved rim is blended in by the mapping).
void make_layered_disk(dealii::Triangulation<2> &triangulation,
                       const std::vector<AnnularLayer> &layers, unsigned int n_angular);

// Horizontal layers y_0 = 0 < y_1 < ... stacked over 0 ≤ x ≤ width; layer k has material id
// materials[k] and cells[k] cells across its thickness; n_x cells along x.
// Boundary ids: 0 = left (x = 0), 1 = right (x = width), 2 = bottom, 3 = top.
void make_layered_slab(dealii::Triangulation<2> &triangulation, double width, unsigned int n_x,
                       const std::vector<double> &layer_thicknesses,
                       const std::vector<dealii::types::material_id> &materials,
                       const std::vector<unsigned int> &cells);

// Geometry of two cylinders in bipolar coordinates w = τ + iσ = ln((z + a)/(z − a)):
// the right cylinder (radius R_right, τ = tau_right > 0) is centred at x = c_right > 0, the
// left one (τ = tau_left < 0) at x = −c_left. Their surface gap is on the x axis near 0.
struct BipolarGeometry
{
  double focus = 0.0;                   // a
  double tau_left = 0.0, tau_right = 0.0;
  double center_left = 0.0, center_right = 0.0; // distances of the centres from the origin
  double sigma_cut = 0.0;

  static BipolarGeometry from_cylinders(double radius_left, double radius_right, double gap,
                                        double sigma_cut);
  std::array<double, 2> to_cartesian(double tau, double sigma) const;
  std::array<double, 2> to_bipolar(double x, double y) const; // σ in [0, 2π)
};

// Material id 0 everywhere. Boundary ids: 0 = left cylinder, 1 = right cylinder,
// 2 = σ = σ_cut, 3 = σ = 2π − σ_cut (the two sides of the cut; Dirichlet with the exact value).
// Manifold id 0 = the bipolar chart on every cell and face.
void make_bipolar_two_cylinders(dealii::Triangulation<2> &triangulation,
                                const BipolarGeometry &geometry, unsigned int n_tau,
                                unsigned int n_sigma);

// ---------------------------------------------------------------------------------------
// The production nip: sleeve (centre at the roller origin) and drum (photoconductor surface
// radius, centre in the direction drum_angle at the development gap), meshed in the bipolar
// coordinates of these two circles (air), with the photoconductor layer as rings under the
// drum surface (same angular divisions, SphericalManifold about the drum centre). The wedge
// σ < σ_cut that reaches infinity behind the drum is left out; its sides and the layer's ends
// there are homogeneous Neumann (zero flux) boundaries, far from the nip.
namespace nip_region {
constexpr dealii::types::material_id photoconductor = 1, air = 2;
}
namespace nip_boundary {
constexpr dealii::types::boundary_id drum = 0, sleeve = 1, far = 2;
}

struct NipLayout
{
  double sleeve_radius = 0.0, drum_radius = 0.0, layer_thickness = 0.0, drum_angle = 0.0;
  std::array<double, 2> drum_center{{0.0, 0.0}};
  BipolarGeometry bipolar; // of the sleeve and the photoconductor surface

  static NipLayout from(double sleeve_radius, double drum_radius, double gap,
                        double drum_angle, double layer_thickness, double sigma_cut = 0.05);
};

// Material ids nip_region, boundary ids nip_boundary (drum = the grounded substrate, or the
// photoconductor surface itself when the layer is left out: layer_thickness = 0 or
// n_layer = 0). Manifold 0 = the bipolar chart (air), 1 = circles about the drum centre.
void make_nip_mesh(dealii::Triangulation<2> &triangulation, const NipLayout &nip,
                   unsigned int n_tau, unsigned int n_sigma, unsigned int n_layer);

} // namespace magbrush::field
