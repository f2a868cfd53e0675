// Cell-list Verlet neighbour list with spatial sorting and id-keyed history (neighbour_list.h).
#include "dem/neighbour_list.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::dem {

void PeriodicBox::wrap(ParticleState &s) const
{
  std::vector<double> *coords[3] = {&s.x, &s.y, &s.z};
  for (int d = 0; d < 3; ++d)
  {
    if (!periodic(d))
      continue;
    const double L = length[static_cast<std::size_t>(d)];
    for (double &v : *coords[d])
    {
      v -= L * std::floor(v / L);
      if (v >= L) // rounding of a tiny negative v
        v -= L;
    }
  }
}

// The touching pairs' ξ, CSR by the owner's index at the last build (the list's own arrays
// still describe that build, whatever happened to the particle arrays since).
void NeighbourList::stash_history()
{
  const std::size_t n = row_start.empty() ? 0 : row_start.size() - 1;
  old_start_.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::int32_t p = row_start[i]; p < row_start[i + 1]; ++p)
      old_start_[i + 1] += touching[static_cast<std::size_t>(p)];
  for (std::size_t k = 0; k < n; ++k)
    old_start_[k + 1] += old_start_[k];
  const std::size_t m = static_cast<std::size_t>(old_start_[n]);
  old_partner_.resize(m);
  old_hx_.resize(m);
  old_hy_.resize(m);
  old_hz_.resize(m);
  std::size_t slot = 0; // rows in order: the pairs of row i fill [old_start_[i], old_start_[i+1])
  for (std::size_t i = 0; i < n; ++i)
    for (std::int32_t p = row_start[i]; p < row_start[i + 1]; ++p)
    {
      const std::size_t q = static_cast<std::size_t>(p);
      if (!touching[q])
        continue;
      old_partner_[slot] = partner[q];
      old_hx_[slot] = hist_x[q];
      old_hy_[slot] = hist_y[q];
      old_hz_[slot] = hist_z[q];
      ++slot;
    }
}

void NeighbourList::compute_cell_order(const ParticleState &s, const PeriodicBox &box, double skin)
{
  const std::size_t n = s.size();
  double r_max = 0.0;
  for (double r : s.radius)
    r_max = std::max(r_max, r);
  const double cut = 2.0 * r_max + skin;
  const std::vector<double> *coords[3] = {&s.x, &s.y, &s.z};
  std::array<double, 3> lo{}, extent{};
  for (int d = 0; d < 3; ++d)
  {
    const std::size_t du = static_cast<std::size_t>(d);
    if (box.periodic(d))
    {
      if (box.length[du] < 2.0 * cut)
        throw std::invalid_argument(
            "periodic length along " + std::string(1, "xyz"[d]) + " (" + std::to_string(box.length[du]) +
            " m) is shorter than twice the interaction range 2 (d_max + skin) = " + std::to_string(2.0 * cut) +
            " m: enlarge the periodic slab or reduce the Verlet skin");
      lo[du] = 0.0;
      extent[du] = box.length[du];
    }
    else if (n > 0)
    {
      const auto [mn, mx] = std::minmax_element(coords[d]->begin(), coords[d]->end());
      lo[du] = *mn;
      extent[du] = *mx - *mn;
    }
  }
  // Cells at least `cut` wide, but never many more cells than particles (a sparse cloud).
  double size = cut;
  const double max_cells = std::max<double>(27.0, 2.0 * static_cast<double>(n));
  for (;;)
  {
    double total = 1.0;
    for (int d = 0; d < 3; ++d)
    {
      const std::size_t du = static_cast<std::size_t>(d);
      n_[du] = std::max(1, static_cast<int>(std::floor(extent[du] / size)));
      total *= n_[du];
    }
    if (total <= max_cells)
      break;
    size *= 1.26;
  }
  cell_size_ = size;
  for (int d = 0; d < 3; ++d)
  {
    const std::size_t du = static_cast<std::size_t>(d);
    origin_[du] = lo[du];
    h_[du] = box.periodic(d) ? extent[du] / n_[du] : std::max(extent[du] / n_[du], size);
  }
  const std::size_t n_cells = static_cast<std::size_t>(n_[0]) * n_[1] * n_[2];
  cell_of_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    int c[3];
    for (int d = 0; d < 3; ++d)
    {
      const std::size_t du = static_cast<std::size_t>(d);
      const int k = static_cast<int>(std::floor(((*coords[d])[i] - origin_[du]) / h_[du]));
      c[d] = std::clamp(k, 0, n_[du] - 1);
    }
    cell_of_[i] = c[0] + n_[0] * (c[1] + n_[1] * c[2]);
  }
  // Stable counting sort: particles in ascending cell order, ties in current order.
  cell_start_.assign(n_cells + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    ++cell_start_[static_cast<std::size_t>(cell_of_[i]) + 1];
  for (std::size_t c = 0; c < n_cells; ++c)
    cell_start_[c + 1] += cell_start_[c];
  counts_.assign(n_cells, 0);
  order_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t c = static_cast<std::size_t>(cell_of_[i]);
    order_[static_cast<std::size_t>(cell_start_[c] + counts_[c]++)] = static_cast<std::int32_t>(i);
  }
  // After the permutation particle k sits in the cell whose range contains k.
  for (std::size_t c = 0; c < n_cells; ++c)
    for (std::int32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k)
      cell_of_[static_cast<std::size_t>(k)] = static_cast<std::int32_t>(c);
  for (int code = 0; code < 27; ++code)
  {
    const int s[3] = {code % 3 - 1, (code / 3) % 3 - 1, code / 9 - 1};
    shifts_[static_cast<std::size_t>(code)] = {s[0] * box.length[0], s[1] * box.length[1], s[2] * box.length[2]};
    for (int d = 0; d < 3; ++d)
      shift_components_[static_cast<std::size_t>(d)][static_cast<std::size_t>(code)] =
        s[d] * box.length[static_cast<std::size_t>(d)];
  }
}

void NeighbourList::build_pairs(const ParticleState &s, const PeriodicBox &box, double skin)
{
  const std::size_t n = s.size();
  const std::int32_t N = static_cast<std::int32_t>(n);
  // The distinct neighbouring cell indices along one direction.
  auto neighbours = [&](int d, int c, int out[3]) {
    const int m = n_[static_cast<std::size_t>(d)];
    int k = 0;
    if (box.periodic(d))
    {
      if (m >= 3)
      {
        out[k++] = (c + m - 1) % m;
        out[k++] = c;
        out[k++] = (c + 1) % m;
      }
      else
        for (int q = 0; q < m; ++q)
          out[k++] = q;
    }
    else
      for (int q = c - 1; q <= c + 1; ++q)
        if (q >= 0 && q < m)
          out[k++] = q;
    return k;
  };
  const double half[3] = {0.5 * box.length[0], 0.5 * box.length[1], 0.5 * box.length[2]};
  const bool per[3] = {box.periodic(0), box.periodic(1), box.periodic(2)};
  // Visits the listed partners j > i of particle i: f(j, image code).
  auto for_each_partner = [&](std::int32_t i, auto &&f) {
    const std::size_t iu = static_cast<std::size_t>(i);
    const int c = cell_of_[iu];
    const int cx = c % n_[0], cy = (c / n_[0]) % n_[1], cz = c / (n_[0] * n_[1]);
    int ox[3], oy[3], oz[3];
    const int nx = neighbours(0, cx, ox), ny = neighbours(1, cy, oy), nz = neighbours(2, cz, oz);
    const double xi = s.x[iu], yi = s.y[iu], zi = s.z[iu], ri = s.radius[iu];
    for (int a = 0; a < nz; ++a)
      for (int b = 0; b < ny; ++b)
        for (int e = 0; e < nx; ++e)
        {
          const std::size_t cell = static_cast<std::size_t>(ox[e] + n_[0] * (oy[b] + n_[1] * oz[a]));
          for (std::int32_t j = std::max(cell_start_[cell], i + 1); j < cell_start_[cell + 1]; ++j)
          {
            const std::size_t ju = static_cast<std::size_t>(j);
            double d[3] = {s.x[ju] - xi, s.y[ju] - yi, s.z[ju] - zi};
            int sh[3] = {0, 0, 0};
            for (int q = 0; q < 3; ++q)
              if (per[q])
              {
                if (d[q] > half[q])
                  sh[q] = -1;
                else if (d[q] < -half[q])
                  sh[q] = 1;
                d[q] += sh[q] * box.length[static_cast<std::size_t>(q)];
              }
            const double reach = ri + s.radius[ju] + skin;
            if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < reach * reach)
              f(j, static_cast<std::int32_t>((sh[0] + 1) + 3 * (sh[1] + 1) + 9 * (sh[2] + 1)));
          }
        }
  };
  row_start.assign(n + 1, 0);
#pragma omp parallel for schedule(dynamic, 256) if (N > 512)
  for (std::int32_t i = 0; i < N; ++i)
  {
    std::int32_t count = 0;
    for_each_partner(i, [&](std::int32_t, std::int32_t) { ++count; });
    row_start[static_cast<std::size_t>(i) + 1] = count;
  }
  for (std::size_t i = 0; i < n; ++i)
    row_start[i + 1] += row_start[i];
  const std::size_t P = static_cast<std::size_t>(row_start[n]);
  owner.resize(P);
  partner.resize(P);
  image.resize(P);
  touching.assign(P, 0);
  for (auto *a : {&hist_x, &hist_y, &hist_z, &force_x, &force_y, &force_z, &torque_j_x, &torque_j_y, &torque_j_z})
    a->resize(P);
#pragma omp parallel for schedule(dynamic, 256) if (N > 512)
  for (std::int32_t i = 0; i < N; ++i)
  {
    std::size_t p = static_cast<std::size_t>(row_start[static_cast<std::size_t>(i)]);
    for_each_partner(i, [&](std::int32_t j, std::int32_t code) {
      owner[p] = i;
      partner[p] = j;
      image[p] = code;
      ++p;
    });
  }
  // Transposed index, ascending pair order within each column.
  col_start.assign(n + 1, 0);
  for (std::size_t p = 0; p < P; ++p)
    ++col_start[static_cast<std::size_t>(partner[p]) + 1];
  for (std::size_t i = 0; i < n; ++i)
    col_start[i + 1] += col_start[i];
  col_pair.resize(P);
  counts_.assign(n, 0);
  for (std::size_t p = 0; p < P; ++p)
  {
    const std::size_t j = static_cast<std::size_t>(partner[p]);
    col_pair[static_cast<std::size_t>(col_start[j] + counts_[j]++)] = static_cast<std::int32_t>(p);
  }
}

void NeighbourList::restore_history(const std::vector<std::int32_t> *origin)
{
  const std::int32_t N = static_cast<std::int32_t>(order_.size());
  const std::int32_t old_n = static_cast<std::int32_t>(old_start_.size()) - 1;
  // Index at the last build of each particle in the new order (−1: entered since).
  old_index_.resize(order_.size());
  for (std::size_t k = 0; k < order_.size(); ++k)
  {
    const std::int32_t o = origin ? (*origin)[static_cast<std::size_t>(order_[k])] : order_[k];
    old_index_[k] = o < old_n ? o : -1; // (first build: nothing to find)
  }
#pragma omp parallel for schedule(static) if (N > 512)
  for (std::int32_t i = 0; i < N; ++i)
  {
    const std::size_t iu = static_cast<std::size_t>(i);
    const std::int32_t a = old_index_[iu];
    for (std::int32_t p = row_start[iu]; p < row_start[iu + 1]; ++p)
    {
      const std::size_t q = static_cast<std::size_t>(p);
      double hx = 0.0, hy = 0.0, hz = 0.0;
      std::int32_t found = 0;
      const std::int32_t b = old_index_[static_cast<std::size_t>(partner[q])];
      if (a >= 0 && b >= 0)
      {
        // Same orientation (a, b): ξ as stored; reversed (b, a): ξ_ab = −ξ_ba.
        for (std::int32_t k = old_start_[static_cast<std::size_t>(a)]; k < old_start_[static_cast<std::size_t>(a) + 1] && !found; ++k)
          if (old_partner_[static_cast<std::size_t>(k)] == b)
          {
            hx = old_hx_[static_cast<std::size_t>(k)];
            hy = old_hy_[static_cast<std::size_t>(k)];
            hz = old_hz_[static_cast<std::size_t>(k)];
            found = 1;
          }
        for (std::int32_t k = old_start_[static_cast<std::size_t>(b)]; k < old_start_[static_cast<std::size_t>(b) + 1] && !found; ++k)
          if (old_partner_[static_cast<std::size_t>(k)] == a)
          {
            hx = -old_hx_[static_cast<std::size_t>(k)];
            hy = -old_hy_[static_cast<std::size_t>(k)];
            hz = -old_hz_[static_cast<std::size_t>(k)];
            found = 1;
          }
      }
      hist_x[q] = hx;
      hist_y[q] = hy;
      hist_z[q] = hz;
      touching[q] = found;
    }
  }
}

std::size_t NeighbourList::memory_bytes() const
{
  std::size_t b = 0;
  for (const auto *a : {&row_start, &owner, &partner, &image, &touching, &col_start, &col_pair, &cell_of_, &cell_start_, &order_,
                        &counts_, &old_start_, &old_partner_, &old_index_})
    b += a->capacity() * sizeof(std::int32_t);
  for (const auto *a : {&hist_x, &hist_y, &hist_z, &force_x, &force_y, &force_z, &torque_j_x, &torque_j_y, &torque_j_z, &old_hx_, &old_hy_, &old_hz_})
    b += a->capacity() * sizeof(double);
  return b;
}

void NeighbourList::write_history(CheckpointWriter &out) const
{
  for (const auto *a : {&row_start, &partner, &touching})
    out.put_array(*a);
  for (const auto *a : {&hist_x, &hist_y, &hist_z})
    out.put_array(*a);
}

void NeighbourList::read_history(CheckpointReader &in)
{
  for (auto *a : {&row_start, &partner, &touching})
    in.get_array(*a);
  for (auto *a : {&hist_x, &hist_y, &hist_z})
    in.get_array(*a);
}

} // namespace magbrush::dem
