#include "cell_multipole_field.h"

#include "dipole_physics.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace magbrush::magnetics {

namespace {
constexpr std::size_t parallel_threshold = 256; // cells or beads
constexpr long one_axis_images = 400;           // ±images of the top level, 1 periodic axis
constexpr long two_axis_image_radius = 64;      // disc radius in periods, 2 periodic axes

long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a - 1) / b) - 1; }

bool adjacent(const std::array<long, 3> &d, long reach = 1)
{
  return std::abs(d[0]) <= reach && std::abs(d[1]) <= reach && std::abs(d[2]) <= reach;
}
} // namespace

CellMultipoleField::CellMultipoleField(int order, const std::array<double, 3> &box, int near_reach)
  : taylor_(order), box_(box), near_reach_(near_reach)
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

  levels_.clear();
  levels_.emplace_back();
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

  // Coarser levels until the top: k cells across the periodic axes (level m), or, with no
  // periodic axis, at most 4 cells across every axis.
  for (int level = 0;; ++level)
  {
    const Level &l = levels_[level];
    bool top;
    if (periodic_axes_ > 0)
      top = level == m;
    else
    {
      std::array<long, 3> lo{LONG_MAX, LONG_MAX, LONG_MAX}, hi{LONG_MIN, LONG_MIN, LONG_MIN};
      for (const auto &I : l.index)
        for (int d = 0; d < 3; ++d)
        {
          lo[d] = std::min(lo[d], I[d]);
          hi[d] = std::max(hi[d], I[d]);
        }
      top = l.index.empty() || (hi[0] - lo[0] < 4 && hi[1] - lo[1] < 4 && hi[2] - lo[2] < 4);
    }
    if (top || level >= 24)
      break;
    Level next;
    for (int d = 0; d < 3; ++d)
    {
      next.size[d] = 2.0 * l.size[d];
      next.cells[d] = l.cells[d] / 2;
    }
    std::vector<std::uint64_t> parent_keys(l.keys.size());
    for (std::size_t c = 0; c < l.keys.size(); ++c)
      parent_keys[c] = key_of({l.index[c][0] >> 1, l.index[c][1] >> 1, l.index[c][2] >> 1});
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
    l.M.assign(l.keys.size() * taylor_.multipole_size(), 0.0);
    l.L.assign(l.keys.size() * taylor_.local_size(), 0.0);
  }

  // Translation tensors of the lower levels (depend on the cell size only).
  // The top level's size depends on the number of levels when nothing is periodic.
  if (h_ != cached_h_ || levels_.size() != cached_levels_)
    top_D_.clear();
  bool tabulated = h_ == cached_h_;
  for (std::size_t level = 0; level + 1 < levels_.size(); ++level)
    tabulated = tabulated && level < offset_D_.size() && !offset_D_[level].empty();
  cached_levels_ = levels_.size();
  if (!tabulated)
  {
    cached_h_ = h_;
    offset_D_.assign(levels_.size(), {});
    const std::size_t nd = taylor_.derivative_size();
    const std::size_t na = taylor_.local_size() * taylor_.multipole_size();
    std::vector<double> D(nd);
    for (std::size_t level = 0; level + 1 < levels_.size(); ++level)
    {
      std::vector<double> &A = offset_D_[level];
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
    }
  }
  build_interaction_lists();
  build_near_pairs(coord);
}

void CellMultipoleField::build_interaction_lists()
{
  const int top = static_cast<int>(levels_.size()) - 1;
  for (int level = 0; level < top; ++level)
  {
    Level &l = levels_[level];
    const Level &up = levels_[level + 1];
    l.list_begin.assign(1, 0);
    l.list_source.clear();
    l.list_offset.clear();
    for (std::size_t c = 0; c < l.keys.size(); ++c)
    {
      const auto &I = l.index[c];
      const std::array<long, 3> P = up.index[l.parent[c]];
      for (long oz = -1; oz <= 1; ++oz)
        for (long oy = -1; oy <= 1; ++oy)
          for (long ox = -1; ox <= 1; ++ox)
            for (int bits = 0; bits < 8; ++bits)
            {
              const std::array<long, 3> J = {2 * (P[0] + ox) + (bits & 1),
                                             2 * (P[1] + oy) + ((bits >> 1) & 1),
                                             2 * (P[2] + oz) + ((bits >> 2) & 1)};
              const std::array<long, 3> D = {J[0] - I[0], J[1] - I[1], J[2] - I[2]};
              if (adjacent(D, level == 0 ? near_reach_ : 1))
                continue;
              std::array<long, 3> W = J;
              if (!wrap(l, W))
                continue;
              const long s = find(l, W);
              if (s < 0)
                continue;
              l.list_source.push_back(static_cast<std::uint32_t>(s));
              l.list_offset.push_back(
                static_cast<std::uint16_t>((D[0] + 3) + 7 * (D[1] + 3) + 49 * (D[2] + 3)));
            }
      l.list_begin.push_back(static_cast<std::uint32_t>(l.list_source.size()));
    }
  }
  // Top level: every occupied top cell with every other (and itself), all periodic images
  // not adjacent, through the lattice-summed tensors.
  Level &t = levels_[top];
  t.list_begin.assign(1, 0);
  t.list_source.clear();
  top_tensor_.clear();
  top_tensors_.clear();
  std::map<const std::vector<double> *, std::uint32_t> slot;
  for (std::size_t c = 0; c < t.keys.size(); ++c)
  {
    for (std::size_t s = 0; s < t.keys.size(); ++s)
    {
      const std::array<long, 3> D = {t.index[s][0] - t.index[c][0], t.index[s][1] - t.index[c][1],
                                     t.index[s][2] - t.index[c][2]};
      if (periodic_axes_ == 0 && adjacent(D, top == 0 ? near_reach_ : 1))
        continue;
      const std::vector<double> &tensor = top_tensor(D);
      auto it = slot.find(&tensor);
      if (it == slot.end())
      {
        it = slot.emplace(&tensor, static_cast<std::uint32_t>(top_tensors_.size())).first;
        top_tensors_.push_back(&tensor);
      }
      t.list_source.push_back(static_cast<std::uint32_t>(s));
      top_tensor_.push_back(it->second);
    }
    t.list_begin.push_back(static_cast<std::uint32_t>(t.list_source.size()));
  }
}

const std::vector<double> &CellMultipoleField::top_tensor(const std::array<long, 3> &offset)
{
  auto it = top_D_.find(offset);
  if (it != top_D_.end())
    return it->second;
  const Level &t = levels_.back();
  const std::size_t nd = taylor_.derivative_size();
  std::vector<double> S(nd, 0.0), D(nd);
  const long reach = levels_.size() == 1 ? near_reach_ : 1;
  auto add_image = [&](const std::array<long, 3> &Delta) {
    if (adjacent(Delta, reach))
      return;
    const double R[3] = {-Delta[0] * t.size[0], -Delta[1] * t.size[1], -Delta[2] * t.size[2]};
    taylor_.derivatives(R, D.data());
    for (std::size_t a = 0; a < nd; ++a)
      S[a] += D[a];
  };
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
    // The image sum converges absolutely (every tensor used is of order ≥ 2, ~1/|m|³):
    // truncating at ±400 periods leaves ~1e-6 of the nearest image.
    for (long m = -one_axis_images; m <= one_axis_images; ++m)
    {
      std::array<long, 3> Delta = offset;
      Delta[axes[0]] += m * t.cells[axes[0]];
      add_image(Delta);
    }
  }
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
  std::vector<double> A(taylor_.local_size() * taylor_.multipole_size());
  taylor_.translation_matrix(S.data(), A.data());
  return top_D_.emplace(offset, std::move(A)).first->second;
}

void CellMultipoleField::build_near_pairs(const double *const coord[3])
{
  const Level &fine = levels_[0];
  auto for_each_neighbour = [&](std::size_t i, auto &&emit) {
    const auto &I = fine.index[bead_cell_[i]];
    const long s = near_reach_;
    for (long oz = -s; oz <= s; ++oz)
      for (long oy = -s; oy <= s; ++oy)
        for (long ox = -s; ox <= s; ++ox)
        {
          std::array<long, 3> J = {I[0] + ox, I[1] + oy, I[2] + oz};
          std::array<long, 3> W = J;
          if (!wrap(fine, W))
            continue;
          const long c = find(fine, W);
          if (c < 0)
            continue;
          double shift[3];
          for (int d = 0; d < 3; ++d)
            shift[d] = box_[d] > 0.0 ? static_cast<double>((J[d] - W[d]) / fine.cells[d]) * box_[d] : 0.0;
          const bool zero_shift = shift[0] == 0.0 && shift[1] == 0.0 && shift[2] == 0.0;
          const bool positive_shift =
            shift[0] > 0.0 || (shift[0] == 0.0 && (shift[1] > 0.0 || (shift[1] == 0.0 && shift[2] > 0.0)));
          for (std::uint32_t k = bead_begin_[c]; k < bead_begin_[c + 1]; ++k)
          {
            const std::uint32_t j = bead_order_[k];
            if (j < i || (j == i && (zero_shift || !positive_shift)))
              continue;
            emit(j, shift);
          }
        }
  };
  const std::size_t n = n_;
  std::vector<std::size_t> begin(n + 1, 0);
#pragma omp parallel for schedule(dynamic, 64) if (n >= parallel_threshold)
  for (long i = 0; i < static_cast<long>(n); ++i)
  {
    std::size_t count = 0;
    for_each_neighbour(i, [&](std::uint32_t, const double *) { ++count; });
    begin[i + 1] = count;
  }
  for (std::size_t i = 0; i < n; ++i)
    begin[i + 1] += begin[i];
  near_pairs_.resize(begin[n]);
#pragma omp parallel for schedule(dynamic, 64) if (n >= parallel_threshold)
  for (long i = 0; i < static_cast<long>(n); ++i)
  {
    std::size_t k = begin[i];
    for_each_neighbour(i, [&](std::uint32_t j, const double *shift) {
      auto &p = near_pairs_[k++];
      p.i = static_cast<std::uint32_t>(i);
      p.j = j;
      for (int d = 0; d < 3; ++d) // raw-coordinate shift: r = x_j − x_i + S
        p.shift[d] = shift[d] + (xw_[3 * j + d] - coord[d][j]) - (xw_[3 * i + d] - coord[d][i]);
    });
  }
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
  const int top = static_cast<int>(levels_.size()) - 1;
  const std::size_t nm = taylor_.multipole_size(), nl = taylor_.local_size();
  const std::size_t na = nl * nm;

  // 1. P2M.
  {
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
        taylor_.add_dipole(s, &p[3 * b], M);
      }
    }
  }
  // 2. M2M.
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
  // 3–4. M2L at every level, L2L downwards.
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
        const double *A = offset_D_[level].data();
        for (std::uint32_t k = l.list_begin[c]; k < l.list_begin[c + 1]; ++k)
          taylor_.apply_translation(&A[l.list_offset[k] * na], &l.M[l.list_source[k] * nm], L);
      }
      else
        for (std::uint32_t k = l.list_begin[c]; k < l.list_begin[c + 1]; ++k)
          taylor_.apply_translation(top_tensors_[top_tensor_[k]]->data(),
                                    &l.M[l.list_source[k] * nm], L);
    }
  }
  // 5. L2P.
  {
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
        double Bb[3] = {0.0, 0.0, 0.0}, G[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
        taylor_.evaluate(u, &fine.L[c * nl], Bb, G);
        for (int a = 0; a < 3; ++a)
        {
          B[3 * b + a] = Bb[a];
          for (int d = 0; d < 3; ++d)
            gradB[9 * b + 3 * a + d] = G[a][d];
        }
      }
    }
  }
}

} // namespace magbrush::magnetics
