// The field-grid contract between the field solver and the DEM: fields sampled on regular
// grids, stored in HDF5 with the provenance that lets a reader decide whether a stored field
// still belongs to its case.
//
//  * Magnetic: the vector potential A_z [T·m] of the roller on a polar grid (an annulus
//    r_min ≤ r ≤ r_max around the roller axis, θ periodic on [0, 2π)). B = curl(A_z ẑ) is
//    taken from a C2 spline of A_z (polar_field_interpolator.h), so B is exactly
//    divergence-free and its gradient is continuous.
//  * Electric: the potential Φ [V] of the nip on a Cartesian window, as the bias solution
//    plus the latent image's solution at K phases of its travel with the drum surface
//    (NipPotentialGrid); E = −∇Φ (nip_potential_field.h).
//
// The file layout is documented in docs/field_grid_format.md. Files are written atomically
// (a temporary file, then a rename), and the reader checks everything it relies on (format name and
// version, kind, shapes, units, finite values, uniform axes) with errors that name the file,
// the dataset and what was expected.
//
// No deal.II and no HDF5 types in this header: the field solver fills a PolarGrid by sampling
// its finite-element solution at the nodes (sample_polar_grid), the DEM reads it back.
#pragma once

#include "case/case_hash.h"
#include "case/case_model.h"

#include <array>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace magbrush {

// Everything that goes wrong with a grid file or a grid: the message is complete (file,
// dataset, what was expected, what was found, what to do).
struct FieldGridError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

// The stored field was computed for other inputs than the case at hand.
struct ProvenanceMismatch : FieldGridError
{
  ProvenanceMismatch(const std::string &message, std::string key)
    : FieldGridError(message), differing_key(std::move(key)) {}
  std::string differing_key; // the first canonical input key that differs
};

// ---------------------------------------------------------------------------------------
// Grids

// A_z on a polar grid centred at the roller axis:
//   r_i = r_min + i (r_max − r_min)/(n_r − 1),   i = 0 .. n_r − 1   (both ends included)
//   θ_j = j 2π / n_theta,                        j = 0 .. n_theta − 1 (periodic: θ = 2π is θ_0)
// A_z is row-major [i_r][i_theta]: A_z[i * n_theta + j].
struct PolarGrid
{
  double r_min = 0.0;   // [m], > 0 (the sleeve surface, typically)
  double r_max = 0.0;   // [m]
  int n_r = 0;          // ≥ 4 (the not-a-knot spline needs four nodes)
  int n_theta = 0;      // ≥ 8
  std::vector<double> A_z; // [T·m]

  double dr() const { return (r_max - r_min) / (n_r - 1); }
  double dtheta() const;
  double r(int i) const { return r_min + i * dr(); }
  double theta(int j) const { return j * dtheta(); }
  double &at(int i, int j) { return A_z[static_cast<size_t>(i) * n_theta + j]; }
  double at(int i, int j) const { return A_z[static_cast<size_t>(i) * n_theta + j]; }
  size_t memory_bytes() const { return A_z.size() * sizeof(double); }
};

// Φ on a Cartesian window:
//   x_i = x_min + i (x_max − x_min)/(n_x − 1),  y_j likewise (both ends included).
// phi is row-major [i_x][i_y]: phi[i * n_y + j].
struct CartesianGrid
{
  double x_min = 0.0, x_max = 0.0; // [m]
  double y_min = 0.0, y_max = 0.0; // [m]
  int n_x = 0, n_y = 0;            // ≥ 4 each
  std::vector<double> phi;         // [V]

  double dx() const { return (x_max - x_min) / (n_x - 1); }
  double dy() const { return (y_max - y_min) / (n_y - 1); }
  double x(int i) const { return x_min + i * dx(); }
  double y(int j) const { return y_min + j * dy(); }
  double &at(int i, int j) { return phi[static_cast<size_t>(i) * n_y + j]; }
  double at(int i, int j) const { return phi[static_cast<size_t>(i) * n_y + j]; }
  size_t memory_bytes() const { return phi.size() * sizeof(double); }
};

// The nip potential the DEM needs (the electric grid, format version 2). The problem is linear
// and the latent image moves with the drum surface while the sleeve and the drum stay where they
// are, so at any moment
//   Φ(x, y; u) = Φ_bias(x, y) + Φ_image(x, y; u),
// Φ_bias: the sleeve at its bias, no image; Φ_image(·; u): the sleeve grounded and the image
// carried along the drum surface by the arc length u (its surface value at arc length s from the
// nip point is the value the case gives at s − u; field_solver/nip_electrostatics.h
// latent_image_value). Φ_image is periodic in u with the image period P and stored at the K
// phases u_k = k P / K, k = 0 .. K − 1; a uniform image (P = 0) has one sample. The drum's
// centre and radius let a reader carry a sample along the surface (nip_potential_field.h).
struct NipPotentialGrid
{
  CartesianGrid bias;                     // the window, and Φ_bias [V] on it
  double image_period = 0.0;              // P [m] along the drum surface; 0: the image is uniform
  std::array<double, 2> drum_center{{0.0, 0.0}}; // [m], in the window's frame
  double drum_radius = 0.0;               // the drum (photoconductor) surface radius [m]
  std::vector<std::vector<double>> image; // K arrays laid out like bias.phi [V]

  int phase_samples() const { return static_cast<int>(image.size()); }
  // Sample k as a grid of its own (the window of `bias`).
  CartesianGrid image_grid(int k) const;
  size_t memory_bytes() const { return bias.memory_bytes() * (1 + image.size()); }
};

// Sample a field given as a function of (x, y) [m] at the grid nodes. The field solver passes
// its finite-element solution (evaluated in a batch and wrapped in a lookup) or, in tests,
// an exact solution.
PolarGrid sample_polar_grid(double r_min, double r_max, int n_r, int n_theta,
                            const std::function<double(double x, double y)> &A_z);
CartesianGrid sample_cartesian_grid(double x_min, double x_max, int n_x,
                                    double y_min, double y_max, int n_y,
                                    const std::function<double(double x, double y)> &phi);

// The polar grid a case asks for: r from the sleeve surface to FieldSettings::grid_outer_radius
// (0 = sleeve + 3 mm), node counts from grid_radial_spacing / grid_angular_spacing (rounded so
// that the spacing is at most the one asked for). Throws FieldGridError without a sleeve.
struct PolarGridLayout
{
  double r_min = 0.0, r_max = 0.0;
  int n_r = 0, n_theta = 0;
};
PolarGridLayout polar_grid_layout(const Case &c);

// Throws FieldGridError naming `what` when the grid is malformed (sizes, shapes, ordering,
// non-finite values). The writer and the reader both call these.
void validate(const PolarGrid &g, const std::string &what);
void validate(const CartesianGrid &g, const std::string &what);
void validate(const NipPotentialGrid &g, const std::string &what);

// ---------------------------------------------------------------------------------------
// The C2 interpolant of the node values, shared by both interpolators.
//
// A tensor-product cubic spline (not-a-knot ends; periodic in θ on the polar grid) is stored
// in bicubic Hermite form: per node the value f and the spline's derivatives f_p, f_q, f_pq
// with respect to the node indices (p along the first grid index, q along the second; unit
// spacing), i.e. 4 doubles per node, [f, f_p, f_q, f_pq]. The Hermite patch over one cell,
// built from its four corners, is then exactly the spline: C2 across cells, O(h^4) in f,
// O(h^3) in first and O(h^2) in second derivatives.
namespace spline {

// Slopes m_k = s'(k) of the cubic spline through f_0 .. f_{n-1} at unit spacing, reading
// f[k * stride] and writing m[k * stride]. not_a_knot: n ≥ 4. periodic: f_n ≡ f_0, n ≥ 3.
void slopes_not_a_knot(const double *f, double *m, int n, int stride);
void slopes_periodic(const double *f, double *m, int n, int stride);

// Node data [f, f_p, f_q, f_pq] (4 per node, node-major) for values f[i * n2 + j].
std::vector<double> bicubic_hermite_data(const std::vector<double> &f, int n1, int n2,
                                         bool periodic_in_second_index);

// Value and derivatives (per unit index) of the bicubic Hermite patch of one cell at local
// coordinates 0 ≤ p, q ≤ 1, from the node data of its corners c_ab = node (i + a, j + b):
// out = {f, f_p, f_q, f_pp, f_pq, f_qq}. Inline: this is the per-particle hot path.
inline void evaluate_patch(const double *c00, const double *c01, const double *c10,
                           const double *c11, double p, double q, double out[6])
{
  // Cubic Hermite basis {value at 0, value at 1, slope at 0, slope at 1} and derivatives.
  const auto basis = [](double t, double h[4], double dh[4], double ddh[4]) {
    const double t2 = t * t, t3 = t2 * t;
    h[0] = 2 * t3 - 3 * t2 + 1;   dh[0] = 6 * t2 - 6 * t;      ddh[0] = 12 * t - 6;
    h[1] = -2 * t3 + 3 * t2;      dh[1] = -6 * t2 + 6 * t;     ddh[1] = -12 * t + 6;
    h[2] = t3 - 2 * t2 + t;       dh[2] = 3 * t2 - 4 * t + 1;  ddh[2] = 6 * t - 4;
    h[3] = t3 - t2;               dh[3] = 3 * t2 - 2 * t;      ddh[3] = 6 * t - 2;
  };
  double hp[4], dhp[4], ddhp[4], hq[4], dhq[4], ddhq[4];
  basis(p, hp, dhp, ddhp);
  basis(q, hq, dhq, ddhq);
  // G[α][β]: α over the p-basis, β over the q-basis.
  const double G[4][4] = {{c00[0], c01[0], c00[2], c01[2]},
                          {c10[0], c11[0], c10[2], c11[2]},
                          {c00[1], c01[1], c00[3], c01[3]},
                          {c10[1], c11[1], c10[3], c11[3]}};
  double g0[4], g1[4], g2[4]; // G·hq, G·dhq, G·ddhq
  for (int a = 0; a < 4; ++a)
  {
    g0[a] = G[a][0] * hq[0] + G[a][1] * hq[1] + G[a][2] * hq[2] + G[a][3] * hq[3];
    g1[a] = G[a][0] * dhq[0] + G[a][1] * dhq[1] + G[a][2] * dhq[2] + G[a][3] * dhq[3];
    g2[a] = G[a][0] * ddhq[0] + G[a][1] * ddhq[1] + G[a][2] * ddhq[2] + G[a][3] * ddhq[3];
  }
  const auto dot = [](const double u[4], const double v[4]) {
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2] + u[3] * v[3];
  };
  out[0] = dot(hp, g0);
  out[1] = dot(dhp, g0);
  out[2] = dot(hp, g1);
  out[3] = dot(ddhp, g0);
  out[4] = dot(dhp, g1);
  out[5] = dot(hp, g2);
}

} // namespace spline

// ---------------------------------------------------------------------------------------
// Provenance: what the field was computed from.

struct GridProvenance
{
  // Digest of the field-relevant case inputs (case/case_hash.h field_hash()).
  std::string case_hash;
  // The canonical inputs themselves (key path → value, as case/case_hash.h field_inputs()
  // returns them), so that a mismatch can name the key. Keys contain no '=' and no newline,
  // values no newline.
  std::vector<std::pair<std::string, std::string>> case_inputs;
  // Characteristic element sizes of the mesh the field was solved on [m], named
  // (e.g. {"far", 2e-3}, {"sleeve", 1e-4}, {"gap", 2e-5}).
  std::vector<std::pair<std::string, double>> mesh_sizes;
  int element_degree = 0;
  // The solver's estimate of the field error (relative, on B or E); NaN = unknown.
  double error_estimate = std::numeric_limits<double>::quiet_NaN();
};

// The provenance a case implies for one of its fields: hash and canonical inputs
// (case_hash.h field_hash/field_inputs), mesh sizes {"far", "sleeve", "gap"} and element
// degree from FieldSettings. The field solver adds its error estimate before writing; the
// DEM compares a stored file with check_provenance(info, case_provenance(c, kind).case_inputs).
GridProvenance case_provenance(const Case &c, FieldKind kind);

// What a reader learns about a file besides the grid.
struct GridFileInfo
{
  std::string path;
  int format_version = 0;
  std::string kind;          // "magnetic" | "electric"
  std::string code_version;  // MAGBRUSH_VERSION of the writer
  std::string created;       // UTC, ISO 8601 (2026-11-22T14:40:00Z)
  std::vector<double> grid_spacing; // magnetic: {Δr [m], Δθ [rad]}; electric: {Δx, Δy} [m]
  GridProvenance provenance;
};

struct MagneticGridFile
{
  GridFileInfo info;
  PolarGrid grid;
};

struct ElectricGridFile
{
  GridFileInfo info;
  NipPotentialGrid grid;
};

// ---------------------------------------------------------------------------------------
// File format

inline constexpr const char *field_grid_format_name = "magbrush-field-grid";
// Version 3: every dataset carries HDF5's Fletcher-32 checksum, the metadata the 1.8 object
// headers' checksums, and the electric field is stored as the bias solution plus the image's
// phase samples (NipPotentialGrid). Files of an older version are refused ("regenerate"); the
// field stage regenerates them by itself.
inline constexpr int field_grid_format_version = 3;

// Write atomically: a temporary file next to `path` first (common/atomic_file.h), renamed onto
// `path` only when complete. On failure (unwritable directory, invalid grid, ...) throws
// FieldGridError and leaves no file behind; an existing `path` is untouched.
void write_magnetic_grid(const std::string &path, const PolarGrid &grid,
                         const GridProvenance &provenance);
void write_electric_grid(const std::string &path, const NipPotentialGrid &grid,
                         const GridProvenance &provenance);

// Read and check everything (see docs/field_grid_format.md); throws FieldGridError.
MagneticGridFile read_magnetic_grid(const std::string &path);
ElectricGridFile read_electric_grid(const std::string &path);

// Only the root attributes (no grid data): cheap, for "is the stored field up to date?".
GridFileInfo read_grid_info(const std::string &path);

// The first canonical input whose value differs between the file and the case (or that
// only one of them has), as a message naming the key, both values and the remedy; empty
// when they agree.
std::string provenance_difference(const GridFileInfo &file,
                                  const std::vector<std::pair<std::string, std::string>> &expected_inputs);

// Throws ProvenanceMismatch (with the key) when provenance_difference() is not empty.
void check_provenance(const GridFileInfo &file,
                      const std::vector<std::pair<std::string, std::string>> &expected_inputs);

} // namespace magbrush
