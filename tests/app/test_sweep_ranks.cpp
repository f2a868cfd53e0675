// The deal of a sweep's points to MPI ranks (app/sweep_ranks.h): every point on exactly one
// rank, rounds of K dealt forwards then backwards, so that a study whose cost grows along its
// values loads the ranks alike.
#include "app/sweep_ranks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

using magbrush::rank_of_point;

TEST(SweepRanks, TwoRanksTakeTheRoundsForwardsThenBackwards)
{
  const std::vector<int> expected = {0, 1, 1, 0, 0, 1, 1, 0};
  for (std::size_t n = 0; n < expected.size(); ++n)
    EXPECT_EQ(rank_of_point(n, 2), expected[n]) << "point " << n;
}

TEST(SweepRanks, EveryRankGetsOnePointPerRound)
{
  for (int ranks = 1; ranks <= 5; ++ranks)
    for (std::size_t round = 0; round < 4; ++round)
    {
      std::vector<int> taken(static_cast<std::size_t>(ranks), 0);
      for (std::size_t place = 0; place < static_cast<std::size_t>(ranks); ++place)
      {
        const int rank = rank_of_point(round * static_cast<std::size_t>(ranks) + place, ranks);
        ASSERT_GE(rank, 0);
        ASSERT_LT(rank, ranks);
        ++taken[static_cast<std::size_t>(rank)];
      }
      EXPECT_TRUE(std::all_of(taken.begin(), taken.end(), [](int t) { return t == 1; }))
          << ranks << " ranks, round " << round;
    }
}

TEST(SweepRanks, CostGrowingAlongTheValuesIsShared)
{
  // Four points whose cost grows with the index (the 30 ms DMA study's DEM times, 376, 442,
  // 521 and 591 s): dealt i mod 2 the ranks carry 897 and 1033 s, dealt back and forth 967 and
  // 963 s.
  const double cost[] = {376, 442, 521, 591};
  double load[2] = {0, 0};
  for (std::size_t n = 0; n < 4; ++n)
    load[rank_of_point(n, 2)] += cost[n];
  EXPECT_DOUBLE_EQ(load[0], 967);
  EXPECT_DOUBLE_EQ(load[1], 963);
}
