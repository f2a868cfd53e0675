// The magnetic neighbour list against brute force over all pairs and images; its incidence
// after appends; the near pairs' rows against the same sums read through the list.
#include "magnetics/magnetic_neighbour_list.h"
#include "magnetics/near_pairs.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <set>
#include <iterator>
#include <tuple>
#include <vector>

using namespace magbrush::magnetics;

namespace {
using Key = std::tuple<unsigned, unsigned, long, long, long>; // i, j, image counts

std::set<Key> brute_force(const std::vector<double> &x, const std::vector<double> &y,
                          const std::vector<double> &z, const std::array<double, 3> &box,
                          double rc)
{
  std::set<Key> out;
  long reach[3];
  for (int d = 0; d < 3; ++d)
    reach[d] = box[d] > 0 ? static_cast<long>(std::ceil((rc + 2.0) / box[d])) + 1 : 0; // raw positions spread over 1.7
  const std::size_t n = x.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i; j < n; ++j)
      for (long a = -reach[0]; a <= reach[0]; ++a)
        for (long b = -reach[1]; b <= reach[1]; ++b)
          for (long c = -reach[2]; c <= reach[2]; ++c)
          {
            if (i == j && !(a > 0 || (a == 0 && (b > 0 || (b == 0 && c > 0)))))
              continue;
            const double r[3] = {x[j] - x[i] + a * box[0], y[j] - y[i] + b * box[1],
                                 z[j] - z[i] + c * box[2]};
            if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < rc * rc)
              out.insert({unsigned(i), unsigned(j), a, b, c});
          }
  return out;
}
} // namespace

TEST(MagneticNeighbourList, MatchesBruteForce)
{
  std::mt19937_64 rng(42);
  // Open box; z-periodic with cutoff beyond half the box; fully periodic with cutoff larger
  // than the box (several images of every neighbour and of the bead itself).
  const std::vector<std::pair<std::array<double, 3>, double>> cases = {
    {{0.0, 0.0, 0.0}, 0.25}, {{0.0, 0.0, 1.0}, 0.6}, {{0.7, 0.8, 0.9}, 1.3}, {{1.0, 0.0, 1.0}, 0.3}};
  for (const auto &[box, rc] : cases)
  {
    std::uniform_real_distribution<double> u(-0.3, 1.4); // positions outside the box on purpose
    const std::size_t n = 60;
    std::vector<double> x(n), y(n), z(n);
    for (std::size_t k = 0; k < n; ++k)
    {
      x[k] = u(rng);
      y[k] = u(rng);
      z[k] = u(rng);
    }
    MagneticNeighbourList list;
    list.build(n, x.data(), y.data(), z.data(), box, rc);
    const std::set<Key> expected = brute_force(x, y, z, box, rc);
    std::set<Key> found;
    for (const auto &p : list.pairs())
    {
      long img[3];
      for (int d = 0; d < 3; ++d)
        img[d] = box[d] > 0 ? std::lround(p.shift[d] / box[d]) : 0;
      EXPECT_TRUE(found.insert({p.i, p.j, img[0], img[1], img[2]}).second) << "duplicate pair";
    }
    std::vector<Key> missing, extra;
    std::set_difference(expected.begin(), expected.end(), found.begin(), found.end(),
                        std::back_inserter(missing));
    std::set_difference(found.begin(), found.end(), expected.begin(), expected.end(),
                        std::back_inserter(extra));
    EXPECT_TRUE(missing.empty() && extra.empty())
      << "box " << box[0] << " " << box[1] << " " << box[2] << " rc " << rc << ": "
      << missing.size() << " pairs missing, " << extra.size() << " extra; first missing "
      << (missing.empty() ? -1 : long(std::get<0>(missing[0]))) << "-"
      << (missing.empty() ? -1 : long(std::get<1>(missing[0]))) << " image "
      << (missing.empty() ? 0 : std::get<2>(missing[0])) << ","
      << (missing.empty() ? 0 : std::get<3>(missing[0])) << ","
      << (missing.empty() ? 0 : std::get<4>(missing[0]));
    // Incidence: every pair appears once as i and once as j.
    std::size_t total = 0;
    for (std::size_t b = 0; b < n; ++b)
      total += list.incident_end()[b] - list.incident_begin()[b];
    EXPECT_EQ(total, 2 * list.size());
    // Displacement bookkeeping: no move, then a wrap-sized jump.
    EXPECT_EQ(list.max_displacement(n, x.data(), y.data(), z.data()), 0.0);
    z[3] += 1.0;
    EXPECT_NEAR(list.max_displacement(n, x.data(), y.data(), z.data()), 1.0, 1e-12);
  }
}

// The incidence of a large list (built by a team when there are ≥ 65,536 pairs) is the serial
// one on any number of threads, and it is right: each bead's entries name exactly the pairs
// that touch it, in increasing pair order, with the end (i or j) it is; a self-image pair
// twice, first as i.
TEST(MagneticNeighbourList, IncidenceOfALargeListIsTheSameOnAnyThreadCount)
{
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t n = 3000;
  std::vector<double> x(n), y(n), z(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    x[k] = u(rng);
    y[k] = 0.4 * u(rng);
    z[k] = 0.05 * u(rng);
  }
  const std::array<double, 3> box = {1.0, 0.0, 0.05}; // (z: a slab narrower than the radius)
  struct Incidence
  {
    std::vector<std::size_t> begin, end;
    std::vector<std::uint32_t> pair;
    std::vector<std::uint8_t> first;
  };
  Incidence by_threads[3];
  const int max_threads = omp_get_max_threads();
  for (int threads : {1, 2, 3})
  {
    omp_set_num_threads(threads);
    MagneticNeighbourList list;
    list.build(n, x.data(), y.data(), z.data(), box, 0.12);
    ASSERT_GE(list.size(), 65536u) << "the list must be large enough for the team";
    by_threads[threads - 1] = {list.incident_begin(), list.incident_end(), list.incident_pair(), list.incident_first()};
    if (threads > 1)
      continue;
    // The serial incidence checked directly against the pairs.
    const auto &pairs = list.pairs();
    std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> expected(n);
    for (std::size_t k = 0; k < pairs.size(); ++k)
    {
      expected[pairs[k].i].push_back({static_cast<std::uint32_t>(k), 1});
      expected[pairs[k].j].push_back({static_cast<std::uint32_t>(k), 0});
    }
    for (std::size_t b = 0; b < n; ++b)
    {
      std::vector<std::pair<std::uint32_t, std::uint8_t>> found;
      for (std::size_t q = list.incident_begin()[b]; q < list.incident_end()[b]; ++q)
        found.push_back({list.incident_pair()[q], list.incident_first()[q]});
      ASSERT_EQ(found, expected[b]) << "bead " << b;
    }
  }
  omp_set_num_threads(max_threads);
  for (int t : {1, 2})
  {
    EXPECT_EQ(by_threads[t].begin, by_threads[0].begin) << t + 1 << " threads";
    EXPECT_EQ(by_threads[t].end, by_threads[0].end) << t + 1 << " threads";
    EXPECT_EQ(by_threads[t].pair, by_threads[0].pair) << t + 1 << " threads";
    EXPECT_EQ(by_threads[t].first, by_threads[0].first) << t + 1 << " threads";
  }
}

namespace {
// Every row of the list's incidence, as (pair, end) in slot order.
std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> rows_of(const MagneticNeighbourList &list)
{
  std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> rows(list.incident_end().size());
  for (std::size_t b = 0; b < rows.size(); ++b)
    for (std::size_t q = list.incident_begin()[b]; q < list.incident_end()[b]; ++q)
      rows[b].push_back({list.incident_pair()[q], list.incident_first()[q]});
  return rows;
}

// The rows a build lays out for the list's pairs: each bead's pairs in increasing pair order.
std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> expected_rows(const MagneticNeighbourList &list,
                                                                               std::size_t n)
{
  std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> rows(n);
  for (std::size_t k = 0; k < list.pairs().size(); ++k)
  {
    rows[list.pairs()[k].i].push_back({static_cast<std::uint32_t>(k), 1});
    rows[list.pairs()[k].j].push_back({static_cast<std::uint32_t>(k), 0});
  }
  return rows;
}
} // namespace

// Beads appended in batches (a fed scene's admissions): the new pairs go into the rows'
// spare slots without moving an earlier row, and the rows are those a build of the same
// pairs gives; a batch crowding round one bead overflows its row and the incidence is laid
// out afresh, with the same rows. The checkpoint keeps the rows.
TEST(MagneticNeighbourList, AppendedBeadsJoinTheRowsInPairOrderInPlaceOrLaidOutAfresh)
{
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double rc = 0.15;
  std::vector<double> x, y, z;
  auto add_bead = [&](double cx, double cy, double spread) {
    x.push_back(cx + spread * (u(rng) - 0.5));
    y.push_back(cy + spread * (u(rng) - 0.5));
    z.push_back(0.05 * u(rng));
  };
  for (int k = 0; k < 400; ++k)
    add_bead(0.5, 0.5, 1.0);
  MagneticNeighbourList list;
  list.build(x.size(), x.data(), y.data(), z.data(), {0.0, 0.0, 0.0}, rc);
  const std::size_t total_after_build = list.incident_begin().back();
  int in_place = 0, afresh = 0;
  for (int batch = 0; batch < 8; ++batch)
  {
    const std::size_t first = x.size();
    // Batches of 3 spread over the box, then one of 60 crowding round the box's centre.
    const bool crowd = batch == 6;
    for (int k = 0; k < (crowd ? 60 : 3); ++k)
      add_bead(crowd ? 0.5 : u(rng), crowd ? 0.5 : u(rng), crowd ? 0.02 : 0.0);
    std::vector<MagneticNeighbourList::Pair> more;
    for (std::size_t j = first; j < x.size(); ++j)
      for (std::size_t i = 0; i < j; ++i)
      {
        const double r[3] = {x[j] - x[i], y[j] - y[i], z[j] - z[i]};
        if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < rc * rc)
          more.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), {0.0, 0.0, 0.0}});
      }
    const std::vector<std::size_t> begin_before(list.incident_begin().begin(), list.incident_begin().end() - 1);
    const bool kept = list.append(x.size(), x.data(), y.data(), z.data(), more);
    (kept ? in_place : afresh) += 1;
    ASSERT_EQ(rows_of(list), expected_rows(list, x.size())) << "batch " << batch;
    if (kept) // no earlier row moved
    {
      EXPECT_TRUE(std::equal(begin_before.begin(), begin_before.end(), list.incident_begin().begin()));
    }
    EXPECT_EQ(list.particle_count(), x.size());
  }
  EXPECT_GE(in_place, 5);
  EXPECT_GE(afresh, 1) << "the crowded batch must overflow a row";
  EXPECT_EQ(list.relayouts(), afresh);
  EXPECT_GT(list.incident_begin().back(), total_after_build);

  // Checkpoint: the same rows (laid out with fresh spare slots), and appends go on from there.
  magbrush::MemoryStateOut out;
  list.write_state(out);
  magbrush::MemoryStateIn in(out.bytes(), "test list");
  MagneticNeighbourList restored;
  restored.read_state(in);
  EXPECT_EQ(rows_of(restored), rows_of(list));
  EXPECT_EQ(restored.pairs().size(), list.pairs().size());
  EXPECT_EQ(in.remaining(), 0u);
}

// The sweeps' partner field through the packed rows and through the list (the rows out of
// date after an admission) is the same to the bit, before and after beads are appended; the
// rows are out of date after an append until they are built again.
TEST(NearPairs, RowFieldThroughTheListIsTheRowsBitForBit)
{
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> x, y, z, radius, mu_r;
  auto add_bead = [&] {
    x.push_back(u(rng));
    y.push_back(0.3 * u(rng));
    z.push_back(0.05 * u(rng));
    radius.push_back(0.01);
    mu_r.push_back(4.0);
  };
  for (int k = 0; k < 300; ++k)
    add_bead();
  const std::array<double, 3> box = {1.0, 0.0, 0.05};
  const double cutoff = 0.1, radius_list = 0.12;
  NearPairs near;
  near.list().build(x.size(), x.data(), y.data(), z.data(), box, radius_list);
  auto beads = [&] {
    return BeadArrays{x.size(), x.data(), y.data(), z.data(), radius.data(), mu_r.data(), nullptr};
  };
  near.evaluate_tensors(beads(), cutoff);
  near.build_rows();
  ASSERT_TRUE(near.has_rows());
  auto check_same = [&](const char *when) {
    std::vector<double> p(3 * x.size());
    for (double &v : p)
      v = u(rng) - 0.5;
    for (std::size_t b = 0; b < x.size(); ++b)
    {
      double rows[3] = {0.25, -0.5, 1.0}, list[3] = {0.25, -0.5, 1.0};
      if (near.has_rows())
        near.add_row_field(b, p, rows);
      near.add_row_field_through_list(b, p, list);
      if (near.has_rows())
      {
        ASSERT_EQ(0, std::memcmp(rows, list, sizeof rows)) << when << ", bead " << b;
      }
    }
  };
  check_same("built");
  const std::size_t first = x.size(), first_pair = near.pairs().size();
  for (int k = 0; k < 20; ++k)
    add_bead();
  std::vector<MagneticNeighbourList::Pair> more;
  {
    MagneticNeighbourList all;
    all.build(x.size(), x.data(), y.data(), z.data(), box, radius_list);
    for (const auto &p : all.pairs())
      if (p.i >= first || p.j >= first)
        more.push_back(p);
  }
  near.list().append(x.size(), x.data(), y.data(), z.data(), more);
  near.appended(beads(), first_pair);
  EXPECT_FALSE(near.has_rows());
  check_same("appended, rows out of date");
  near.build_rows();
  ASSERT_TRUE(near.has_rows());
  check_same("appended, rows built again");
}
