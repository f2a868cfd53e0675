// The two-sphere correction's own pair list after an admission (TwoSphereCorrection::admit:
// newcomers appended without a rebuild) holds exactly the pairs and periodic images that a
// fresh build over all beads lists — also in a slab narrower than the list's reach, where a
// bead meets several images of a neighbour and images of itself (the full roller's 0.12 mm
// slab against a reach of ~0.124 mm). The admission used to refuse such a slab outright, so
// that in the full roller every newcomer waited for the next full evaluation and most steps
// left the engine's thread team to try again.
#include "magnetics/two_sphere_correction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <tuple>
#include <vector>

using namespace magbrush::magnetics;

namespace {

// A listed pair as (lower index, higher index, image in periods): the list stores
// r = x_j − x_i + shift with raw (unwrapped) positions, so a shift is a whole number of
// periods; the same pair seen from the other bead has the opposite shift.
using PairKey = std::tuple<std::uint32_t, std::uint32_t, long, long, long>;

std::set<PairKey> pair_set(const MagneticNeighbourList &list, const std::array<double, 3> &box)
{
  std::set<PairKey> keys;
  for (const MagneticNeighbourList::Pair &p : list.pairs())
  {
    long s[3];
    for (int d = 0; d < 3; ++d)
    {
      const double periods = box[d] > 0.0 ? p.shift[d] / box[d] : p.shift[d];
      s[d] = std::lround(periods);
      EXPECT_NEAR(periods, static_cast<double>(s[d]), 1e-9) << "a shift that is not a whole period";
    }
    const bool flip = p.j < p.i;
    const std::uint32_t i = flip ? p.j : p.i, j = flip ? p.i : p.j;
    const int sign = flip ? -1 : 1;
    auto inserted = keys.insert({i, j, sign * s[0], sign * s[1], sign * s[2]});
    EXPECT_TRUE(inserted.second) << "pair " << i << "-" << j << " listed twice with the same image";
  }
  return keys;
}

struct Beads
{
  std::vector<double> x, y, z, radius, mu_r;
  BeadArrays view(std::size_t n) const { return {n, x.data(), y.data(), z.data(), radius.data(), mu_r.data(), nullptr}; }
};

// `count` beads of one radius in a box periodic along x and z (open along y), at unwrapped
// positions: a third of them displaced by −3 … +3 periods, as the magnetics keep a bead's
// image nearest its last position while the engine wraps it.
Beads random_beads(std::size_t count, const std::array<double, 3> &box, double height, double radius, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> periods(-3, 3);
  Beads b;
  for (std::size_t k = 0; k < count; ++k)
  {
    const bool displaced = k % 3 == 0;
    b.x.push_back(box[0] * (u(rng) + (displaced ? periods(rng) : 0)));
    b.y.push_back(height * u(rng));
    b.z.push_back(box[2] * (u(rng) + (displaced ? periods(rng) : 0)));
    b.radius.push_back(radius);
    b.mu_r.push_back(3.9);
  }
  return b;
}

// Admits the last `newcomers` of the beads into a list built over the others and compares the
// pair set with a list built over all of them.
void expect_admission_equals_fresh_build(const std::array<double, 3> &box, std::size_t count, std::size_t newcomers,
                                         double radius, unsigned seed)
{
  MagneticSettings settings; // the defaults a case runs: switch_end 5 mean radii, skin 0.3 d
  const Beads beads = random_beads(count, box, 0.4e-3, radius, seed);
  const std::size_t first = count - newcomers;

  TwoSphereCorrection admitted(settings, box);
  admitted.refresh_list(beads.view(first));
  ASSERT_TRUE(admitted.can_admit(beads.view(count), first));
  ASSERT_TRUE(admitted.admit(beads.view(count), first));

  TwoSphereCorrection fresh(settings, box);
  fresh.refresh_list(beads.view(count));

  const std::set<PairKey> a = pair_set(admitted.list(), box), f = pair_set(fresh.list(), box);
  EXPECT_EQ(admitted.list().size(), fresh.list().size());
  EXPECT_EQ(a, f);
  // The scene must exercise what it is about: pairs across several images, and own images.
  long self = 0, far_images = 0;
  for (const PairKey &k : f)
  {
    self += std::get<0>(k) == std::get<1>(k);
    far_images += std::abs(std::get<4>(k)) >= 2 || std::abs(std::get<2>(k)) >= 2;
  }
  std::printf("box %.3g x %.3g mm, list radius %.3g mm: %zu pairs (%ld of a bead with its own image, %ld across "
              "two or more periods)\n",
              box[0] * 1e3, box[2] * 1e3, fresh.list().list_radius() * 1e3, f.size(), self, far_images);
}

} // namespace

// A 0.06 mm slab (1.7 diameters), narrower than the reach: several images of every neighbour
// and of the bead itself.
TEST(TwoSphereAdmission, AdmittedPairsEqualAFreshBuildInASlabNarrowerThanTheReach)
{
  const double radius = 17.5e-6; // Kweon's 35 um carriers; reach 5 radii + 0.3 d = 98 um
  expect_admission_equals_fresh_build({0.5e-3, 0.0, 0.06e-3}, 400, 12, radius, 1);
  // The full roller's slab: 0.12 mm, just above the reach (images ±1 only).
  expect_admission_equals_fresh_build({0.5e-3, 0.0, 0.12e-3}, 400, 12, radius, 2);
}

// A wide box (every pair within one period): the case the admission handled before.
TEST(TwoSphereAdmission, AdmittedPairsEqualAFreshBuildInAWideBox)
{
  expect_admission_equals_fresh_build({1.0e-3, 0.0, 1.0e-3}, 600, 20, 30e-6, 3);
}
