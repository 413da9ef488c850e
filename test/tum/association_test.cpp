// Nearest association of two time-stamp streams (drivers/tum/association.h): every item of a
// with an item of b within the limit is kept, with its nearest.

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>

#include "drivers/tum/association.h"

namespace kestrel::tum {
namespace {

std::vector<std::pair<size_t, size_t>> pairs_of(const Association& a) {
  std::vector<std::pair<size_t, size_t>> out;
  for (const auto& p : a.pairs) out.emplace_back(p.a, p.b);
  return out;
}

using Pairs = std::vector<std::pair<size_t, size_t>>;

TEST(Association, PairsWithinTheLimitInclusive) {
  const Association a = associate({0, 100, 200}, {20, 121, 300}, 20);
  EXPECT_EQ(pairs_of(a), (Pairs{{0, 0}}));  // 121 is 21 away from 100; 300 is 100 from 200
  EXPECT_EQ(a.unmatched_a, 2u);
  EXPECT_EQ(a.unused_b, 2u);
}

TEST(Association, ADepthFrameMayServeTwoColourFrames) {
  // Both a=0 and a=10 want b=6: both keep it (one-to-one, a=0 would be lost).
  const Association a = associate({0, 10}, {6}, 10);
  EXPECT_EQ(pairs_of(a), (Pairs{{0, 0}, {1, 0}}));
  EXPECT_EQ(a.unmatched_a, 0u);
  EXPECT_EQ(a.unused_b, 0u);
  EXPECT_EQ(a.shared_b, 1u);
}

TEST(Association, EqualDifferencesGoToTheEarlierPartner) {
  const Association a = associate({10}, {0, 20}, 10);
  EXPECT_EQ(pairs_of(a), (Pairs{{0, 0}}));
  EXPECT_EQ(a.unused_b, 1u);
}

TEST(Association, EachTakesItsNearest) {
  // a=0 is nearest to b=1, a=3 to b=2; a=4 also to b=2 (2 away), not the free b=1 (3 away).
  const Association a = associate({0, 3, 4}, {1, 2}, 5);
  EXPECT_EQ(pairs_of(a), (Pairs{{0, 0}, {1, 1}, {2, 1}}));
  EXPECT_EQ(a.shared_b, 1u);
}

TEST(Association, TumFreiburg1XyzExcerpt) {
  // RGB and depth stamps of fr1_xyz around 1305031105.6 s (us after 1305031105.5): the RGB
  // frame at .675166, which TUM's one-to-one associate.py leaves without depth (its nearest,
  // .659104, went to .643273, and .698235 is 23 ms away), shares .659104 (16 ms); the depth
  // frame at .627128 is nearest to no RGB frame.
  const std::vector<int64_t> rgb = {43282, 75449, 111378, 143273, 175166, 211309};
  const std::vector<int64_t> depth = {29583, 62109, 97193, 127128, 159104, 198235};
  const Association a = associate(rgb, depth, 20000);
  EXPECT_EQ(pairs_of(a), (Pairs{{0, 0}, {1, 1}, {2, 2}, {3, 4}, {4, 4}, {5, 5}}));
  EXPECT_EQ(a.unmatched_a, 0u);
  EXPECT_EQ(a.unused_b, 1u);
  EXPECT_EQ(a.shared_b, 1u);
}

TEST(Association, EmptyInputs) {
  EXPECT_TRUE(associate({}, {1, 2}, 10).pairs.empty());
  EXPECT_EQ(associate({}, {1, 2}, 10).unused_b, 2u);
  EXPECT_EQ(associate({1, 2}, {}, 10).unmatched_a, 2u);
}

TEST(Association, RejectsUnsortedInputAndNegativeLimit) {
  EXPECT_THROW(associate({2, 1}, {1}, 10), std::invalid_argument);
  EXPECT_THROW(associate({1}, {1, 1}, 10), std::invalid_argument);
  EXPECT_THROW(associate({1}, {1}, -1), std::invalid_argument);
}

// On random streams, against the rule by brute force: an item of a is paired exactly when
// some b lies within the limit, and then with the nearest (the earlier on a tie); the counts
// add up.
TEST(Association, RandomStreamsPairEachWithItsNearestWithinTheLimit) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<int64_t> ta, tb;
    int64_t t = 0;
    for (int i = 0; i < 40; ++i) ta.push_back(t += 1 + static_cast<int64_t>(rng() % 50));
    t = 0;
    for (int i = 0; i < 40; ++i) tb.push_back(t += 1 + static_cast<int64_t>(rng() % 50));
    const int64_t limit = 5 + static_cast<int64_t>(rng() % 30);
    const Association a = associate(ta, tb, limit);

    Pairs expected;
    std::vector<int> uses(tb.size(), 0);
    for (size_t i = 0; i < ta.size(); ++i) {
      std::optional<size_t> best;
      for (size_t j = 0; j < tb.size(); ++j)
        if (std::llabs(ta[i] - tb[j]) <= limit && (!best || std::llabs(ta[i] - tb[j]) < std::llabs(ta[i] - tb[*best])))
          best = j;
      if (!best) continue;
      expected.emplace_back(i, *best);
      ++uses[*best];
    }
    ASSERT_EQ(pairs_of(a), expected) << "trial " << trial;
    EXPECT_EQ(a.unmatched_a + a.pairs.size(), ta.size());
    EXPECT_EQ(a.unused_b, static_cast<size_t>(std::count(uses.begin(), uses.end(), 0)));
    EXPECT_EQ(a.shared_b, static_cast<size_t>(std::count_if(uses.begin(), uses.end(), [](int u) { return u > 1; })));
  }
}

}  // namespace
}  // namespace kestrel::tum
