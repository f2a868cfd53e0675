#include "magnetics/magnetic_neighbour_list.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace magbrush::magnetics {

namespace {

// Spare slots kept after a row of `count` incidence entries, for the pairs of beads appended
// later. A fed scene admits newcomers every few microseconds between two builds, and the
// beads near the inflow gain partners at each admission; without the spare slots every
// admission laid out the whole incidence again (and the near pairs' rows with it), O(pairs)
// for a few dozen new beads: ~16 % of a full-roller run. A quarter of the row plus four
// keeps all but a few admissions in place (MagneticNeighbourList::relayouts() counts them)
// for a quarter more memory in the arrays indexed by slot.
std::size_t spare_slots(std::size_t count) { return 4 + count / 4; }

// The cell grid along one axis. Periodic axes: nc cells of width L/nc ≥ list radius (one
// cell when the box is narrower than the radius); a bead looks `reach` cells either way,
// wrapping with an image shift. Open axes: cells of width ≥ list radius over the bounding
// box, reach 1, no wrap.
struct Axis
{
  bool periodic = false;
  double length = 0.0; // periodic length
  double origin = 0.0; // open axes: lower bound of the bounding box
  double width = 1.0;  // cell width
  long cells = 1;
  long reach = 1;

  long cell_of(double wrapped) const
  {
    long c = static_cast<long>(std::floor((wrapped - origin) / width));
    return std::clamp(c, 0L, cells - 1);
  }
};

// Wraps a coordinate into [0, L) on a periodic axis.
double wrap(double v, const Axis &a)
{
  if (!a.periodic)
    return v;
  double w = v - a.length * std::floor(v / a.length);
  if (w >= a.length) // round-off at the upper edge
    w -= a.length;
  return w;
}

} // namespace

void MagneticNeighbourList::build(std::size_t n, const double *x, const double *y,
                                  const double *z, const std::array<double, 3> &box,
                                  double list_radius, const PairReach &reach)
{
  if (!(list_radius > 0.0))
    throw std::invalid_argument("magnetic neighbour list: expected a positive list radius, "
                                "found " + std::to_string(list_radius) + " m.");
  if (n >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("magnetic neighbour list: too many beads for 32-bit indices.");
  list_radius_ = list_radius;
  box_ = box;
  const double *coord[3] = {x, y, z};

  // Grid: cap the number of cells so a sparse open box cannot blow the memory up.
  Axis axis[3];
  const long max_cells_per_axis = 1024;
  for (int d = 0; d < 3; ++d)
  {
    Axis &a = axis[d];
    a.periodic = box[d] > 0.0;
    if (a.periodic)
    {
      a.length = box[d];
      a.origin = 0.0;
      a.cells = std::clamp(static_cast<long>(std::floor(a.length / list_radius)), 1L,
                           max_cells_per_axis);
      a.width = a.length / a.cells;
      a.reach = static_cast<long>(std::ceil(list_radius / a.width));
    }
    else
    {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (std::size_t b = 0; b < n; ++b)
      {
        lo = std::min(lo, coord[d][b]);
        hi = std::max(hi, coord[d][b]);
      }
      if (n == 0)
        lo = hi = 0.0;
      a.origin = lo;
      a.width = std::max(list_radius, (hi - lo) / max_cells_per_axis);
      a.cells = static_cast<long>(std::floor((hi - lo) / a.width)) + 1;
      a.reach = 1;
    }
  }

  // Wrapped positions and cell of every bead; counting sort keeps index order in a cell.
  std::vector<double> xw(3 * n);
  std::vector<long> cell(n);
  const long ncell = axis[0].cells * axis[1].cells * axis[2].cells;
  std::vector<std::size_t> cell_begin(ncell + 1, 0);
  for (std::size_t b = 0; b < n; ++b)
  {
    long c[3];
    for (int d = 0; d < 3; ++d)
    {
      xw[3 * b + d] = wrap(coord[d][b], axis[d]);
      c[d] = axis[d].cell_of(xw[3 * b + d]);
    }
    cell[b] = (c[2] * axis[1].cells + c[1]) * axis[0].cells + c[0];
    ++cell_begin[cell[b] + 1];
  }
  for (long c = 0; c < ncell; ++c)
    cell_begin[c + 1] += cell_begin[c];
  std::vector<std::uint32_t> cell_beads(n);
  {
    std::vector<std::size_t> fill(cell_begin.begin(), cell_begin.end() - 1);
    for (std::size_t b = 0; b < n; ++b)
      cell_beads[fill[cell[b]]++] = static_cast<std::uint32_t>(b);
  }

  const double r2max = list_radius * list_radius;
  auto pair_reach2 = [&reach](std::size_t i, std::size_t j) {
    const double r = reach.factor * 0.5 * (reach.radius[i] + reach.radius[j]) + reach.skin;
    return r * r;
  };
  // Visits every (neighbour j ≥ i, image) of bead i within the list radius, in a fixed
  // order; `emit(j, shift)` receives the shift in wrapped coordinates.
  auto for_each_neighbour = [&](std::size_t i, auto &&emit) {
    long ci[3];
    for (int d = 0; d < 3; ++d)
      ci[d] = axis[d].cell_of(xw[3 * i + d]);
    for (long oz = -axis[2].reach; oz <= axis[2].reach; ++oz)
      for (long oy = -axis[1].reach; oy <= axis[1].reach; ++oy)
        for (long ox = -axis[0].reach; ox <= axis[0].reach; ++ox)
        {
          const long o[3] = {ox, oy, oz};
          long cj[3];
          double shift[3];
          bool inside = true;
          for (int d = 0; d < 3 && inside; ++d)
          {
            const long c = ci[d] + o[d];
            if (axis[d].periodic)
            {
              const long q = (c >= 0) ? c / axis[d].cells : -((-c - 1) / axis[d].cells) - 1;
              cj[d] = c - q * axis[d].cells;
              shift[d] = q * axis[d].length;
            }
            else
            {
              inside = (c >= 0 && c < axis[d].cells);
              cj[d] = c;
              shift[d] = 0.0;
            }
          }
          if (!inside)
            continue;
          const long c = (cj[2] * axis[1].cells + cj[1]) * axis[0].cells + cj[0];
          const bool zero_shift = shift[0] == 0.0 && shift[1] == 0.0 && shift[2] == 0.0;
          // A bead's own image counts once per ± pair: keep the lexicographically positive.
          const bool positive_shift =
            shift[0] > 0.0 || (shift[0] == 0.0 && (shift[1] > 0.0 || (shift[1] == 0.0 && shift[2] > 0.0)));
          // A cell's beads are in ascending index: start at the first j ≥ i.
          const std::uint32_t *first = cell_beads.data() + cell_begin[c], *last = cell_beads.data() + cell_begin[c + 1];
          for (const std::uint32_t *k = std::lower_bound(first, last,
                                                         static_cast<std::uint32_t>(i));
               k < last; ++k)
          {
            const std::uint32_t j = *k;
            if (j == i && (zero_shift || !positive_shift))
              continue;
            double r2 = 0.0;
            for (int d = 0; d < 3; ++d)
            {
              const double r = xw[3 * j + d] + shift[d] - xw[3 * i + d];
              r2 += r * r;
            }
            if (r2 < r2max && (!reach.radius || r2 < pair_reach2(i, j)))
              emit(j, shift);
          }
        }
  };

  collect_pairs(n, for_each_neighbour, xw.data(), coord, 512, pairs_, blocks_);

  build_incidence(n, coord);
}

void MagneticNeighbourList::set_pairs(std::size_t n, const double *x, const double *y,
                                      const double *z, const std::array<double, 3> &box,
                                      double list_radius, std::vector<Pair> &pairs)
{
  list_radius_ = list_radius;
  box_ = box;
  pairs_.swap(pairs);
  pairs.clear();
  const double *coord[3] = {x, y, z};
  build_incidence(n, coord);
}

void MagneticNeighbourList::clear()
{
  built_ = false;
  list_radius_ = 0.0;
  box_ = {0.0, 0.0, 0.0};
  x_ref_.clear();
  pairs_.clear();
  incident_begin_.clear();
  incident_end_.clear();
  incident_pair_.clear();
  incident_first_.clear();
}

void MagneticNeighbourList::build_incidence(std::size_t n, const double *const coord[3])
{
  build_pair_incidence(n);
  x_ref_.resize(3 * n);
  for (std::size_t b = 0; b < n; ++b)
    for (int d = 0; d < 3; ++d)
      x_ref_[3 * b + d] = coord[d][b];
  built_ = true;
}

bool MagneticNeighbourList::append(std::size_t n, const double *x, const double *y, const double *z,
                                   const std::vector<Pair> &more)
{
  const std::size_t first = particle_count();
  const std::size_t first_pair = pairs_.size();
  pairs_.insert(pairs_.end(), more.begin(), more.end());
  const bool kept = append_incidence(first, n, first_pair);
  if (!kept)
  {
    build_pair_incidence(n);
    ++relayouts_;
  }
  const double *coord[3] = {x, y, z};
  x_ref_.resize(3 * n);
  for (std::size_t b = first; b < n; ++b)
    for (int d = 0; d < 3; ++d)
      x_ref_[3 * b + d] = coord[d][b];
  return kept;
}

// The pairs from first_pair on into the rows' spare slots (the beads from first_bead on get
// rows after the last one), in pair order: each row stays in increasing pair order, as
// build_pair_incidence() would lay it out. Nothing is written unless every new entry fits.
bool MagneticNeighbourList::append_incidence(std::size_t first_bead, std::size_t n, std::size_t first_pair)
{
  if (incident_end_.size() != first_bead || incident_begin_.size() != first_bead + 1)
    return false;
  const std::size_t np = pairs_.size();
  fill_.assign(n, 0); // new entries per bead
  for (std::size_t k = first_pair; k < np; ++k)
  {
    ++fill_[pairs_[k].i];
    ++fill_[pairs_[k].j];
  }
  const auto fits = [&](std::uint32_t b) {
    return b >= first_bead || incident_end_[b] + fill_[b] <= incident_begin_[b + 1];
  };
  for (std::size_t k = first_pair; k < np; ++k)
    if (!fits(pairs_[k].i) || !fits(pairs_[k].j))
      return false;
  std::size_t at = incident_begin_[first_bead];
  incident_begin_.resize(n + 1);
  incident_end_.resize(n);
  for (std::size_t b = first_bead; b < n; ++b)
  {
    incident_begin_[b] = incident_end_[b] = at;
    at += fill_[b] + spare_slots(fill_[b]);
  }
  incident_begin_[n] = at;
  incident_pair_.resize(at);
  incident_first_.resize(at);
  for (std::size_t k = first_pair; k < np; ++k)
  {
    const std::size_t qi = incident_end_[pairs_[k].i]++; // (i before j: a self-image pair's order)
    incident_pair_[qi] = static_cast<std::uint32_t>(k);
    incident_first_[qi] = 1;
    const std::size_t qj = incident_end_[pairs_[k].j]++;
    incident_pair_[qj] = static_cast<std::uint32_t>(k);
    incident_first_[qj] = 0;
  }
  return true;
}

void MagneticNeighbourList::build_pair_incidence(std::size_t n)
{
  // Incidence (CSR), in increasing pair order for every bead: a counting sort of the pair
  // ends by bead. Each thread of the team (one for a small list) takes a contiguous range of
  // pairs and counts its ends per bead; a bead's entries are then laid out range after range,
  // each range in pair order, so the result is the same on any number of threads. (Serial,
  // this was ~3 % of a full-roller run's CPU time, on one thread while the other waited: a
  // rebuild renews the incidence of every pair; an admission only appends, see append().)
  const std::size_t np = pairs_.size();
  incident_begin_.assign(n + 1, 0);
  incident_end_.resize(n);
  constexpr std::size_t parallel_pairs = 65536; // (below it a team costs more than it saves)
  const int wanted = np >= parallel_pairs ? omp_get_max_threads() : 1;
#pragma omp parallel num_threads(wanted)
  {
    const std::size_t threads = static_cast<std::size_t>(omp_get_num_threads());
    const std::size_t t = static_cast<std::size_t>(omp_get_thread_num());
#pragma omp single
    fill_.assign(threads * n, 0); // (the implicit barrier publishes it)
    const std::size_t k0 = np * t / threads, k1 = np * (t + 1) / threads;
    std::size_t *mine = fill_.data() + t * n;
    for (std::size_t k = k0; k < k1; ++k)
    {
      ++mine[pairs_[k].i];
      ++mine[pairs_[k].j];
    }
#pragma omp barrier
#pragma omp single
    {
      // Each range's first slot per bead: after the bead's earlier entries and those of the
      // ranges before it; then the row's spare slots.
      std::size_t at = 0;
      for (std::size_t b = 0; b < n; ++b)
      {
        incident_begin_[b] = at;
        for (std::size_t r = 0; r < threads; ++r)
        {
          const std::size_t count = fill_[r * n + b];
          fill_[r * n + b] = at;
          at += count;
        }
        incident_end_[b] = at;
        at += spare_slots(at - incident_begin_[b]);
      }
      incident_begin_[n] = at;
      incident_pair_.resize(at);
      incident_first_.resize(at);
    }
    for (std::size_t k = k0; k < k1; ++k)
    {
      const Pair &p = pairs_[k];
      incident_pair_[mine[p.i]] = static_cast<std::uint32_t>(k);
      incident_first_[mine[p.i]++] = 1;
      incident_pair_[mine[p.j]] = static_cast<std::uint32_t>(k);
      incident_first_[mine[p.j]++] = 0;
    }
  }
}

double MagneticNeighbourList::max_displacement(std::size_t n, const double *x,
                                               const double *y, const double *z) const
{
  if (!built_ || n != particle_count())
    return std::numeric_limits<double>::infinity();
  double max2 = 0.0;
#pragma omp parallel for reduction(max : max2) if (n >= 512)
  for (long b = 0; b < static_cast<long>(n); ++b)
  {
    const double dx = x[b] - x_ref_[3 * b], dy = y[b] - x_ref_[3 * b + 1],
                 dz = z[b] - x_ref_[3 * b + 2];
    max2 = std::max(max2, dx * dx + dy * dy + dz * dz);
  }
  return std::sqrt(max2);
}

// ---------------------------------------------------------------------------------------
// Restart: the list as built (its pairs refer to the reference positions, which decide when
// it expires), so that a restarted run rebuilds it at the same step as the run that wrote it.

void MagneticNeighbourList::write_state(StateOut &out) const
{
  out.put<std::uint8_t>(built_);
  out.put(list_radius_);
  out.put(box_);
  out.put_array(x_ref_);
  out.put_array(pairs_);
  // The incidence without its spare slots (the layout is the list's own business; the
  // entries, row by row, are what a restart must have).
  const std::size_t n = incident_end_.size();
  std::vector<std::size_t> begin(incident_begin_.empty() ? 0 : n + 1, 0);
  std::vector<std::uint32_t> pair;
  std::vector<std::uint8_t> first;
  for (std::size_t b = 0; b < n; ++b)
  {
    pair.insert(pair.end(), incident_pair_.begin() + incident_begin_[b], incident_pair_.begin() + incident_end_[b]);
    first.insert(first.end(), incident_first_.begin() + incident_begin_[b], incident_first_.begin() + incident_end_[b]);
    begin[b + 1] = pair.size();
  }
  out.put_array(begin);
  out.put_array(pair);
  out.put_array(first);
}

void MagneticNeighbourList::read_state(StateIn &in)
{
  built_ = in.get<std::uint8_t>() != 0;
  list_radius_ = in.get<double>();
  box_ = in.get<std::array<double, 3>>();
  in.get_array(x_ref_);
  in.get_array(pairs_);
  std::vector<std::size_t> begin;
  std::vector<std::uint32_t> pair;
  std::vector<std::uint8_t> first;
  in.get_array(begin);
  in.get_array(pair);
  in.get_array(first);
  if (!begin.empty() && (begin.front() != 0 || begin.back() != pair.size() || first.size() != pair.size() ||
                         !std::is_sorted(begin.begin(), begin.end())))
    in.fail("is corrupt (magnetic neighbour list incidence)");
  // Laid out again with every row's spare slots.
  const std::size_t n = begin.empty() ? 0 : begin.size() - 1;
  incident_begin_.assign(begin.empty() ? 0 : n + 1, 0);
  incident_end_.resize(n);
  incident_pair_.clear();
  incident_first_.clear();
  for (std::size_t b = 0; b < n; ++b)
  {
    incident_begin_[b] = incident_pair_.size();
    incident_pair_.insert(incident_pair_.end(), pair.begin() + begin[b], pair.begin() + begin[b + 1]);
    incident_first_.insert(incident_first_.end(), first.begin() + begin[b], first.begin() + begin[b + 1]);
    incident_end_[b] = incident_pair_.size();
    const std::size_t spare = spare_slots(begin[b + 1] - begin[b]);
    incident_pair_.resize(incident_pair_.size() + spare, 0);
    incident_first_.resize(incident_first_.size() + spare, 0);
  }
  if (n > 0)
    incident_begin_[n] = incident_pair_.size();
}

} // namespace magbrush::magnetics
