// Field grids: sampling, validation, the spline node data, and the HDF5 writer and reader.
// The file layout is documented in docs/field_grid_format.md; keep the two in step.
#include "fields/field_grid.h"

#include "common/atomic_file.h"

#include "fields/cartesian_field_interpolator.h"
#include "fields/polar_field_interpolator.h"

#include <hdf5.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <sstream>

#ifndef MAGBRUSH_VERSION
#define MAGBRUSH_VERSION "unknown"
#endif

namespace magbrush {

namespace {
constexpr double two_pi = 2.0 * M_PI;
}

double PolarGrid::dtheta() const { return two_pi / n_theta; }

// ---------------------------------------------------------------------------------------
// Sampling and layout

PolarGrid sample_polar_grid(double r_min, double r_max, int n_r, int n_theta,
                            const std::function<double(double, double)> &A_z)
{
  PolarGrid g;
  g.r_min = r_min;
  g.r_max = r_max;
  g.n_r = n_r;
  g.n_theta = n_theta;
  if (n_r < 1 || n_theta < 1)
    throw FieldGridError("sample_polar_grid: node counts must be positive, found n_r = " +
                         std::to_string(n_r) + ", n_theta = " + std::to_string(n_theta));
  g.A_z.resize(static_cast<size_t>(n_r) * n_theta);
  for (int i = 0; i < n_r; ++i)
    for (int j = 0; j < n_theta; ++j)
    {
      const double r = g.r(i), t = g.theta(j);
      g.at(i, j) = A_z(r * std::cos(t), r * std::sin(t));
    }
  return g;
}

CartesianGrid sample_cartesian_grid(double x_min, double x_max, int n_x, double y_min,
                                    double y_max, int n_y,
                                    const std::function<double(double, double)> &phi)
{
  CartesianGrid g;
  g.x_min = x_min;
  g.x_max = x_max;
  g.y_min = y_min;
  g.y_max = y_max;
  g.n_x = n_x;
  g.n_y = n_y;
  if (n_x < 1 || n_y < 1)
    throw FieldGridError("sample_cartesian_grid: node counts must be positive, found n_x = " +
                         std::to_string(n_x) + ", n_y = " + std::to_string(n_y));
  g.phi.resize(static_cast<size_t>(n_x) * n_y);
  for (int i = 0; i < n_x; ++i)
    for (int j = 0; j < n_y; ++j)
      g.at(i, j) = phi(g.x(i), g.y(j));
  return g;
}

PolarGridLayout polar_grid_layout(const Case &c)
{
  if (!c.sleeve)
    throw FieldGridError("case '" + c.source_file +
                         "': a polar field grid needs a sleeve (the grid starts at its surface)");
  const FieldSettings &f = c.field;
  if (!(f.grid_radial_spacing > 0) || !(f.grid_angular_spacing > 0))
    throw FieldGridError("case '" + c.source_file +
                         "': field.grid_radial_spacing and field.grid_angular_spacing must be > 0");
  PolarGridLayout l;
  l.r_min = c.sleeve->radius;
  l.r_max = f.grid_outer_radius > 0 ? f.grid_outer_radius : c.sleeve->radius + 3e-3;
  if (!(l.r_max > l.r_min))
    throw FieldGridError("case '" + c.source_file + "': field.grid_outer_radius (" +
                         std::to_string(l.r_max) + " m) must exceed the sleeve radius (" +
                         std::to_string(l.r_min) + " m)");
  // Round the node counts up, so the spacing is never coarser than asked for.
  l.n_r = std::max(4, 1 + static_cast<int>(std::ceil((l.r_max - l.r_min) / f.grid_radial_spacing - 1e-9)));
  l.n_theta = std::max(8, static_cast<int>(std::ceil(two_pi / f.grid_angular_spacing - 1e-9)));
  return l;
}

// ---------------------------------------------------------------------------------------
// Validation

namespace {

std::string num(double v)
{
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

void require_finite(const std::vector<double> &v, const std::string &what,
                    const std::string &dataset, int n2)
{
  for (size_t k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]))
      throw FieldGridError(what + ": " + dataset + " has a non-finite value (" + num(v[k]) +
                           ") at node [" + std::to_string(k / n2) + "][" +
                           std::to_string(k % n2) +
                           "]; the field solver produced NaN/Inf there — check its log "
                           "and regenerate the field");
}

} // namespace

void validate(const PolarGrid &g, const std::string &what)
{
  if (g.n_r < 4 || g.n_theta < 8)
    throw FieldGridError(what + ": polar grid needs n_r ≥ 4 and n_theta ≥ 8, found n_r = " +
                         std::to_string(g.n_r) + ", n_theta = " + std::to_string(g.n_theta));
  if (!(std::isfinite(g.r_min) && std::isfinite(g.r_max) && g.r_min > 0 && g.r_max > g.r_min))
    throw FieldGridError(what + ": polar grid needs 0 < r_min < r_max, found r_min = " +
                         num(g.r_min) + " m, r_max = " + num(g.r_max) + " m");
  const size_t expected = static_cast<size_t>(g.n_r) * g.n_theta;
  if (g.A_z.size() != expected)
    throw FieldGridError(what + ": A_z has " + std::to_string(g.A_z.size()) +
                         " values but n_r × n_theta = " + std::to_string(expected));
  require_finite(g.A_z, what, "/polar/A_z", g.n_theta);
}

void validate(const CartesianGrid &g, const std::string &what)
{
  if (g.n_x < 4 || g.n_y < 4)
    throw FieldGridError(what + ": Cartesian grid needs n_x ≥ 4 and n_y ≥ 4, found n_x = " +
                         std::to_string(g.n_x) + ", n_y = " + std::to_string(g.n_y));
  if (!(std::isfinite(g.x_min) && std::isfinite(g.x_max) && g.x_max > g.x_min &&
        std::isfinite(g.y_min) && std::isfinite(g.y_max) && g.y_max > g.y_min))
    throw FieldGridError(what + ": Cartesian grid needs x_min < x_max and y_min < y_max, found x = [" +
                         num(g.x_min) + ", " + num(g.x_max) + "], y = [" + num(g.y_min) + ", " +
                         num(g.y_max) + "]");
  const size_t expected = static_cast<size_t>(g.n_x) * g.n_y;
  if (g.phi.size() != expected)
    throw FieldGridError(what + ": phi has " + std::to_string(g.phi.size()) +
                         " values but n_x × n_y = " + std::to_string(expected));
  require_finite(g.phi, what, "/cartesian/phi", g.n_y);
}

CartesianGrid NipPotentialGrid::image_grid(int k) const
{
  CartesianGrid g = bias;
  g.phi = image.at(static_cast<size_t>(k));
  return g;
}

void validate(const NipPotentialGrid &g, const std::string &what)
{
  validate(g.bias, what + " (bias solution)");
  if (!(std::isfinite(g.image_period) && g.image_period >= 0.0))
    throw FieldGridError(what + ": the image period must be finite and ≥ 0, found " +
                         num(g.image_period) + " m");
  if (g.image.empty())
    throw FieldGridError(what + ": the image needs at least one phase sample, found none");
  if (!(std::isfinite(g.drum_radius) && g.drum_radius >= 0.0 && std::isfinite(g.drum_center[0]) &&
        std::isfinite(g.drum_center[1])))
    throw FieldGridError(what + ": the drum centre and radius must be finite (radius ≥ 0), found (" +
                         num(g.drum_center[0]) + ", " + num(g.drum_center[1]) + ") m, " +
                         num(g.drum_radius) + " m");
  if (g.image_period == 0.0 && g.image.size() != 1)
    throw FieldGridError(what + ": a uniform image (period 0) has exactly one phase sample, found " +
                         std::to_string(g.image.size()));
  for (size_t k = 0; k < g.image.size(); ++k)
  {
    if (g.image[k].size() != g.bias.phi.size())
      throw FieldGridError(what + ": image phase sample " + std::to_string(k) + " has " +
                           std::to_string(g.image[k].size()) + " values but n_x × n_y = " +
                           std::to_string(g.bias.phi.size()));
    require_finite(g.image[k], what, "/cartesian/phi_image[" + std::to_string(k) + "]", g.bias.n_y);
  }
}

// ---------------------------------------------------------------------------------------
// Spline node data

namespace spline {

// Interior rows of the C2 condition at unit spacing: m_{k-1} + 4 m_k + m_{k+1} = 3 (f_{k+1} − f_{k-1}).
// Not-a-knot (third derivative continuous at nodes 1 and n−2), eliminated into tridiagonal
// end rows:  m_0 + 2 m_1 = (−5 f_0 + 4 f_1 + f_2)/2  and its mirror image.
void slopes_not_a_knot(const double *f, double *m, int n, int stride)
{
  if (n < 4)
    throw FieldGridError("not-a-knot spline needs at least 4 nodes, found " + std::to_string(n));
  // Thomas algorithm; c holds the modified super-diagonal (small n: a local buffer).
  std::vector<double> c(n);
  const auto F = [&](int k) { return f[static_cast<size_t>(k) * stride]; };
  double *const M = m;
  const auto Mk = [&](int k) -> double & { return M[static_cast<size_t>(k) * stride]; };
  // Row 0: b = 1, c = 2.
  c[0] = 2.0;
  Mk(0) = 0.5 * (-5 * F(0) + 4 * F(1) + F(2));
  for (int k = 1; k < n - 1; ++k)
  {
    const double denom = 4.0 - c[k - 1];
    c[k] = 1.0 / denom;
    Mk(k) = (3.0 * (F(k + 1) - F(k - 1)) - Mk(k - 1)) / denom;
  }
  // Row n−1: a = 2, b = 1.
  const double rhs = 0.5 * (5 * F(n - 1) - 4 * F(n - 2) - F(n - 3));
  Mk(n - 1) = (rhs - 2.0 * Mk(n - 2)) / (1.0 - 2.0 * c[n - 2]);
  for (int k = n - 2; k >= 0; --k)
    Mk(k) -= c[k] * Mk(k + 1);
}

// Cyclic system m_{k-1} + 4 m_k + m_{k+1} = 3 (f_{k+1} − f_{k-1}) (indices mod n), solved by
// the Sherman–Morrison correction of the tridiagonal part.
void slopes_periodic(const double *f, double *m, int n, int stride)
{
  if (n < 3)
    throw FieldGridError("periodic spline needs at least 3 nodes, found " + std::to_string(n));
  const auto F = [&](int k) { return f[static_cast<size_t>(((k % n) + n) % n) * stride]; };
  // A = T + u vᵀ with u = (γ, 0, …, 0, 1), v = (1, 0, …, 0, 1/γ), γ = −4.
  const double gamma = -4.0;
  std::vector<double> b(n, 4.0), c(n), y(n), z(n);
  b[0] = 4.0 - gamma;
  b[n - 1] = 4.0 - 1.0 / gamma;
  // Factor T once (a = c = 1), solve for the right-hand side and for u.
  std::vector<double> rhs(n), u(n, 0.0);
  for (int k = 0; k < n; ++k)
    rhs[k] = 3.0 * (F(k + 1) - F(k - 1));
  u[0] = gamma;
  u[n - 1] = 1.0;
  double denom = b[0];
  c[0] = 1.0 / denom;
  y[0] = rhs[0] / denom;
  z[0] = u[0] / denom;
  for (int k = 1; k < n; ++k)
  {
    denom = b[k] - c[k - 1];
    c[k] = 1.0 / denom;
    y[k] = (rhs[k] - y[k - 1]) / denom;
    z[k] = (u[k] - z[k - 1]) / denom;
  }
  for (int k = n - 2; k >= 0; --k)
  {
    y[k] -= c[k] * y[k + 1];
    z[k] -= c[k] * z[k + 1];
  }
  const double factor = (y[0] + y[n - 1] / gamma) / (1.0 + z[0] + z[n - 1] / gamma);
  for (int k = 0; k < n; ++k)
    m[static_cast<size_t>(k) * stride] = y[k] - factor * z[k];
}

std::vector<double> bicubic_hermite_data(const std::vector<double> &f, int n1, int n2,
                                         bool periodic_in_second_index)
{
  const size_t nodes = static_cast<size_t>(n1) * n2;
  if (f.size() != nodes)
    throw FieldGridError("bicubic_hermite_data: " + std::to_string(f.size()) +
                         " values for a " + std::to_string(n1) + " × " + std::to_string(n2) +
                         " grid");
  std::vector<double> f_p(nodes), f_q(nodes), f_pq(nodes);
  const auto along_q = [&](const double *in, double *out) {
    if (periodic_in_second_index)
      slopes_periodic(in, out, n2, 1);
    else
      slopes_not_a_knot(in, out, n2, 1);
  };
  for (int i = 0; i < n1; ++i)
    along_q(&f[static_cast<size_t>(i) * n2], &f_q[static_cast<size_t>(i) * n2]);
  for (int j = 0; j < n2; ++j)
  {
    slopes_not_a_knot(&f[j], &f_p[j], n1, n2);
    // The tensor-product spline's mixed derivative: the p-spline of the q-slopes.
    slopes_not_a_knot(&f_q[j], &f_pq[j], n1, n2);
  }
  std::vector<double> data(4 * nodes);
  for (size_t k = 0; k < nodes; ++k)
  {
    data[4 * k + 0] = f[k];
    data[4 * k + 1] = f_p[k];
    data[4 * k + 2] = f_q[k];
    data[4 * k + 3] = f_pq[k];
  }
  return data;
}

} // namespace spline

GridProvenance case_provenance(const Case &c, FieldKind kind)
{
  GridProvenance p;
  p.case_hash = field_hash(c, kind);
  p.case_inputs = field_inputs(c, kind);
  p.mesh_sizes = {{"far", c.field.mesh_size_far},
                  {"sleeve", c.field.mesh_size_sleeve},
                  {"gap", c.field.mesh_size_gap}};
  p.element_degree = c.field.element_degree;
  return p;
}

// ---------------------------------------------------------------------------------------
// HDF5 plumbing: handles closed by RAII, the library's own error printing silenced (we
// throw messages of our own).

namespace {

class Handle
{
public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(const Handle &) = delete;
  Handle &operator=(const Handle &) = delete;
  Handle(Handle &&other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = -1; }
  ~Handle()
  {
    if (id_ >= 0)
      closer_(id_);
  }
  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }

private:
  hid_t id_;
  Closer closer_;
};

// Silences HDF5's automatic error-stack printing for the lifetime of the object.
class QuietHdf5
{
public:
  QuietHdf5()
  {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

private:
  H5E_auto2_t func_ = nullptr;
  void *data_ = nullptr;
};

std::string utc_now_iso8601()
{
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buffer;
}

// --- writing -----------------------------------------------------------------------------

struct Writer
{
  std::string path; // for messages (the final path, not the .tmp)

  void check(herr_t status, const std::string &what) const
  {
    if (status < 0)
      throw FieldGridError("file " + path + ": HDF5 failed to write " + what +
                           " (disk full or file system error?)");
  }

  void string_attribute(hid_t object, const std::string &name, const std::string &value) const
  {
    Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
    check(H5Tset_size(type, std::max<size_t>(1, value.size())), "attribute " + name);
    check(H5Tset_strpad(type, H5T_STR_NULLPAD), "attribute " + name);
    check(H5Tset_cset(type, H5T_CSET_UTF8), "attribute " + name);
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle attr(H5Acreate2(object, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (!attr.valid())
      check(-1, "attribute " + name);
    check(H5Awrite(attr, type, value.empty() ? "" : value.data()), "attribute " + name);
  }

  void double_attribute(hid_t object, const std::string &name, const std::vector<double> &v) const
  {
    const hsize_t n = v.size();
    Handle space(n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
    Handle attr(H5Acreate2(object, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose);
    if (!attr.valid())
      check(-1, "attribute " + name);
    check(H5Awrite(attr, H5T_NATIVE_DOUBLE, v.data()), "attribute " + name);
  }

  void int_attribute(hid_t object, const std::string &name, int value) const
  {
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle attr(H5Acreate2(object, name.c_str(), H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose);
    if (!attr.valid())
      check(-1, "attribute " + name);
    check(H5Awrite(attr, H5T_NATIVE_INT, &value), "attribute " + name);
  }

  // Every dataset is chunked with HDF5's Fletcher-32 checksum filter, so that a value damaged
  // on disk fails the read instead of entering a run (docs/field_grid_format.md). A chunk
  // holds whole rows, at most about 1 MiB.
  void dataset(hid_t group, const std::string &name, const std::vector<double> &data,
               const std::vector<hsize_t> &dims, const std::string &units) const
  {
    Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
    Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    hsize_t row = 1;
    for (size_t d = 1; d < dims.size(); ++d)
      row *= dims[d];
    std::vector<hsize_t> chunk = dims;
    if (!dims.empty() && !data.empty())
    {
      chunk[0] = std::max<hsize_t>(1, std::min<hsize_t>(dims[0], (hsize_t{1} << 17) / std::max<hsize_t>(row, 1)));
      check(H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data()), "dataset " + name + " (chunks)");
      check(H5Pset_fletcher32(dcpl), "dataset " + name + " (Fletcher-32 filter)");
    }
    Handle set(H5Dcreate2(group, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT),
               H5Dclose);
    if (!set.valid())
      check(-1, "dataset " + name);
    check(H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()),
          "dataset " + name);
    string_attribute(set, "units", units);
  }
};

std::string join_inputs(const std::vector<std::pair<std::string, std::string>> &inputs,
                        const std::string &path)
{
  std::string lines;
  for (const auto &[key, value] : inputs)
  {
    if (key.empty() || key.find_first_of("=\n") != std::string::npos ||
        value.find('\n') != std::string::npos)
      throw FieldGridError("file " + path + ": provenance input '" + key +
                           "' cannot be stored (keys must be non-empty without '=' or newline, "
                           "values without newline)");
    lines += key + "=" + value + "\n";
  }
  return lines;
}

void write_provenance(const Writer &w, hid_t root, const std::string &kind,
                      const GridProvenance &p, const std::vector<double> &spacing)
{
  w.string_attribute(root, "format", field_grid_format_name);
  w.int_attribute(root, "format_version", field_grid_format_version);
  w.string_attribute(root, "kind", kind);
  w.string_attribute(root, "code_version", MAGBRUSH_VERSION);
  w.string_attribute(root, "created", utc_now_iso8601());
  w.string_attribute(root, "case_hash", p.case_hash);
  w.string_attribute(root, "case_inputs", join_inputs(p.case_inputs, w.path));
  std::string names;
  std::vector<double> sizes;
  for (const auto &[name, size] : p.mesh_sizes)
  {
    if (name.find('\n') != std::string::npos)
      throw FieldGridError("file " + w.path + ": mesh size name '" + name + "' contains a newline");
    names += name + "\n";
    sizes.push_back(size);
  }
  w.string_attribute(root, "mesh_size_names", names);
  // An empty list is stored as an empty string and a one-element NaN array, so the
  // attribute always exists; the reader pairs sizes with names.
  w.double_attribute(root, "mesh_sizes",
                     sizes.empty() ? std::vector<double>{std::nan("")} : sizes);
  w.int_attribute(root, "element_degree", p.element_degree);
  w.double_attribute(root, "grid_spacing", spacing);
  w.double_attribute(root, "error_estimate", {p.error_estimate});
}

// Creates a temporary file next to `path` (AtomicFile), lets `fill` write into its root
// group, then renames it onto `path`. Any failure removes the temporary file, so no partial
// file is ever left behind.
template <typename Fill>
void write_atomically(const std::string &path, Fill fill)
{
  AtomicFile file(path);
  QuietHdf5 quiet;
  {
    // The 1.8 object-header format checksums the metadata (the attributes: provenance, grid
    // layout) as the filter does the values.
    Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_LATEST);
    Handle h5(H5Fcreate(file.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), H5Fclose);
    if (!h5.valid())
      throw FieldGridError("file " + path + ": cannot create '" + file.temp_path() +
                           "' (does the directory exist and is it writable?)");
    Writer w{path};
    fill(w, h5);
    if (H5Fflush(h5, H5F_SCOPE_GLOBAL) < 0)
      throw FieldGridError("file " + path + ": HDF5 failed to flush '" + file.temp_path() + "'");
  }
  try
  {
    file.commit();
  }
  catch (const AtomicFileError &e)
  {
    throw FieldGridError("file " + path + ": " + e.what());
  }
}

std::vector<double> linspace(double a, double b, int n, bool include_end)
{
  std::vector<double> v(n);
  const double h = (b - a) / (include_end ? n - 1 : n);
  for (int k = 0; k < n; ++k)
    v[k] = a + k * h;
  if (include_end)
    v[n - 1] = b;
  return v;
}

} // namespace

void write_magnetic_grid(const std::string &path, const PolarGrid &grid,
                         const GridProvenance &provenance)
{
  validate(grid, "file " + path);
  write_atomically(path, [&](const Writer &w, hid_t file) {
    write_provenance(w, file, "magnetic", provenance, {grid.dr(), grid.dtheta()});
    Handle group(H5Gcreate2(file, "polar", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (!group.valid())
      w.check(-1, "group /polar");
    w.double_attribute(group, "r_min", {grid.r_min});
    w.double_attribute(group, "r_max", {grid.r_max});
    w.int_attribute(group, "n_r", grid.n_r);
    w.int_attribute(group, "n_theta", grid.n_theta);
    w.dataset(group, "r", linspace(grid.r_min, grid.r_max, grid.n_r, true),
              {static_cast<hsize_t>(grid.n_r)}, "m");
    w.dataset(group, "theta", linspace(0.0, two_pi, grid.n_theta, false),
              {static_cast<hsize_t>(grid.n_theta)}, "rad");
    const std::vector<hsize_t> shape = {static_cast<hsize_t>(grid.n_r),
                                        static_cast<hsize_t>(grid.n_theta)};
    w.dataset(group, "A_z", grid.A_z, shape, "T*m");
    // For inspection only (h5py, ParaView); the reader ignores them: B at the nodes, from the
    // same spline the DEM uses, in polar components.
    const PolarFieldInterpolator interp(grid);
    std::vector<double> B_r(grid.A_z.size()), B_theta(grid.A_z.size());
    for (int i = 0; i < grid.n_r; ++i)
      for (int j = 0; j < grid.n_theta; ++j)
      {
        const double c = std::cos(grid.theta(j)), s = std::sin(grid.theta(j));
        const Vec3 B = interp.field({grid.r(i) * c, grid.r(i) * s, 0.0});
        B_r[static_cast<size_t>(i) * grid.n_theta + j] = B[0] * c + B[1] * s;
        B_theta[static_cast<size_t>(i) * grid.n_theta + j] = -B[0] * s + B[1] * c;
      }
    w.dataset(group, "B_r", B_r, shape, "T");
    w.dataset(group, "B_theta", B_theta, shape, "T");
  });
}

void write_electric_grid(const std::string &path, const NipPotentialGrid &nip,
                         const GridProvenance &provenance)
{
  validate(nip, "file " + path);
  const CartesianGrid &grid = nip.bias;
  write_atomically(path, [&](const Writer &w, hid_t file) {
    write_provenance(w, file, "electric", provenance, {grid.dx(), grid.dy()});
    Handle group(H5Gcreate2(file, "cartesian", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (!group.valid())
      w.check(-1, "group /cartesian");
    w.double_attribute(group, "x_min", {grid.x_min});
    w.double_attribute(group, "x_max", {grid.x_max});
    w.double_attribute(group, "y_min", {grid.y_min});
    w.double_attribute(group, "y_max", {grid.y_max});
    w.int_attribute(group, "n_x", grid.n_x);
    w.int_attribute(group, "n_y", grid.n_y);
    w.double_attribute(group, "image_period", {nip.image_period});
    w.int_attribute(group, "phase_samples", nip.phase_samples());
    w.double_attribute(group, "drum_center", {nip.drum_center[0], nip.drum_center[1]});
    w.double_attribute(group, "drum_radius", {nip.drum_radius});
    w.dataset(group, "x", linspace(grid.x_min, grid.x_max, grid.n_x, true),
              {static_cast<hsize_t>(grid.n_x)}, "m");
    w.dataset(group, "y", linspace(grid.y_min, grid.y_max, grid.n_y, true),
              {static_cast<hsize_t>(grid.n_y)}, "m");
    const std::vector<hsize_t> shape = {static_cast<hsize_t>(grid.n_x),
                                        static_cast<hsize_t>(grid.n_y)};
    w.dataset(group, "phi_bias", grid.phi, shape, "V");
    std::vector<double> images;
    images.reserve(grid.phi.size() * nip.image.size());
    for (const auto &sample : nip.image)
      images.insert(images.end(), sample.begin(), sample.end());
    w.dataset(group, "phi_image", images,
              {static_cast<hsize_t>(nip.phase_samples()), shape[0], shape[1]}, "V");
    // For inspection only; the reader ignores them: Φ and E = −∇Φ at the nodes at phase 0
    // (the image as the case gives it, bias on).
    CartesianGrid total = grid;
    for (size_t k = 0; k < total.phi.size(); ++k)
      total.phi[k] += nip.image[0][k];
    w.dataset(group, "phi", total.phi, shape, "V");
    const CartesianFieldInterpolator interp(total);
    std::vector<double> E_x(grid.phi.size()), E_y(grid.phi.size());
    for (int i = 0; i < grid.n_x; ++i)
      for (int j = 0; j < grid.n_y; ++j)
      {
        const Vec3 E = interp.field({grid.x(i), grid.y(j), 0.0});
        E_x[static_cast<size_t>(i) * grid.n_y + j] = E[0];
        E_y[static_cast<size_t>(i) * grid.n_y + j] = E[1];
      }
    w.dataset(group, "E_x", E_x, shape, "V/m");
    w.dataset(group, "E_y", E_y, shape, "V/m");
  });
}

// ---------------------------------------------------------------------------------------
// Reading

namespace {

struct Reader
{
  std::string path;

  [[noreturn]] void fail(const std::string &message) const
  {
    throw FieldGridError("file " + path + ": " + message);
  }

  static std::string object_name(hid_t object)
  {
    char buffer[256];
    const ssize_t n = H5Iget_name(object, buffer, sizeof(buffer));
    return n > 0 ? std::string(buffer, static_cast<size_t>(std::min<ssize_t>(n, 255))) : "?";
  }

  Handle open_attribute(hid_t object, const std::string &name) const
  {
    if (H5Aexists(object, name.c_str()) <= 0)
      fail("attribute '" + name + "' of " + object_name(object) +
           " is missing; this is not a complete magbrush field grid (regenerate it with "
           "`magbrush field CASE`)");
    return Handle(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose);
  }

  std::string string_attribute(hid_t object, const std::string &name) const
  {
    Handle attr = open_attribute(object, name);
    Handle type(H5Aget_type(attr), H5Tclose);
    if (H5Tget_class(type) != H5T_STRING)
      fail("attribute '" + name + "' of " + object_name(object) + " should be a string");
    Handle space(H5Aget_space(attr), H5Sclose);
    if (H5Sget_simple_extent_npoints(space) != 1)
      fail("attribute '" + name + "' of " + object_name(object) + " should be a single string");
    if (H5Tis_variable_str(type) > 0)
    {
      Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(mem, H5T_VARIABLE);
      H5Tset_cset(mem, H5Tget_cset(type));
      char *value = nullptr;
      if (H5Aread(attr, mem, &value) < 0)
        fail("cannot read attribute '" + name + "'");
      std::string result = value ? value : "";
      H5free_memory(value);
      return result;
    }
    const size_t size = H5Tget_size(type);
    std::string buffer(size, '\0');
    if (H5Aread(attr, type, buffer.data()) < 0)
      fail("cannot read attribute '" + name + "'");
    return buffer.substr(0, buffer.find('\0'));
  }

  std::vector<double> double_attribute(hid_t object, const std::string &name) const
  {
    Handle attr = open_attribute(object, name);
    Handle type(H5Aget_type(attr), H5Tclose);
    if (H5Tget_class(type) != H5T_FLOAT && H5Tget_class(type) != H5T_INTEGER)
      fail("attribute '" + name + "' of " + object_name(object) + " should be a number");
    Handle space(H5Aget_space(attr), H5Sclose);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    std::vector<double> v(static_cast<size_t>(std::max<hssize_t>(n, 0)));
    if (n <= 0 || H5Aread(attr, H5T_NATIVE_DOUBLE, v.data()) < 0)
      fail("cannot read attribute '" + name + "' of " + object_name(object));
    return v;
  }

  double scalar_attribute(hid_t object, const std::string &name) const
  {
    const std::vector<double> v = double_attribute(object, name);
    if (v.size() != 1)
      fail("attribute '" + name + "' of " + object_name(object) + " should be a single number, found " +
           std::to_string(v.size()));
    return v[0];
  }

  int int_attribute(hid_t object, const std::string &name) const
  {
    const double v = scalar_attribute(object, name);
    if (!(std::isfinite(v) && v == std::floor(v) && std::abs(v) < 2e9))
      fail("attribute '" + name + "' of " + object_name(object) + " should be an integer, found " +
           num(v));
    return static_cast<int>(v);
  }

  Handle open_group(hid_t file, const std::string &name) const
  {
    if (H5Lexists(file, name.c_str(), H5P_DEFAULT) <= 0)
      fail("group /" + name + " is missing (is this a field grid of the right kind?)");
    Handle group(H5Gopen2(file, name.c_str(), H5P_DEFAULT), H5Gclose);
    if (!group.valid())
      fail("/" + name + " is not a group");
    return group;
  }

  // A dataset of doubles with the expected shape and units.
  std::vector<double> dataset(hid_t group, const std::string &group_name, const std::string &name,
                              const std::vector<hsize_t> &expected_dims,
                              const std::string &expected_units) const
  {
    const std::string full = "/" + group_name + "/" + name;
    if (H5Lexists(group, name.c_str(), H5P_DEFAULT) <= 0)
      fail("dataset " + full + " is missing");
    Handle set(H5Dopen2(group, name.c_str(), H5P_DEFAULT), H5Dclose);
    if (!set.valid())
      fail(full + " is not a dataset");
    Handle type(H5Dget_type(set), H5Tclose);
    if (H5Tget_class(type) != H5T_FLOAT)
      fail("dataset " + full + " should hold floating-point numbers");
    Handle space(H5Dget_space(set), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space);
    std::vector<hsize_t> dims(static_cast<size_t>(std::max(rank, 0)));
    if (rank > 0)
      H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    if (dims != expected_dims)
    {
      const auto shape = [](const std::vector<hsize_t> &d) {
        std::string s = "(";
        for (size_t k = 0; k < d.size(); ++k)
          s += (k ? ", " : "") + std::to_string(d[k]);
        return s + ")";
      };
      fail("dataset " + full + " has shape " + shape(dims) + " but " + shape(expected_dims) +
           " was expected from the grid attributes");
    }
    if (H5Aexists(set, "units") <= 0)
      fail("dataset " + full + " has no 'units' attribute ('" + expected_units + "' was expected)");
    const std::string units = string_attribute(set, "units");
    if (units != expected_units)
      fail("dataset " + full + " has units '" + units + "' but '" + expected_units +
           "' was expected");
    size_t count = 1;
    for (hsize_t d : dims)
      count *= d;
    if (count > 0 && !has_checksum(set))
      fail("dataset " + full + " carries no Fletcher-32 checksum (every format_version " +
           std::to_string(field_grid_format_version) +
           " dataset does): the file was not written by this magbrush; regenerate it with `magbrush field CASE`");
    std::vector<double> data(count);
    if (count > 0 && H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
      fail("dataset " + full + " is damaged: its Fletcher-32 checksum does not match its values (the file "
           "changed on disk after it was written); regenerate it with `magbrush field CASE`");
    return data;
  }

  static bool has_checksum(hid_t set)
  {
    Handle dcpl(H5Dget_create_plist(set), H5Pclose);
    unsigned flags = 0;
    size_t n_values = 0;
    return dcpl.valid() &&
           H5Pget_filter_by_id2(dcpl, H5Z_FILTER_FLETCHER32, &flags, &n_values, nullptr, 0, nullptr, nullptr) >= 0;
  }

  // The axis must be the uniform one the attributes describe (strictly increasing).
  void check_axis(const std::vector<double> &axis, const std::vector<double> &expected,
                  const std::string &full, double spacing) const
  {
    for (size_t k = 0; k < axis.size(); ++k)
    {
      if (!std::isfinite(axis[k]))
        fail("dataset " + full + " has a non-finite value at index " + std::to_string(k));
      if (k > 0 && !(axis[k] > axis[k - 1]))
        fail("dataset " + full + " is not strictly increasing at index " + std::to_string(k));
    }
    for (size_t k = 0; k < axis.size(); ++k)
    {
      if (std::abs(axis[k] - expected[k]) > 1e-9 * spacing + 1e-15 * std::abs(expected[k]))
        fail("dataset " + full + " is not the uniform axis of the grid attributes: value " +
             num(axis[k]) + " at index " + std::to_string(k) + ", expected " + num(expected[k]));
    }
  }
};

Handle open_for_reading(const std::string &path)
{
  FILE *probe = std::fopen(path.c_str(), "rb");
  if (!probe)
    throw FieldGridError("file " + path + ": cannot open it (" + std::strerror(errno) +
                         "); run `magbrush field CASE` to compute the field");
  std::fclose(probe);
  if (H5Fis_hdf5(path.c_str()) <= 0)
    throw FieldGridError("file " + path + ": not an HDF5 file (expected a " +
                         std::string(field_grid_format_name) + " file written by magbrush)");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid())
    throw FieldGridError("file " + path + ": HDF5 cannot open it (damaged or truncated?)");
  return file;
}

GridFileInfo read_info(const Reader &r, hid_t file)
{
  GridFileInfo info;
  info.path = r.path;
  if (H5Aexists(file, "format") <= 0)
    r.fail("no 'format' attribute: not a " + std::string(field_grid_format_name) + " file");
  const std::string format = r.string_attribute(file, "format");
  if (format != field_grid_format_name)
    r.fail("format is '" + format + "' but '" + field_grid_format_name + "' was expected");
  info.format_version = r.int_attribute(file, "format_version");
  if (info.format_version != field_grid_format_version)
    r.fail("format_version is " + std::to_string(info.format_version) + " but this magbrush (" +
           MAGBRUSH_VERSION + ") reads version " + std::to_string(field_grid_format_version) +
           " (checksummed datasets; the electric field as bias solution plus the image's phase samples); "
           "regenerate the field with this version (`magbrush field CASE`)");
  info.kind = r.string_attribute(file, "kind");
  if (info.kind != "magnetic" && info.kind != "electric")
    r.fail("kind is '" + info.kind + "' but 'magnetic' or 'electric' was expected");
  info.code_version = r.string_attribute(file, "code_version");
  info.created = r.string_attribute(file, "created");
  info.grid_spacing = r.double_attribute(file, "grid_spacing");

  GridProvenance &p = info.provenance;
  p.case_hash = r.string_attribute(file, "case_hash");
  std::istringstream lines(r.string_attribute(file, "case_inputs"));
  for (std::string line; std::getline(lines, line);)
  {
    if (line.empty())
      continue;
    const size_t eq = line.find('=');
    if (eq == std::string::npos || eq == 0)
      r.fail("attribute 'case_inputs' has a line without 'key=value': '" + line + "'");
    p.case_inputs.emplace_back(line.substr(0, eq), line.substr(eq + 1));
  }
  std::vector<std::string> names;
  std::istringstream name_lines(r.string_attribute(file, "mesh_size_names"));
  for (std::string line; std::getline(name_lines, line);)
    names.push_back(line);
  const std::vector<double> sizes = r.double_attribute(file, "mesh_sizes");
  if (!names.empty() && names.size() != sizes.size())
    r.fail("attribute 'mesh_sizes' has " + std::to_string(sizes.size()) + " values for " +
           std::to_string(names.size()) + " names in 'mesh_size_names'");
  for (size_t k = 0; k < names.size(); ++k)
    p.mesh_sizes.emplace_back(names[k], sizes[k]);
  p.element_degree = r.int_attribute(file, "element_degree");
  p.error_estimate = r.scalar_attribute(file, "error_estimate");
  return info;
}

void require_kind(const Reader &r, const GridFileInfo &info, const std::string &kind)
{
  if (info.kind != kind)
    r.fail("kind is '" + info.kind + "' but a '" + kind + "' field grid was expected");
}

} // namespace

GridFileInfo read_grid_info(const std::string &path)
{
  QuietHdf5 quiet;
  Handle file = open_for_reading(path);
  return read_info(Reader{path}, file);
}

MagneticGridFile read_magnetic_grid(const std::string &path)
{
  QuietHdf5 quiet;
  Handle file = open_for_reading(path);
  const Reader r{path};
  MagneticGridFile out;
  out.info = read_info(r, file);
  require_kind(r, out.info, "magnetic");

  Handle group = r.open_group(file, "polar");
  PolarGrid &g = out.grid;
  g.r_min = r.scalar_attribute(group, "r_min");
  g.r_max = r.scalar_attribute(group, "r_max");
  g.n_r = r.int_attribute(group, "n_r");
  g.n_theta = r.int_attribute(group, "n_theta");
  if (g.n_r < 4 || g.n_theta < 8)
    r.fail("polar grid needs n_r ≥ 4 and n_theta ≥ 8, found n_r = " + std::to_string(g.n_r) +
           ", n_theta = " + std::to_string(g.n_theta));
  if (!(std::isfinite(g.r_min) && std::isfinite(g.r_max) && g.r_min > 0 && g.r_max > g.r_min))
    r.fail("polar grid needs 0 < r_min < r_max, found r_min = " + num(g.r_min) + ", r_max = " +
           num(g.r_max));
  const auto nr = static_cast<hsize_t>(g.n_r), nt = static_cast<hsize_t>(g.n_theta);
  r.check_axis(r.dataset(group, "polar", "r", {nr}, "m"), linspace(g.r_min, g.r_max, g.n_r, true),
               "/polar/r", g.dr());
  r.check_axis(r.dataset(group, "polar", "theta", {nt}, "rad"),
               linspace(0.0, two_pi, g.n_theta, false), "/polar/theta", g.dtheta());
  g.A_z = r.dataset(group, "polar", "A_z", {nr, nt}, "T*m");
  validate(g, "file " + path);
  return out;
}

ElectricGridFile read_electric_grid(const std::string &path)
{
  QuietHdf5 quiet;
  Handle file = open_for_reading(path);
  const Reader r{path};
  ElectricGridFile out;
  out.info = read_info(r, file);
  require_kind(r, out.info, "electric");

  Handle group = r.open_group(file, "cartesian");
  CartesianGrid &g = out.grid.bias;
  g.x_min = r.scalar_attribute(group, "x_min");
  g.x_max = r.scalar_attribute(group, "x_max");
  g.y_min = r.scalar_attribute(group, "y_min");
  g.y_max = r.scalar_attribute(group, "y_max");
  g.n_x = r.int_attribute(group, "n_x");
  g.n_y = r.int_attribute(group, "n_y");
  if (g.n_x < 4 || g.n_y < 4)
    r.fail("Cartesian grid needs n_x ≥ 4 and n_y ≥ 4, found n_x = " + std::to_string(g.n_x) +
           ", n_y = " + std::to_string(g.n_y));
  if (!(g.x_max > g.x_min && g.y_max > g.y_min && std::isfinite(g.x_min) &&
        std::isfinite(g.x_max) && std::isfinite(g.y_min) && std::isfinite(g.y_max)))
    r.fail("Cartesian grid needs x_min < x_max and y_min < y_max");
  const auto nx = static_cast<hsize_t>(g.n_x), ny = static_cast<hsize_t>(g.n_y);
  r.check_axis(r.dataset(group, "cartesian", "x", {nx}, "m"),
               linspace(g.x_min, g.x_max, g.n_x, true), "/cartesian/x", g.dx());
  r.check_axis(r.dataset(group, "cartesian", "y", {ny}, "m"),
               linspace(g.y_min, g.y_max, g.n_y, true), "/cartesian/y", g.dy());
  g.phi = r.dataset(group, "cartesian", "phi_bias", {nx, ny}, "V");
  out.grid.image_period = r.scalar_attribute(group, "image_period");
  const std::vector<double> centre = r.double_attribute(group, "drum_center");
  if (centre.size() != 2)
    r.fail("attribute /cartesian/drum_center must hold 2 values, found " + std::to_string(centre.size()));
  out.grid.drum_center = {centre[0], centre[1]};
  out.grid.drum_radius = r.scalar_attribute(group, "drum_radius");
  const int K = r.int_attribute(group, "phase_samples");
  if (K < 1)
    r.fail("attribute /cartesian/phase_samples must be ≥ 1, found " + std::to_string(K));
  const std::vector<double> images =
    r.dataset(group, "cartesian", "phi_image", {static_cast<hsize_t>(K), nx, ny}, "V");
  const size_t n = g.phi.size();
  for (int k = 0; k < K; ++k)
    out.grid.image.emplace_back(images.begin() + static_cast<std::ptrdiff_t>(k * n),
                                images.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
  validate(out.grid, "file " + path);
  return out;
}

// ---------------------------------------------------------------------------------------
// Provenance

namespace {

struct Difference
{
  std::string key;     // empty: none
  std::string message;
};

// The first canonical input that differs, in the case's order (then inputs only the file has).
Difference first_difference(const GridFileInfo &file,
                            const std::vector<std::pair<std::string, std::string>> &expected)
{
  const auto find = [](const std::vector<std::pair<std::string, std::string>> &list,
                       const std::string &key) -> const std::string * {
    for (const auto &[k, v] : list)
      if (k == key)
        return &v;
    return nullptr;
  };
  const auto &stored = file.provenance.case_inputs;
  const std::string what = "field file " + file.path + " (" + file.kind + ")";
  const std::string remedy = "; regenerate it with `magbrush field CASE`";
  for (const auto &[key, value] : expected)
  {
    const std::string *in_file = find(stored, key);
    if (!in_file)
      return {key, what + " does not record input '" + key + "' (the case has " + key + " = " +
                       value + "): it was computed from other inputs" + remedy};
    if (*in_file != value)
      return {key, what + " was computed for " + key + " = " + *in_file + " but the case has " +
                       key + " = " + value + remedy};
  }
  for (const auto &[key, value] : stored)
    if (!find(expected, key))
      return {key, what + " was computed with input " + key + " = " + value +
                       ", which the case does not have" + remedy};
  return {};
}

} // namespace

std::string provenance_difference(const GridFileInfo &file,
                                  const std::vector<std::pair<std::string, std::string>> &expected)
{
  return first_difference(file, expected).message;
}

void check_provenance(const GridFileInfo &file,
                      const std::vector<std::pair<std::string, std::string>> &expected)
{
  Difference d = first_difference(file, expected);
  if (!d.key.empty())
    throw ProvenanceMismatch(d.message, d.key);
}

} // namespace magbrush
