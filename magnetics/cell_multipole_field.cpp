#include "magnetics/cell_multipole_field.h"

#include "magnetics/dipole_physics.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace magbrush::magnetics {

namespace {
constexpr std::size_t parallel_threshold = 256; // cells or beads
constexpr long one_axis_images = 40;            // ±explicit images, 1 periodic axis (+ integral tail)
constexpr long two_axis_image_radius = 64;      // disc radius in periods, 2 periodic axes

long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a - 1) / b) - 1; }

bool adjacent(const std::array<long, 3> &d, long reach = 1)
{
  return std::abs(d[0]) <= reach && std::abs(d[1]) <= reach && std::abs(d[2]) <= reach;
}
} // namespace

CellMultipoleField::CellMultipoleField(int order, const std::array<double, 3> &box, int near_reach,
                                       SourceKind kind)
  : taylor_(order, kind), box_(box), near_reach_(near_reach)
{
  if (near_reach < 1 || near_reach > 2)
    throw std::invalid_argument("cell multipole: the near field reaches 1 or 2 fine cells; found " +
                                std::to_string(near_reach) + ".");
  for (double L : box_)
  {
    if (L < 0.0)
      throw std::invalid_argument("cell multipole: periodic lengths must be ≥ 0 (0 = open).");
    periodic_axes_ += L > 0.0;
  }
  if (periodic_axes_ == 3)
    throw std::invalid_argument(
      "cell multipole: a box periodic along all three axes has a shape-dependent dipole sum "
      "(it needs Ewald summation with a stated boundary condition), which is not implemented; "
      "found three periodic axes. Leave one axis open or use magnetic_far_field: none.");
}

std::uint64_t CellMultipoleField::key_of(const std::array<long, 3> &I) const
{
  return (static_cast<std::uint64_t>(I[0]) << 42) | (static_cast<std::uint64_t>(I[1]) << 21) |
         static_cast<std::uint64_t>(I[2]);
}

long CellMultipoleField::find(const Level &level, const std::array<long, 3> &I) const
{
  const std::uint64_t key = key_of(I);
  const auto it = std::lower_bound(level.keys.begin(), level.keys.end(), key);
  return (it != level.keys.end() && *it == key) ? it - level.keys.begin() : -1;
}

void CellMultipoleField::Level::reset()
{
  size = {0.0, 0.0, 0.0};
  cells = {0, 0, 0};
  factor = {1, 1, 1};
  scale = 1.0;
  for (auto *v : {&parent, &child_begin, &children, &list_begin, &list_source})
    v->clear();
  keys.clear();
  index.clear();
  list_matrix.clear();
  list_matrix_f.clear();
  Mf.clear();
  row_scale.clear();
  M.clear();
  L.clear();
}

CellMultipoleField::Level CellMultipoleField::take_spare_level()
{
  if (spare_levels_.empty())
    return Level{};
  Level l = std::move(spare_levels_.back());
  spare_levels_.pop_back();
  return l;
}

void CellMultipoleField::build_dense_index(const Level &fine)
{
  // The near pairs look up 5³ cells around every bead (twice: count, then fill); a binary
  // search over the occupied cells per lookup was ~40 % of a rebuild in a wide strip. Fine
  // cell indices are ≥ 0: a dense array over their bounding box, when it is small.
  dense_.clear();
  std::array<long, 3> extent{1, 1, 1};
  for (const auto &I : fine.index)
    for (int d = 0; d < 3; ++d)
      extent[d] = std::max(extent[d], I[d] + 1);
  for (int d = 0; d < 3; ++d)
    if (box_[d] > 0.0)
      extent[d] = std::max(extent[d], fine.cells[d]);
  const double size = static_cast<double>(extent[0]) * extent[1] * extent[2];
  if (size > 16e6)
    return; // (sparse beads over a huge box: keep the binary search)
  dense_extent_ = extent;
  dense_.assign(static_cast<std::size_t>(size), -1);
  for (std::size_t c = 0; c < fine.index.size(); ++c)
  {
    const auto &I = fine.index[c];
    dense_[static_cast<std::size_t>((I[2] * extent[1] + I[1]) * extent[0] + I[0])] = static_cast<std::int32_t>(c);
  }
}

long CellMultipoleField::find_fine(const std::array<long, 3> &I) const
{
  if (dense_.empty())
    return find(levels_[0], I);
  for (int d = 0; d < 3; ++d)
    if (I[d] < 0 || I[d] >= dense_extent_[d])
      return -1;
  return dense_[static_cast<std::size_t>((I[2] * dense_extent_[1] + I[1]) * dense_extent_[0] + I[0])];
}

bool CellMultipoleField::wrap(const Level &level, std::array<long, 3> &I) const
{
  for (int d = 0; d < 3; ++d)
  {
    if (box_[d] > 0.0)
      I[d] -= floor_div(I[d], level.cells[d]) * level.cells[d];
    else if (I[d] < 0 || I[d] >= (1L << 21))
      return false;
  }
  return true;
}

std::array<double, 3> CellMultipoleField::centre(int level, const std::array<long, 3> &I) const
{
  const Level &l = levels_[level];
  return {origin_[0] + (I[0] + 0.5) * l.size[0], origin_[1] + (I[1] + 0.5) * l.size[1],
          origin_[2] + (I[2] + 0.5) * l.size[2]};
}

void CellMultipoleField::build(std::size_t n, const double *x, const double *y, const double *z,
                               double cell_size)
{
  if (!(cell_size > 0.0))
    throw std::invalid_argument("cell multipole: expected a positive cell size, found " +
                                std::to_string(cell_size) + " m.");
  n_ = n;
  const double *coord[3] = {x, y, z};

  // Fine cells: k·2^m cells along every periodic axis (k = 1 or 3, the same for all periodic
  // axes, so that they all reach k cells at the same top level m; cell sizes within ±22 % of
  // the target), cubic-ish cells along the open axes.
  int m = 0;
  long k = 1;
  if (periodic_axes_ > 0)
  {
    double shortest = std::numeric_limits<double>::infinity();
    for (double L : box_)
      if (L > 0.0)
        shortest = std::min(shortest, L);
    const double want = std::log(std::max(1.0, shortest / cell_size));
    double best = std::numeric_limits<double>::infinity();
    for (long kk : {1L, 3L})
      for (int mm = 0; mm <= 20; ++mm)
      {
        const double miss = std::abs(std::log(static_cast<double>(kk << mm)) - want);
        if (miss < best)
        {
          best = miss;
          k = kk;
          m = mm;
        }
      }
  }
  double periodic_h = 0.0;
  for (int d = 0; d < 3; ++d)
    if (box_[d] > 0.0)
      periodic_h += box_[d] / static_cast<double>(k << m) / periodic_axes_;
  for (int d = 0; d < 3; ++d)
    h_[d] = box_[d] > 0.0 ? box_[d] / static_cast<double>(k << m)
                          : (periodic_axes_ > 0 ? periodic_h : cell_size);

  xw_.resize(3 * n);
  for (int d = 0; d < 3; ++d)
  {
    if (box_[d] > 0.0)
    {
      origin_[d] = 0.0;
      for (std::size_t b = 0; b < n; ++b)
      {
        double w = coord[d][b] - box_[d] * std::floor(coord[d][b] / box_[d]);
        if (w >= box_[d])
          w -= box_[d];
        xw_[3 * b + d] = w;
      }
    }
    else
    {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (std::size_t b = 0; b < n; ++b)
      {
        lo = std::min(lo, coord[d][b]);
        hi = std::max(hi, coord[d][b]);
      }
      if ((hi - lo) / h_[d] >= static_cast<double>(1L << 20))
        throw std::invalid_argument("cell multipole: the beads span " + std::to_string(hi - lo) +
                                    " m along axis " + std::to_string(d) +
                                    ", more than 2^20 cells; expected a compact bead cloud.");
      origin_[d] = n ? lo : 0.0;
      for (std::size_t b = 0; b < n; ++b)
        xw_[3 * b + d] = coord[d][b];
    }
  }

  wrap_shift_.resize(3 * n);
  for (std::size_t b = 0; b < n; ++b)
    for (int d = 0; d < 3; ++d)
      wrap_shift_[3 * b + d] = xw_[3 * b + d] - coord[d][b];

  // Coarsest first, so that the finest level takes the finest level's storage back.
  while (!levels_.empty())
  {
    levels_.back().reset();
    spare_levels_.push_back(std::move(levels_.back()));
    levels_.pop_back();
  }
  levels_.push_back(take_spare_level());
  Level &fine = levels_[0];
  fine.size = h_;
  for (int d = 0; d < 3; ++d)
    fine.cells[d] = box_[d] > 0.0 ? (k << m) : 0;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> sorted(n);
  std::vector<std::array<long, 3>> bead_index(n);
  for (std::size_t b = 0; b < n; ++b)
  {
    std::array<long, 3> I;
    for (int d = 0; d < 3; ++d)
    {
      I[d] = static_cast<long>(std::floor((xw_[3 * b + d] - origin_[d]) / h_[d]));
      if (box_[d] > 0.0)
        I[d] = std::clamp(I[d], 0L, fine.cells[d] - 1);
      I[d] = std::max(I[d], 0L);
    }
    bead_index[b] = I;
    sorted[b] = {key_of(I), static_cast<std::uint32_t>(b)};
  }
  std::sort(sorted.begin(), sorted.end());
  bead_order_.resize(n);
  bead_begin_.clear();
  bead_cell_.resize(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    const std::uint32_t b = sorted[k].second;
    bead_order_[k] = b;
    if (k == 0 || sorted[k].first != sorted[k - 1].first)
    {
      bead_begin_.push_back(static_cast<std::uint32_t>(k));
      fine.keys.push_back(sorted[k].first);
      fine.index.push_back(bead_index[b]);
    }
    bead_cell_[b] = static_cast<std::uint32_t>(fine.keys.size() - 1);
  }
  bead_begin_.push_back(static_cast<std::uint32_t>(n));
  build_dense_index(fine);

  // Coarser levels until the top. Periodic axes halve down to k cells (level m), then
  // collapse by k into a single cell of one period ("columns", levels > m: a cell then holds
  // its whole periodic column and all its images); open axes halve until at most 4 cells
  // span them. Without periodic axes: plain halving until at most 4 cells span every axis.
  column_level_ = periodic_axes_ > 0 ? m + 1 : std::numeric_limits<int>::max();
  for (int level = 0;; ++level)
  {
    Level &l = levels_[level];
    std::array<long, 3> lo{LONG_MAX, LONG_MAX, LONG_MAX}, hi{LONG_MIN, LONG_MIN, LONG_MIN};
    for (const auto &I : l.index)
      for (int d = 0; d < 3; ++d)
      {
        lo[d] = std::min(lo[d], I[d]);
        hi[d] = std::max(hi[d], I[d]);
      }
    bool top = level >= column_level_ || periodic_axes_ == 0;
    for (int d = 0; d < 3; ++d)
    {
      if (box_[d] > 0.0)
        l.factor[d] = level < m ? 2 : (level == m ? k : 1);
      else
      {
        l.factor[d] = (!l.index.empty() && hi[d] > lo[d]) ? 2 : 1;
        if (!l.index.empty() && hi[d] - lo[d] >= 4)
          top = false;
      }
    }
    if (level < column_level_ && periodic_axes_ > 0)
      top = false;
    if (top || level >= 40)
    {
      l.factor = {1, 1, 1};
      break;
    }
    Level next = take_spare_level();
    for (int d = 0; d < 3; ++d)
    {
      next.size[d] = l.factor[d] * l.size[d];
      next.cells[d] = l.cells[d] / l.factor[d];
    }
    const std::array<long, 3> f = l.factor;
    auto parent_of = [&f](const std::array<long, 3> &I) {
      return std::array<long, 3>{I[0] / f[0], I[1] / f[1], I[2] / f[2]};
    };
    std::vector<std::uint64_t> parent_keys(l.keys.size());
    for (std::size_t c = 0; c < l.keys.size(); ++c)
      parent_keys[c] = key_of(parent_of(l.index[c]));
    next.keys = parent_keys;
    std::sort(next.keys.begin(), next.keys.end());
    next.keys.erase(std::unique(next.keys.begin(), next.keys.end()), next.keys.end());
    next.index.resize(next.keys.size());
    for (std::size_t c = 0; c < next.keys.size(); ++c)
    {
      const std::uint64_t k = next.keys[c];
      next.index[c] = {static_cast<long>(k >> 42), static_cast<long>((k >> 21) & 0x1FFFFF),
                       static_cast<long>(k & 0x1FFFFF)};
    }
    Level &child = levels_[level];
    child.parent.resize(child.keys.size());
    next.child_begin.assign(next.keys.size() + 1, 0);
    for (std::size_t c = 0; c < child.keys.size(); ++c)
    {
      child.parent[c] = static_cast<std::uint32_t>(
        std::lower_bound(next.keys.begin(), next.keys.end(), parent_keys[c]) - next.keys.begin());
      ++next.child_begin[child.parent[c] + 1];
    }
    for (std::size_t c = 0; c < next.keys.size(); ++c)
      next.child_begin[c + 1] += next.child_begin[c];
    next.children.resize(child.keys.size());
    std::vector<std::uint32_t> fill(next.child_begin.begin(), next.child_begin.end() - 1);
    for (std::size_t c = 0; c < child.keys.size(); ++c)
      next.children[fill[child.parent[c]]++] = static_cast<std::uint32_t>(c);
    levels_.push_back(std::move(next));
  }
  for (Level &l : levels_)
  {
    l.scale = std::cbrt(l.size[0] * l.size[1] * l.size[2]);
    l.row_scale.resize(taylor_.local_size());
    taylor_.row_scales(l.scale, l.row_scale.data());
    l.M.assign(l.keys.size() * taylor_.multipole_size(), 0.0);
    l.L.assign(l.keys.size() * taylor_.local_size(), 0.0);
  }

  // Translation tensors of the lower levels (depend on the cell size only).
  // The top level's size depends on the number of levels when nothing is periodic.
  if (h_ != cached_h_)
  {
    lattice_.clear();
    lattice_f_.clear();
  }
  bool tabulated = h_ == cached_h_;
  for (std::size_t level = 0; level + 1 < levels_.size(); ++level)
    tabulated = tabulated && level < offset_D_.size() && level < cached_sizes_.size() &&
                cached_sizes_[level] == levels_[level].size &&
                (static_cast<int>(level) + 1 >= column_level_ || !offset_D_[level].empty());
  cached_levels_ = levels_.size();
  if (!tabulated)
  {
    cached_h_ = h_;
    cached_sizes_.clear();
    for (const Level &l : levels_)
      cached_sizes_.push_back(l.size);
    offset_D_.assign(levels_.size(), {});
    offset_Df_.assign(levels_.size(), {});
    const std::size_t nd = taylor_.derivative_size();
    const std::size_t na = taylor_.local_size() * taylor_.multipole_size();
    std::vector<double> D(nd);
    for (std::size_t level = 0; level + 1 < levels_.size(); ++level)
    {
      std::vector<double> &A = offset_D_[level];
      if (static_cast<int>(level) + 1 >= column_level_)
        continue; // lattice-summed translations from level m up
      A.assign(343 * na, 0.0);
      for (int o = 0; o < 343; ++o)
      {
        const long dx = o % 7 - 3, dy = (o / 7) % 7 - 3, dz = o / 49 - 3;
        if (adjacent({dx, dy, dz}))
          continue;
        const double R[3] = {-dx * levels_[level].size[0], -dy * levels_[level].size[1],
                             -dz * levels_[level].size[2]};
        taylor_.derivatives(R, D.data());
        taylor_.translation_matrix(D.data(), &A[o * na]);
      }
      offset_Df_[level].resize(A.size());
      for (int o = 0; o < 343; ++o)
        taylor_.scaled_matrix(&A[o * na], levels_[level].scale, &offset_Df_[level][o * na]);
    }
  }
  build_interaction_lists();
  build_near_pairs(coord);
}

void CellMultipoleField::update_positions(const double *x, const double *y, const double *z)
{
  const double *coord[3] = {x, y, z};
  for (std::size_t b = 0; b < n_; ++b)
    for (int d = 0; d < 3; ++d)
      xw_[3 * b + d] = coord[d][b] + wrap_shift_[3 * b + d];
}

bool CellMultipoleField::fine_index(const double xw[3], std::array<long, 3> &I) const
{
  const Level &fine = levels_[0];
  for (int d = 0; d < 3; ++d)
  {
    if (box_[d] <= 0.0 && xw[d] < origin_[d])
      return false;
    I[d] = static_cast<long>(std::floor((xw[d] - origin_[d]) / h_[d]));
    if (box_[d] > 0.0)
      I[d] = std::clamp(I[d], 0L, fine.cells[d] - 1);
    I[d] = std::max(I[d], 0L);
  }
  return true;
}

bool CellMultipoleField::can_add(const double x[3]) const
{
  if (levels_.empty())
    return false;
  double w[3];
  for (int d = 0; d < 3; ++d)
  {
    w[d] = x[d];
    if (box_[d] > 0.0)
    {
      w[d] = x[d] - box_[d] * std::floor(x[d] / box_[d]);
      if (w[d] >= box_[d])
        w[d] -= box_[d];
    }
  }
  std::array<long, 3> I;
  return fine_index(w, I) && find_fine(I) >= 0;
}

bool CellMultipoleField::add_beads(std::size_t n, const double *x, const double *y, const double *z)
{
  if (levels_.empty() || n < n_ || near_targets_ < n)
    return false;
  const double *coord[3] = {x, y, z};
  // First the cells (as build() wraps and sorts): all must be occupied, or nothing changes.
  const std::size_t first = n_;
  std::vector<double> xw(3 * (n - first));
  std::vector<std::uint32_t> cell(n - first);
  for (std::size_t b = first; b < n; ++b)
  {
    double *w = &xw[3 * (b - first)];
    for (int d = 0; d < 3; ++d)
    {
      w[d] = coord[d][b];
      if (box_[d] > 0.0)
      {
        w[d] = coord[d][b] - box_[d] * std::floor(coord[d][b] / box_[d]);
        if (w[d] >= box_[d])
          w[d] -= box_[d];
      }
    }
    std::array<long, 3> I;
    if (!fine_index(w, I))
      return false;
    const long c = find_fine(I);
    if (c < 0)
      return false;
    cell[b - first] = static_cast<std::uint32_t>(c);
  }
  n_ = n;
  xw_.insert(xw_.end(), xw.begin(), xw.end());
  wrap_shift_.resize(3 * n);
  bead_cell_.resize(n);
  for (std::size_t b = first; b < n; ++b)
  {
    bead_cell_[b] = cell[b - first];
    for (int d = 0; d < 3; ++d)
      wrap_shift_[3 * b + d] = xw_[3 * b + d] - coord[d][b];
  }
  // Every cell's beads in ascending index (as build()'s sort leaves them): the old ones, then
  // the appended ones of that cell.
  const std::size_t nc = bead_begin_.size() - 1;
  begin_scratch_.assign(nc + 1, 0);
  for (std::size_t c = 0; c < nc; ++c)
    begin_scratch_[c + 1] = bead_begin_[c + 1] - bead_begin_[c];
  for (std::size_t b = first; b < n; ++b)
    ++begin_scratch_[bead_cell_[b] + 1];
  for (std::size_t c = 0; c < nc; ++c)
    begin_scratch_[c + 1] += begin_scratch_[c];
  order_scratch_.resize(n);
  for (std::size_t c = 0; c < nc; ++c)
    std::copy(bead_order_.begin() + bead_begin_[c], bead_order_.begin() + bead_begin_[c + 1],
              order_scratch_.begin() + begin_scratch_[c]);
  std::vector<std::uint32_t> fill(nc);
  for (std::size_t c = 0; c < nc; ++c)
    fill[c] = begin_scratch_[c] + (bead_begin_[c + 1] - bead_begin_[c]);
  for (std::size_t b = first; b < n; ++b)
    order_scratch_[fill[bead_cell_[b]]++] = static_cast<std::uint32_t>(b);
  bead_order_.swap(order_scratch_);
  bead_begin_.swap(begin_scratch_);
  return true;
}

void CellMultipoleField::appended_near_pairs(std::size_t first, std::vector<MagneticNeighbourList::Pair> &out) const
{
  const long s = near_reach_, span = 2 * s + 1, per_cell = span * span * span;
  auto make_pair = [&](std::uint32_t i, std::uint32_t j, const double shift[3]) {
    MagneticNeighbourList::Pair p;
    p.i = i;
    p.j = j;
    for (int d = 0; d < 3; ++d)
      p.shift[d] = shift[d] + wrap_shift_[3 * j + d] - wrap_shift_[3 * i + d];
    return p;
  };
  for (std::size_t c = first; c < n_; ++c)
  {
    const std::size_t e0 = bead_cell_[c] * per_cell;
    for (std::size_t e = e0; e < e0 + per_cell; ++e)
    {
      const std::int32_t cell = neighbour_cell_[e];
      if (cell < 0)
        continue;
      double shift[3], back[3];
      for (int d = 0; d < 3; ++d)
      {
        shift[d] = box_[d] > 0.0 ? static_cast<double>(static_cast<long>(neighbour_image_[3 * e + d])) * box_[d] : 0.0;
        back[d] = -shift[d];
      }
      const bool zero_shift = shift[0] == 0.0 && shift[1] == 0.0 && shift[2] == 0.0;
      const bool positive_shift =
        shift[0] > 0.0 || (shift[0] == 0.0 && (shift[1] > 0.0 || (shift[1] == 0.0 && shift[2] > 0.0)));
      for (std::uint32_t k = bead_begin_[cell]; k < bead_begin_[cell + 1]; ++k)
      {
        const std::uint32_t j = bead_order_[k];
        if (j < first) // an older bead: listed from its side, with the image seen from there
          out.push_back(make_pair(j, static_cast<std::uint32_t>(c), back));
        else if (j > c || (j == c && !zero_shift && positive_shift))
          out.push_back(make_pair(static_cast<std::uint32_t>(c), j, shift));
      }
    }
  }
}

void CellMultipoleField::far_field_at(std::size_t b, double B[3], double gradB[9]) const
{
  const Level &fine = levels_[0];
  const std::uint32_t c = bead_cell_[b];
  const auto centre_c = centre(0, fine.index[c]);
  const double u[3] = {xw_[3 * b] - centre_c[0], xw_[3 * b + 1] - centre_c[1], xw_[3 * b + 2] - centre_c[2]};
  double G[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  B[0] = B[1] = B[2] = 0.0;
  taylor_.evaluate(u, &fine.L[c * taylor_.local_size()], B, G);
  for (int a = 0; a < 3; ++a)
    for (int d = 0; d < 3; ++d)
      gradB[3 * a + d] = G[a][d];
}

bool CellMultipoleField::set_fine_locals(const std::vector<double> &L)
{
  if (levels_.empty() || L.size() != levels_[0].L.size())
    return false;
  levels_[0].L = L;
  return true;
}

bool CellMultipoleField::near(int level, const std::array<long, 3> &D) const
{
  // Columns (all periodic axes collapsed): neighbours along the open axes, any image.
  // Resolved levels: 3D neighbours in unwrapped index space (images explicit).
  const long reach = level == 0 ? near_reach_ : 1;
  for (int d = 0; d < 3; ++d)
    if (!(level >= column_level_ && box_[d] > 0.0) && std::abs(D[d]) > reach)
      return false;
  return true;
}

void CellMultipoleField::build_interaction_lists()
{
  const int top = static_cast<int>(levels_.size()) - 1;
  const std::size_t na = taylor_.local_size() * taylor_.multipole_size();
  for (int level = 0; level <= top; ++level)
  {
    Level &l = levels_[level];
    l.list_begin.assign(1, 0);
    l.list_source.clear();
    l.list_matrix.clear();
    l.list_matrix_f.clear();
    // Translation of source cell J (unwrapped index I + D) to target I: below level m a
    // single image from the offset table; from level m up, the lattice sum over the images,
    // memoised per offset for this level (two map lookups per list entry were ~8 % of a
    // rebuild: with k = 3 cells per period the fine level itself is lattice-summed).
    lattice_memo_.assign(memo_width * memo_width * memo_width, {nullptr, nullptr});
    auto add = [&](const std::array<long, 3> &D, long source) {
      l.list_source.push_back(static_cast<std::uint32_t>(source));
      if (level + 1 < column_level_ && level < top)
      {
        const std::size_t o = ((D[0] + 3) + 7 * (D[1] + 3) + 49 * (D[2] + 3)) * na;
        l.list_matrix.push_back(&offset_D_[level][o]);
        l.list_matrix_f.push_back(&offset_Df_[level][o]);
        return;
      }
      const long R = memo_width / 2;
      const bool memo = std::abs(D[0]) <= R && std::abs(D[1]) <= R && std::abs(D[2]) <= R;
      std::pair<const double *, const float *> *entry =
        memo ? &lattice_memo_[static_cast<std::size_t>((D[0] + R) + memo_width * ((D[1] + R) + memo_width * (D[2] + R)))]
             : nullptr;
      if (!entry || !entry->first)
      {
        const std::pair<const double *, const float *> found{lattice_matrix(level, D).data(),
                                                             lattice_f_.at(lattice_key(level, D)).data()};
        if (!entry)
        {
          l.list_matrix.push_back(found.first);
          l.list_matrix_f.push_back(found.second);
          return;
        }
        *entry = found;
      }
      l.list_matrix.push_back(entry->first);
      l.list_matrix_f.push_back(entry->second);
    };
    for (std::size_t c = 0; c < l.keys.size(); ++c)
    {
      const auto &I = l.index[c];
      if (level == top)
      {
        // Every occupied top cell that is not a neighbour (all images, lattice-summed).
        for (std::size_t s = 0; s < l.keys.size(); ++s)
        {
          std::array<long, 3> D = {l.index[s][0] - I[0], l.index[s][1] - I[1], l.index[s][2] - I[2]};
          if (periodic_axes_ == 0 && near(level, D))
            continue;
          if (periodic_axes_ > 0 && near(level, D))
            continue; // columns: neighbours are refined below
          add(D, static_cast<long>(s));
        }
        // Resolved top (no periodic axis): done. Periodic top with images of itself or of
        // a neighbour: refined below as well.
        l.list_begin.push_back(static_cast<std::uint32_t>(l.list_source.size()));
        continue;
      }
      const Level &up = levels_[level + 1];
      const std::array<long, 3> P = up.index[l.parent[c]];
      // The parent's neighbours: columns along the open axes only; resolved cells in 3D.
      std::array<long, 3> span{1, 1, 1};
      if (level + 1 >= column_level_)
        for (int d = 0; d < 3; ++d)
          if (box_[d] > 0.0)
            span[d] = 0;
      for (long oz = -span[2]; oz <= span[2]; ++oz)
        for (long oy = -span[1]; oy <= span[1]; ++oy)
          for (long ox = -span[0]; ox <= span[0]; ++ox)
          {
            const long Q[3] = {P[0] + ox, P[1] + oy, P[2] + oz};
            const std::array<long, 3> f = l.factor;
            for (long cz = 0; cz < f[2]; ++cz)
              for (long cy = 0; cy < f[1]; ++cy)
                for (long cx = 0; cx < f[0]; ++cx)
                {
                  const std::array<long, 3> J = {Q[0] * f[0] + cx, Q[1] * f[1] + cy, Q[2] * f[2] + cz};
                  const std::array<long, 3> D = {J[0] - I[0], J[1] - I[1], J[2] - I[2]};
                  // Level m under a column parent: the images of J are summed in the
                  // lattice matrix, minus the neighbours; J itself may be one of them.
                  if (level + 1 < column_level_ && near(level, D))
                    continue;
                  if (level >= column_level_ && near(level, D))
                    continue;
                  std::array<long, 3> W = J;
                  if (!wrap(l, W))
                    continue;
                  const long source = level == 0 ? find_fine(W) : find(l, W);
                  if (source < 0)
                    continue;
                  add(D, source);
                }
          }
      l.list_begin.push_back(static_cast<std::uint32_t>(l.list_source.size()));
    }
  }
}

CellMultipoleField::LatticeKey CellMultipoleField::lattice_key(int level, const std::array<long, 3> &offset) const
{
  LatticeKey key = {level, offset[0], offset[1], offset[2], 0, 0, 0};
  for (int d = 0; d < 3; ++d)
    std::memcpy(&key[4 + d], &levels_[level].size[d], sizeof(double));
  return key;
}

const std::vector<double> &CellMultipoleField::lattice_matrix(int level, const std::array<long, 3> &offset)
{
  const LatticeKey key = lattice_key(level, offset);
  auto it = lattice_.find(key);
  if (it != lattice_.end())
    return it->second;
  const Level &t = levels_[level];
  const std::size_t nd = taylor_.derivative_size();
  std::vector<double> S(nd, 0.0), D(nd);
  // Images that are neighbours at this level are refined below (resolved levels only; for
  // columns the offset is never a neighbour).
  auto add_image = [&](const std::array<long, 3> &Delta) {
    if (level < column_level_ && near(level, Delta))
      return;
    const double R[3] = {-Delta[0] * t.size[0], -Delta[1] * t.size[1], -Delta[2] * t.size[2]};
    taylor_.derivatives(R, D.data());
    for (std::size_t a = 0; a < nd; ++a)
      S[a] += D[a];
  };
  const bool charges = taylor_.source_kind() == SourceKind::charges;
  int axes[3], na = 0, open = -1;
  for (int d = 0; d < 3; ++d)
    if (box_[d] > 0.0)
      axes[na++] = d;
    else
      open = d;
  if (na == 0)
    add_image(offset);
  else if (na == 1)
  {
    // ±M images explicitly, the rest as the integral over the continuous line of images
    // (Euler–Maclaurin with midpoint ends: the next term is ~f''/24, negligible at M = 40);
    // every dipole tensor is of order ≥ 2, so the tail decays at least like 1/M² (charges
    // add the orders 0 and 1: the field's tail is integrable, the potential's regularised).
    const int ax = axes[0];
    const long step = t.cells[ax];
    const double period = box_[ax];
    for (long j = -one_axis_images; j <= one_axis_images; ++j)
    {
      std::array<long, 3> Delta = offset;
      Delta[ax] += j * step;
      add_image(Delta);
    }
    static const double node[8] = {0.0198550717512319, 0.1016667612931866, 0.2372337950418355,
                                   0.4082826787521751, 0.5917173212478249, 0.7627662049581645,
                                   0.8983332387068134, 0.9801449282487681};
    static const double weight[8] = {0.0506142681451881, 0.1111905172266872, 0.1568533229389436,
                                     0.1813418916891810, 0.1813418916891810, 0.1568533229389436,
                                     0.1111905172266872, 0.0506142681451881};
    const double Z0 = (one_axis_images + 0.5) * period;
    const double R0[3] = {-offset[0] * t.size[0], -offset[1] * t.size[1], -offset[2] * t.size[2]};
    for (int side : {-1, 1})
      for (int q = 0; q < 8; ++q)
      {
        const double z = Z0 / node[q];
        double R[3] = {R0[0], R0[1], R0[2]};
        R[ax] += side * z;
        taylor_.derivatives(R, D.data());
        const double w = weight[q] * Z0 / (node[q] * node[q]) / period;
        // Charges: the potential of a line of images diverges like ln; the regularised tail
        // ∫ (1/|R| − 1/z) drops the same infinite constant for every offset, so Φ is defined
        // up to (that constant) × (the total charge) and the field is exact.
        if (charges)
          D[0] -= 1.0 / z;
        for (std::size_t a = 0; a < nd; ++a)
          S[a] += w * D[a];
      }
  }
  else if (charges)
    windowed_sheet_sum(level, offset, axes, S);
  else
  {
    // Two periodic axes: the lattice sum of the order-2 tensor converges only like 1/R
    // (the rim of a polarised sheet). Images inside a disc of radius R_M explicitly, the
    // rest as a continuum of areal density 1/A: an infinite uniform sheet of dipoles has no
    // field off the sheet, so the continuum beyond R_eff (the disc of the same area as the
    // summed images) contributes −(the disc), which for D_α at height h above the sheet is
    //   ∫_{ρ>R} ∂²(1/r)/∂h² dA = −2π q,  ∫_{ρ>R} ∂²(1/r)/∂t² dA = π q,  q = R²/(R² + h²)^{3/2},
    // and its h-derivative for the order-3 tensors (orders ≥ 4 decay like 1/R³: neglected).
    const long M = two_axis_image_radius;
    long count = 0;
    for (long m1 = -M; m1 <= M; ++m1)
      for (long m2 = -M; m2 <= M; ++m2)
      {
        if (m1 * m1 + m2 * m2 > M * M)
          continue;
        ++count;
        std::array<long, 3> Delta = offset;
        Delta[axes[0]] += m1 * t.cells[axes[0]];
        Delta[axes[1]] += m2 * t.cells[axes[1]];
        add_image(Delta);
      }
    const double A = box_[axes[0]] * box_[axes[1]];
    const double R2 = count * A / pi;
    const double hn = -offset[open] * t.size[open];
    const double s0 = R2 + hn * hn;
    const double q = R2 / (s0 * std::sqrt(s0)), q3 = -3.0 * hn * R2 / (s0 * s0 * std::sqrt(s0));
    auto at = [&](int n_normal, int n_t1, int n_t2) {
      int e[3] = {0, 0, 0};
      e[open] = n_normal;
      e[axes[0]] = n_t1;
      e[axes[1]] = n_t2;
      return taylor_.index(e[0], e[1], e[2]);
    };
    S[at(2, 0, 0)] += -2.0 * pi / A * q;
    S[at(0, 2, 0)] += pi / A * q;
    S[at(0, 0, 2)] += pi / A * q;
    S[at(3, 0, 0)] += -2.0 * pi / A * q3;
    S[at(1, 2, 0)] += pi / A * q3;
    S[at(1, 0, 2)] += pi / A * q3;
  }
  std::vector<double> matrix(taylor_.local_size() * taylor_.multipole_size());
  taylor_.translation_matrix(S.data(), matrix.data());
  std::vector<float> &scaled = lattice_f_[key];
  scaled.resize(matrix.size());
  taylor_.scaled_matrix(matrix.data(), t.scale, scaled.data());
  return lattice_.emplace(key, std::move(matrix)).first->second;
}

void CellMultipoleField::windowed_sheet_sum(int level, const std::array<long, 3> &offset, const int axes[2],
                                            std::vector<double> &S)
{
  // Charges, two periodic axes: the sums of orders 0 and 1 (the potential and field of a
  // charged sheet) converge badly or not at all, and the hard disc + analytic continuum of the
  // dipoles leaves ~1e-3 of the sheet field from the disc's ragged rim (its lattice-point
  // count). Here the images are weighted by a smooth window w(ρ/ρ_M) (1 inside half the
  // radius, falling to 0 at ρ_M = two_axis_image_radius periods, C∞) and the rest, (1 − w),
  // is the continuum integral of density 1/A: by Poisson summation the lattice sum of the
  // smooth (1 − w) D_α differs from its integral only by its Fourier transform at the
  // reciprocal lattice vectors, which a smooth window makes negligible. The integral runs in
  // polar coordinates about the offset's own image (radial Gauss–Legendre over the window's
  // ramp and over the tail ρ = ρ_M/t, the periodic angle by the trapezoidal rule). The
  // potential's integral diverges: its integrand is regularised by −1/ρ, which drops the same
  // infinite constant for every offset.
  const Level &t = levels_[level];
  const std::size_t nd = taylor_.derivative_size();
  std::vector<double> D(nd);
  const double P1 = box_[axes[0]], P2 = box_[axes[1]], A = P1 * P2;
  const double rho_max = two_axis_image_radius * std::min(P1, P2), rho_in = 0.5 * rho_max;
  auto window = [&](double rho) {
    if (rho <= rho_in)
      return 1.0;
    if (rho >= rho_max)
      return 0.0;
    const double u = (rho - rho_in) / (rho_max - rho_in);
    const double a = std::exp(-1.0 / u), b = std::exp(-1.0 / (1.0 - u));
    return b / (a + b);
  };
  const double R0[3] = {-offset[0] * t.size[0], -offset[1] * t.size[1], -offset[2] * t.size[2]};
  const long M1 = static_cast<long>(std::ceil(rho_max / P1)), M2 = static_cast<long>(std::ceil(rho_max / P2));
  for (long m1 = -M1; m1 <= M1; ++m1)
    for (long m2 = -M2; m2 <= M2; ++m2)
    {
      const double w = window(std::hypot(m1 * P1, m2 * P2));
      if (w == 0.0)
        continue;
      std::array<long, 3> Delta = offset;
      Delta[axes[0]] += m1 * t.cells[axes[0]];
      Delta[axes[1]] += m2 * t.cells[axes[1]];
      if (level < column_level_ && near(level, Delta))
        continue;
      const double R[3] = {-Delta[0] * t.size[0], -Delta[1] * t.size[1], -Delta[2] * t.size[2]};
      taylor_.derivatives(R, D.data());
      for (std::size_t a = 0; a < nd; ++a)
        S[a] += w * D[a];
    }
  // Gauss–Legendre nodes on [0, 1] (24 points), by Newton iteration on P_24.
  constexpr int ng = 24, nangle = 32;
  static const std::array<std::array<double, ng>, 2> gauss = [] {
    std::array<std::array<double, ng>, 2> g{};
    for (int i = 0; i < ng; ++i)
    {
      double x = std::cos(pi * (i + 0.75) / (ng + 0.5)), dp = 0.0;
      for (int it = 0; it < 100; ++it)
      {
        double p0 = 1.0, p1 = x;
        for (int k = 2; k <= ng; ++k)
        {
          const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = ng * (x * p1 - p0) / (x * x - 1.0);
        const double dx = p1 / dp;
        x -= dx;
        if (std::abs(dx) < 1e-16)
          break;
      }
      g[0][i] = 0.5 * (1.0 - x);
      g[1][i] = 1.0 / ((1.0 - x * x) * dp * dp); // weight on [0, 1]: 2/((1−x²)P'²)/2
    }
    return g;
  }();
  auto ring = [&](double rho, double weight) {
    // weight × ∫ dθ (1 − w) D_α(R0 + ρ e_θ) ρ / A, trapezoidal in θ.
    const double f = weight * (1.0 - window(rho)) * rho / A * (2.0 * pi / nangle);
    if (f == 0.0)
      return;
    for (int k = 0; k < nangle; ++k)
    {
      const double th = 2.0 * pi * (k + 0.5) / nangle;
      double R[3] = {R0[0], R0[1], R0[2]};
      R[axes[0]] += rho * std::cos(th);
      R[axes[1]] += rho * std::sin(th);
      taylor_.derivatives(R, D.data());
      D[0] -= 1.0 / rho;
      for (std::size_t a = 0; a < nd; ++a)
        S[a] += f * D[a];
    }
  };
  for (int i = 0; i < ng; ++i)
    ring(rho_in + (rho_max - rho_in) * gauss[0][i], (rho_max - rho_in) * gauss[1][i]);
  for (int i = 0; i < ng; ++i)
  {
    const double u = gauss[0][i]; // ρ = ρ_M/u, dρ = ρ_M/u² du
    ring(rho_max / u, rho_max / (u * u) * gauss[1][i]);
  }
}

void CellMultipoleField::build_near_pairs(const double *const coord[3])
{
  const Level &fine = levels_[0];
  // The (2 near_reach + 1)³ neighbour cells of every occupied fine cell (−1: empty or
  // outside) and their image counts along the periodic axes, found once per cell rather
  // than once per bead (the wraps and lookups were a third of collecting the pairs).
  const long s = near_reach_, span = 2 * s + 1, per_cell = span * span * span;
  const std::size_t nc = fine.keys.size();
  neighbour_cell_.resize(nc * per_cell);
  neighbour_image_.resize(3 * nc * per_cell);
  for (std::size_t c = 0; c < nc; ++c)
  {
    const auto &I = fine.index[c];
    std::size_t e = c * per_cell;
    for (long oz = -s; oz <= s; ++oz)
      for (long oy = -s; oy <= s; ++oy)
        for (long ox = -s; ox <= s; ++ox, ++e)
        {
          const std::array<long, 3> J = {I[0] + ox, I[1] + oy, I[2] + oz};
          std::array<long, 3> W = J;
          neighbour_cell_[e] = wrap(fine, W) ? static_cast<std::int32_t>(find_fine(W)) : -1;
          for (int d = 0; d < 3; ++d)
            neighbour_image_[3 * e + d] = box_[d] > 0.0 ? static_cast<std::int32_t>((J[d] - W[d]) / fine.cells[d]) : 0;
        }
  }
  auto for_each_neighbour = [&](std::size_t i, auto &&emit) {
    const std::size_t e0 = bead_cell_[i] * per_cell;
    for (std::size_t e = e0; e < e0 + per_cell; ++e)
    {
      const std::int32_t c = neighbour_cell_[e];
      if (c < 0)
        continue;
      double shift[3];
      for (int d = 0; d < 3; ++d)
        shift[d] = box_[d] > 0.0 ? static_cast<double>(static_cast<long>(neighbour_image_[3 * e + d])) * box_[d] : 0.0;
      const bool zero_shift = shift[0] == 0.0 && shift[1] == 0.0 && shift[2] == 0.0;
      const bool positive_shift =
        shift[0] > 0.0 || (shift[0] == 0.0 && (shift[1] > 0.0 || (shift[1] == 0.0 && shift[2] > 0.0)));
      // A cell's beads are in ascending index: start at the first j ≥ i.
      const std::uint32_t *first = bead_order_.data() + bead_begin_[c], *last = bead_order_.data() + bead_begin_[c + 1];
      for (const std::uint32_t *k = std::lower_bound(first, last, static_cast<std::uint32_t>(i)); k < last; ++k)
      {
        const std::uint32_t j = *k;
        if ((j == i && (zero_shift || !positive_shift)) || (i >= near_targets_ && j >= near_targets_))
          continue;
        emit(j, shift);
      }
    }
  };
  MagneticNeighbourList::collect_pairs(n_, for_each_neighbour, xw_.data(), coord, parallel_threshold, near_pairs_,
                                      near_pair_blocks_);
}

std::size_t CellMultipoleField::interactions() const
{
  std::size_t count = 0;
  for (const Level &l : levels_)
    count += l.list_source.size();
  return count;
}


void CellMultipoleField::evaluate(const double *p, double *B, double *gradB)
{
  if (taylor_.source_kind() != SourceKind::dipoles)
    throw std::logic_error("cell multipole: evaluate(p, B, gradB) is the dipole field; this "
                           "expansion is for charges (evaluate(sources, targets)).");
  form_multipoles([&](const double s[3], std::uint32_t b, double *M) { taylor_.add_dipole(s, &p[3 * b], M); });
  translate();
  evaluate_at_beads([&](const double u[3], std::uint32_t b, const double *L) {
    double Bb[3] = {0.0, 0.0, 0.0}, G[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    taylor_.evaluate(u, L, Bb, G);
    for (int a = 0; a < 3; ++a)
    {
      B[3 * b + a] = Bb[a];
      for (int d = 0; d < 3; ++d)
        gradB[9 * b + 3 * a + d] = G[a][d];
    }
  });
}

void CellMultipoleField::evaluate(const FarFieldSources &sources, const FarFieldTargets &targets)
{
  if (taylor_.source_kind() != SourceKind::charges)
    throw std::logic_error("cell multipole: evaluate(sources, targets) needs an expansion built "
                           "for charges (SourceKind::charges); this one is for dipoles.");
  form_multipoles([&](const double s[3], std::uint32_t b, double *M) {
    if (sources.charge)
      taylor_.add_charge(s, sources.charge[b], M);
    if (sources.dipole)
      taylor_.add_dipole(s, &sources.dipole[3 * b], M);
  });
  translate();
  evaluate_at_beads([&](const double u[3], std::uint32_t b, const double *L) {
    double phi = 0.0, grad[3] = {0, 0, 0}, hessian[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    taylor_.evaluate_potential(u, L, targets.potential ? &phi : nullptr, targets.field ? grad : nullptr,
                               targets.gradient ? hessian : nullptr);
    if (targets.potential)
      targets.potential[b] = phi;
    if (targets.field)
      for (int a = 0; a < 3; ++a)
        targets.field[3 * b + a] = -grad[a];
    if (targets.gradient)
      for (int a = 0; a < 9; ++a)
        targets.gradient[9 * b + a] = -hessian[a];
  });
}

template <class AddSources>
void CellMultipoleField::form_multipoles(const AddSources &add_sources)
{
  // P2M: every fine cell sums the moments of its beads about its centre.
  const std::size_t nm = taylor_.multipole_size();
  Level &fine = levels_[0];
  const long nc = static_cast<long>(fine.keys.size());
#pragma omp parallel for schedule(static) if (nc >= static_cast<long>(parallel_threshold))
  for (long c = 0; c < nc; ++c)
  {
    double *M = &fine.M[c * nm];
    std::fill(M, M + nm, 0.0);
    const auto centre_c = centre(0, fine.index[c]);
    for (std::uint32_t k = bead_begin_[c]; k < bead_begin_[c + 1]; ++k)
    {
      const std::uint32_t b = bead_order_[k];
      const double s[3] = {xw_[3 * b] - centre_c[0], xw_[3 * b + 1] - centre_c[1],
                           xw_[3 * b + 2] - centre_c[2]};
      add_sources(s, b, M);
    }
  }
}

void CellMultipoleField::translate()
{
  const int top = static_cast<int>(levels_.size()) - 1;
  const std::size_t nm = taylor_.multipole_size(), nl = taylor_.local_size();
  // M2M.
  for (int level = 1; level <= top; ++level)
  {
    Level &l = levels_[level];
    const Level &child = levels_[level - 1];
    const long nc = static_cast<long>(l.keys.size());
#pragma omp parallel for schedule(static) if (nc >= static_cast<long>(parallel_threshold))
    for (long c = 0; c < nc; ++c)
    {
      double *M = &l.M[c * nm];
      std::fill(M, M + nm, 0.0);
      const auto centre_c = centre(level, l.index[c]);
      for (std::uint32_t k = l.child_begin[c]; k < l.child_begin[c + 1]; ++k)
      {
        const std::uint32_t ch = l.children[k];
        const auto centre_ch = centre(level - 1, child.index[ch]);
        const double d[3] = {centre_ch[0] - centre_c[0], centre_ch[1] - centre_c[1],
                             centre_ch[2] - centre_c[2]};
        taylor_.shift_multipole(d, &child.M[ch * nm], M);
      }
    }
  }
  if (single_precision_)
    for (Level &l : levels_)
    {
      l.Mf.resize(l.M.size());
      for (std::size_t c = 0; c < l.keys.size(); ++c)
        taylor_.scaled_moments(&l.M[c * nm], l.scale, &l.Mf[c * nm]);
    }
  // M2L at every level, L2L downwards.
  for (int level = top; level >= 0; --level)
  {
    Level &l = levels_[level];
    const long nc = static_cast<long>(l.keys.size());
#pragma omp parallel for schedule(dynamic, 16) if (nc >= 64)
    for (long c = 0; c < nc; ++c)
    {
      double *L = &l.L[c * nl];
      std::fill(L, L + nl, 0.0);
      if (level < top)
      {
        const Level &up = levels_[level + 1];
        const auto centre_c = centre(level, l.index[c]);
        const auto centre_p = centre(level + 1, up.index[l.parent[c]]);
        const double e[3] = {centre_c[0] - centre_p[0], centre_c[1] - centre_p[1],
                             centre_c[2] - centre_p[2]};
        taylor_.shift_local(e, &up.L[l.parent[c] * nl], L);
      }
      if (single_precision_)
      {
        float Lf[1024];
        std::fill(Lf, Lf + nl, 0.0f);
        for (std::uint32_t k = l.list_begin[c]; k < l.list_begin[c + 1]; ++k)
          taylor_.accumulate_translation(l.list_matrix_f[k], &l.Mf[l.list_source[k] * nm], Lf);
        for (std::size_t g = 0; g < nl; ++g)
          L[g] += l.row_scale[g] * Lf[g];
      }
      else
        for (std::uint32_t k = l.list_begin[c]; k < l.list_begin[c + 1]; ++k)
          taylor_.apply_translation(l.list_matrix[k], &l.M[l.list_source[k] * nm], L);
    }
  }
}

template <class AtBead>
void CellMultipoleField::evaluate_at_beads(const AtBead &at_bead) const
{
  // L2P: every bead reads its fine cell's local expansion at its offset from the centre.
  const std::size_t nl = taylor_.local_size();
  const Level &fine = levels_[0];
  const long nc = static_cast<long>(fine.keys.size());
#pragma omp parallel for schedule(static) if (nc >= static_cast<long>(parallel_threshold))
  for (long c = 0; c < nc; ++c)
  {
    const auto centre_c = centre(0, fine.index[c]);
    for (std::uint32_t k = bead_begin_[c]; k < bead_begin_[c + 1]; ++k)
    {
      const std::uint32_t b = bead_order_[k];
      const double u[3] = {xw_[3 * b] - centre_c[0], xw_[3 * b + 1] - centre_c[1],
                           xw_[3 * b + 2] - centre_c[2]};
      at_bead(u, b, &fine.L[c * nl]);
    }
  }
}

} // namespace magbrush::magnetics
