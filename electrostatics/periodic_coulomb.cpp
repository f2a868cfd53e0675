#include "electrostatics/periodic_coulomb.h"

#include "electrostatics/coulomb_constants.h"

#include <omp.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::electrostatics {

namespace {
constexpr long parallel_threshold = 512;

// Adds the kernel field q r/|r|³ and potential q/|r| at r = (target − source).
inline void add_coulomb(double rx, double ry, double rz, double q, double &ex, double &ey, double &ez, double &phi)
{
  const double r2 = rx * rx + ry * ry + rz * rz;
  const double ir = 1.0 / std::sqrt(r2);
  const double qir3 = q * ir * ir * ir;
  ex += qir3 * rx;
  ey += qir3 * ry;
  ez += qir3 * rz;
  phi += q * ir;
}

// One near row: the field and potential at target (tx, ty, tz) of the sources src[k] shifted by
// shift[3k..3k+2], summed in a fixed order (so the bits do not depend on the thread count).
// With SSE2 (every x86-64) the row is taken two entries at a time, even and odd entries in the
// two lanes of one register, and the lanes added at the end, then the odd one out: the square
// root and the division — most of a pair's cost — go two to an instruction. Without SSE2 the
// same order in scalar code, so the two builds give the same bits.
struct RowSum
{
  double ex = 0.0, ey = 0.0, ez = 0.0, phi = 0.0;
};

inline RowSum near_row_sum(double tx, double ty, double tz, const std::uint32_t *src, const double *shift,
                           std::uint32_t count, const double *sx, const double *sy, const double *sz,
                           const double *sq)
{
  RowSum out;
  std::uint32_t k = 0;
#if defined(__SSE2__)
  __m128d ex = _mm_setzero_pd(), ey = _mm_setzero_pd(), ez = _mm_setzero_pd(), ph = _mm_setzero_pd();
  const __m128d one = _mm_set1_pd(1.0), t_x = _mm_set1_pd(tx), t_y = _mm_set1_pd(ty), t_z = _mm_set1_pd(tz);
  for (; k + 1 < count; k += 2)
  {
    const std::uint32_t a = src[k], b = src[k + 1];
    const double *ha = shift + 3 * k, *hb = shift + 3 * k + 3;
    // (_mm_set_pd takes the high lane first: entry k in the low lane.)
    const __m128d rx = _mm_sub_pd(_mm_sub_pd(t_x, _mm_set_pd(sx[b], sx[a])), _mm_set_pd(hb[0], ha[0]));
    const __m128d ry = _mm_sub_pd(_mm_sub_pd(t_y, _mm_set_pd(sy[b], sy[a])), _mm_set_pd(hb[1], ha[1]));
    const __m128d rz = _mm_sub_pd(_mm_sub_pd(t_z, _mm_set_pd(sz[b], sz[a])), _mm_set_pd(hb[2], ha[2]));
    const __m128d q = _mm_set_pd(sq[b], sq[a]);
    const __m128d r2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(rx, rx), _mm_mul_pd(ry, ry)), _mm_mul_pd(rz, rz));
    const __m128d ir = _mm_div_pd(one, _mm_sqrt_pd(r2));
    const __m128d qir3 = _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(q, ir), ir), ir);
    ex = _mm_add_pd(ex, _mm_mul_pd(qir3, rx));
    ey = _mm_add_pd(ey, _mm_mul_pd(qir3, ry));
    ez = _mm_add_pd(ez, _mm_mul_pd(qir3, rz));
    ph = _mm_add_pd(ph, _mm_mul_pd(q, ir));
  }
  auto lanes = [](__m128d v) { return _mm_cvtsd_f64(v) + _mm_cvtsd_f64(_mm_unpackhi_pd(v, v)); };
  out = {lanes(ex), lanes(ey), lanes(ez), lanes(ph)};
#else
  RowSum even, odd;
  for (; k + 1 < count; k += 2)
  {
    const std::uint32_t a = src[k], b = src[k + 1];
    add_coulomb(tx - sx[a] - shift[3 * k], ty - sy[a] - shift[3 * k + 1], tz - sz[a] - shift[3 * k + 2], sq[a],
                even.ex, even.ey, even.ez, even.phi);
    add_coulomb(tx - sx[b] - shift[3 * k + 3], ty - sy[b] - shift[3 * k + 4], tz - sz[b] - shift[3 * k + 5], sq[b],
                odd.ex, odd.ey, odd.ez, odd.phi);
  }
  out = {even.ex + odd.ex, even.ey + odd.ey, even.ez + odd.ez, even.phi + odd.phi};
#endif
  if (k < count)
  {
    const std::uint32_t a = src[k];
    add_coulomb(tx - sx[a] - shift[3 * k], ty - sy[a] - shift[3 * k + 1], tz - sz[a] - shift[3 * k + 2], sq[a], out.ex,
                out.ey, out.ez, out.phi);
  }
  return out;
}
} // namespace

PeriodicCoulomb::PeriodicCoulomb(const CoulombSettings &settings, const std::array<double, 3> &box)
  : settings_(settings), box_(box)
{
  if (settings.order < 0 || settings.order > 8)
    throw std::invalid_argument("Coulomb: the far-field order must be within 0 … 8; found " +
                                std::to_string(settings.order) + ".");
  if (!(settings.cell_size > 0.0))
    throw std::invalid_argument("Coulomb: the far-field cell size must be positive; found " +
                                std::to_string(settings.cell_size) + " m.");
  if (box[0] > 0.0 && box[1] > 0.0 && box[2] > 0.0)
    throw std::invalid_argument("Coulomb: a box periodic along x, y and z is not supported (its charge sums need "
                                "Ewald summation with a stated boundary condition); leave one axis open, or set "
                                "electric.coulomb: false.");
  far_ = std::make_unique<magnetics::CellMultipoleField>(settings.order, box, settings.near_reach,
                                                         magnetics::SourceKind::charges);
  far_->set_single_precision(settings.single_precision);
}

void PeriodicCoulomb::set_image_surface(const GroundedSurface &surface, int terms)
{
  surface_ = surface;
  image_terms_ = terms;
  images_per_charge_ = surface.layer.pair_image_count(terms);
}

void PeriodicCoulomb::place_sources(const double *x, const double *y, const double *z, const double *q,
                                    const double *floor)
{
  const std::size_t n = n_;
  for (std::size_t i = 0; i < n; ++i)
  {
    sx_[i] = x[i];
    sy_[i] = y[i];
    sz_[i] = z[i];
    sq_[i] = q[i];
  }
  if (images_per_charge_ == 0)
    return;
  for (std::size_t i = 0; i < n; ++i)
    place_images_of(i, x, y, z, q, floor);
}

// The pair images of charge i below the tangent plane at its foot point on the surface.
void PeriodicCoulomb::place_images_of(std::size_t i, const double *x, const double *y, const double *z,
                                      const double *q, const double *floor)
{
  const std::size_t n = n_, m = static_cast<std::size_t>(images_per_charge_);
  double normal[3];
  double h = surface_.height(x[i], y[i], z[i], normal);
  if (floor)
    h = std::max(h, floor[i]);
  h = std::max(h, 0.0);
  const double foot[3] = {x[i] - h * normal[0], y[i] - h * normal[1], z[i] - h * normal[2]};
  surface_.layer.pair_images(h, image_terms_, image_charge_, image_depth_);
  for (std::size_t k = 0; k < m; ++k)
  {
    const std::size_t s = n + i * m + k;
    sx_[s] = foot[0] - image_depth_[k] * normal[0];
    sy_[s] = foot[1] - image_depth_[k] * normal[1];
    sz_[s] = foot[2] - image_depth_[k] * normal[2];
    sq_[s] = q[i] * image_charge_[k];
  }
}

void PeriodicCoulomb::build_rows(std::vector<char> &own_image_near)
{
  // Each real target's row lists the sources of its near pairs with the shift that puts the
  // source's image next to it, in the order of the pair list (fixed): a charge's own images
  // at zero shift are left out (the self force is the conductor-image term's).
  const std::size_t n = n_, m = static_cast<std::size_t>(images_per_charge_);
  const auto &pairs = far_->near_pairs();
  auto owner = [&](std::uint32_t s) { return s < n ? s : static_cast<std::uint32_t>((s - n) / m); };
  auto own_image = [&](std::uint32_t target, std::uint32_t source, const double *shift) {
    return source >= n && owner(source) == target && shift[0] == 0.0 && shift[1] == 0.0 && shift[2] == 0.0;
  };
  own_image_near.assign(n * m, 0);
  row_begin_.assign(n + 1, 0);
  for (const auto &p : pairs)
  {
    const double minus[3] = {-p.shift[0], -p.shift[1], -p.shift[2]};
    if (p.i < n && !own_image(p.i, p.j, p.shift))
      ++row_begin_[p.i + 1];
    if (p.j < n && !own_image(p.j, p.i, minus))
      ++row_begin_[p.j + 1];
  }
  for (std::size_t i = 0; i < n; ++i)
    row_begin_[i + 1] += row_begin_[i];
  row_source_.resize(row_begin_[n]);
  row_shift_.resize(3 * row_begin_[n]);
  std::vector<std::uint32_t> &fill = row_fill_;
  fill.assign(row_begin_.begin(), row_begin_.end() - 1);
  auto put = [&](std::uint32_t target, std::uint32_t source, const double *shift) {
    if (own_image(target, source, shift))
    {
      own_image_near[source - n] = 1;
      return;
    }
    const std::uint32_t k = fill[target]++;
    row_source_[k] = source;
    for (int d = 0; d < 3; ++d)
      row_shift_[3 * k + d] = shift[d];
  };
  for (const auto &p : pairs)
  {
    const double minus[3] = {-p.shift[0], -p.shift[1], -p.shift[2]};
    if (p.i < n)
      put(p.i, p.j, p.shift);
    if (p.j < n)
      put(p.j, p.i, minus);
  }
}

void PeriodicCoulomb::remove_own_far_images(const std::vector<char> &own_image_near)
{
  // The far field contains a charge's own images (zero shift) that are not near pairs:
  // subtract their exact field (the expansion's error on them stays, as for any far pair).
  const std::size_t n = n_, m = static_cast<std::size_t>(images_per_charge_);
  if (m == 0)
    return;
#pragma omp parallel for schedule(static) if (static_cast<long>(n) >= parallel_threshold)
  for (long il = 0; il < static_cast<long>(n); ++il)
  {
    const std::size_t i = static_cast<std::size_t>(il);
    double ex = 0.0, ey = 0.0, ez = 0.0, phi = 0.0;
    for (std::size_t k = 0; k < m; ++k)
    {
      const std::size_t s = n + i * m + k;
      if (own_image_near[i * m + k])
        continue;
      add_coulomb(sx_[i] - sx_[s], sy_[i] - sy_[s], sz_[i] - sz_[s], sq_[s], ex, ey, ez, phi);
    }
    far_E_[3 * i] -= coulomb_constant * ex;
    far_E_[3 * i + 1] -= coulomb_constant * ey;
    far_E_[3 * i + 2] -= coulomb_constant * ez;
    far_phi_[i] -= coulomb_constant * phi;
  }
}

void PeriodicCoulomb::rebuild(std::size_t n, const double *x, const double *y, const double *z, const double *q,
                              const double *floor)
{
  n_ = n;
  const std::size_t total = n * (1 + static_cast<std::size_t>(images_per_charge_));
  for (auto *v : {&sx_, &sy_, &sz_, &sq_})
    v->resize(total);
  place_sources(x, y, z, q, floor);
  const double t0 = omp_get_wtime();
  far_->set_near_targets(n);
  far_->build(total, sx_.data(), sy_.data(), sz_.data(), settings_.cell_size);
  const double t1 = omp_get_wtime();
  build_rows(own_image_near_);
  columns_built_ = false;
  const double t2 = omp_get_wtime();
  scratch_E_.resize(3 * total);
  scratch_phi_.resize(total);
  far_->evaluate(magnetics::FarFieldSources{sq_.data(), nullptr},
                 magnetics::FarFieldTargets{scratch_phi_.data(), scratch_E_.data(), nullptr});
  far_E_.resize(3 * n);
  far_phi_.resize(n);
  for (std::size_t i = 0; i < 3 * n; ++i)
    far_E_[i] = coulomb_constant * scratch_E_[i];
  for (std::size_t i = 0; i < n; ++i)
    far_phi_[i] = coulomb_constant * scratch_phi_[i];
  remove_own_far_images(own_image_near_);
  times_ = {t1 - t0, t2 - t1, omp_get_wtime() - t2};
}

void PeriodicCoulomb::field(const double *x, const double *y, const double *z, const double *q, const double *floor,
                            double *E, double *phi)
{
  place_sources(x, y, z, q, floor);
  const long n = static_cast<long>(n_);
#pragma omp parallel for schedule(static) if (n >= parallel_threshold)
  for (long i = 0; i < n; ++i)
  {
    const std::uint32_t first = row_begin_[i];
    const RowSum near = near_row_sum(sx_[i], sy_[i], sz_[i], row_source_.data() + first, row_shift_.data() + 3 * first,
                                     row_begin_[i + 1] - first, sx_.data(), sy_.data(), sz_.data(), sq_.data());
    E[3 * i] = far_E_[3 * i] + coulomb_constant * near.ex;
    E[3 * i + 1] = far_E_[3 * i + 1] + coulomb_constant * near.ey;
    E[3 * i + 2] = far_E_[3 * i + 2] + coulomb_constant * near.ez;
    if (phi)
      phi[i] = far_phi_[i] + coulomb_constant * near.phi;
  }
}

void PeriodicCoulomb::build_columns()
{
  // A counting sort of the row entries by source: the entries of each source in row order.
  const std::size_t sources = sx_.size(), entries = row_source_.size();
  column_begin_.assign(sources + 1, 0);
  for (const std::uint32_t s : row_source_)
    ++column_begin_[s + 1];
  for (std::size_t s = 0; s < sources; ++s)
    column_begin_[s + 1] += column_begin_[s];
  column_entry_.resize(entries);
  entry_target_.resize(entries);
  row_fill_.assign(column_begin_.begin(), column_begin_.end() - 1);
  for (std::size_t i = 0; i < n_; ++i)
    for (std::uint32_t e = row_begin_[i]; e < row_begin_[i + 1]; ++e)
    {
      column_entry_[row_fill_[row_source_[e]]++] = e;
      entry_target_[e] = static_cast<std::uint32_t>(i);
    }
  moving_.assign(n_, 0);
  columns_built_ = true;
}

void PeriodicCoulomb::renew(const std::vector<std::uint32_t> &moved, const double *x, const double *y, const double *z,
                            const double *q, const double *floor, std::vector<std::uint32_t> &touched,
                            std::vector<double> &dE, std::vector<double> &E_moved)
{
  if (!columns_built_)
    build_columns();
  const std::size_t n = n_, m = static_cast<std::size_t>(images_per_charge_);
  touched.clear();
  dE.resize(3 * n);
  for (const std::uint32_t k : moved)
    moving_[k] = 1;
  // Each entry of a moved source in another charge's row: its field from the source where it
  // was, then where it is now. (A target that moves too gets its whole row afresh below.)
  auto entries_of = [&](std::size_t s, double sign) {
    for (std::uint32_t c = column_begin_[s]; c < column_begin_[s + 1]; ++c)
    {
      const std::uint32_t e = column_entry_[c], i = entry_target_[e];
      if (moving_[i])
        continue;
      double ex = 0.0, ey = 0.0, ez = 0.0, phi = 0.0;
      add_coulomb(sx_[i] - sx_[s] - row_shift_[3 * e], sy_[i] - sy_[s] - row_shift_[3 * e + 1],
                  sz_[i] - sz_[s] - row_shift_[3 * e + 2], sq_[s], ex, ey, ez, phi);
      if (sign > 0.0)
        touched.push_back(i);
      dE[3 * i] += sign * coulomb_constant * ex;
      dE[3 * i + 1] += sign * coulomb_constant * ey;
      dE[3 * i + 2] += sign * coulomb_constant * ez;
    }
  };
  for (const std::uint32_t k : moved)
  {
    entries_of(k, -1.0);
    for (std::size_t j = 0; j < m; ++j)
      entries_of(n + k * m + j, -1.0);
    sx_[k] = x[k];
    sy_[k] = y[k];
    sz_[k] = z[k];
    sq_[k] = q[k];
    if (m > 0)
      place_images_of(k, x, y, z, q, floor);
    entries_of(k, 1.0);
    for (std::size_t j = 0; j < m; ++j)
      entries_of(n + k * m + j, 1.0);
  }
  E_moved.resize(3 * moved.size());
  for (std::size_t a = 0; a < moved.size(); ++a)
  {
    const std::uint32_t k = moved[a], first = row_begin_[k];
    const RowSum near = near_row_sum(sx_[k], sy_[k], sz_[k], row_source_.data() + first, row_shift_.data() + 3 * first,
                                     row_begin_[k + 1] - first, sx_.data(), sy_.data(), sz_.data(), sq_.data());
    E_moved[3 * a] = far_E_[3 * k] + coulomb_constant * near.ex;
    E_moved[3 * a + 1] = far_E_[3 * k + 1] + coulomb_constant * near.ey;
    E_moved[3 * a + 2] = far_E_[3 * k + 2] + coulomb_constant * near.ez;
  }
  for (const std::uint32_t k : moved)
    moving_[k] = 0;
}

} // namespace magbrush::electrostatics
