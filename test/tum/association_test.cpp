// One-to-one nearest association of two time-stamp streams (drivers/tum/association.h).

#include <gtest/gtest.h>

#include <random>
#include <set>

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

TEST(Association, ConflictGoesToTheCloserPair) {
  // Both a=0 and a=10 want b=6; a=10 is closer (4 < 6).
  const Association a = associate({0, 10}, {6}, 10);
  EXPECT_EQ(pairs_of(a), (Pairs{{1, 0}}));
  EXPECT_EQ(a.unmatched_a, 1u);
  EXPECT_EQ(a.unused_b, 0u);
}

TEST(Association, EqualDifferencesGoToTheLowerIndex) {
  const Association a = associate({0, 20}, {10}, 10);
  EXPECT_EQ(pairs_of(a), (Pairs{{0, 0}}));
}

TEST(Association, EachItemIsUsedOnce) {
  // a=0 is nearest to both b=1 and b=2; it takes b=1, and b=2 goes to a=3.
  const Association a = associate({0, 3}, {1, 2}, 5);
  EXPECT_EQ(pairs_of(a), (Pairs{{0, 0}, {1, 1}}));
}

TEST(Association, TumFreiburg1XyzExcerpt) {
  // RGB and depth stamps of fr1_xyz around 1305031105.6 s (us after 1305031105.5): the depth
  // frame at .627128 loses both RGB neighbours to closer depth frames, and the RGB frame at
  // .675166 is left without depth (its candidates are taken or 23 ms away).
  const std::vector<int64_t> rgb = {43282, 75449, 111378, 143273, 175166, 211309};
  const std::vector<int64_t> depth = {29583, 62109, 97193, 127128, 159104, 198235};
  const Association a = associate(rgb, depth, 20000);
  EXPECT_EQ(pairs_of(a), (Pairs{{0, 0}, {1, 1}, {2, 2}, {3, 4}, {5, 5}}));
  EXPECT_EQ(a.unmatched_a, 1u);
  EXPECT_EQ(a.unused_b, 1u);
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

// On random streams: one-to-one, every pair within the limit, nothing left that could still
// pair (maximal), and no pair that a closer free partner would have beaten (greedy order).
TEST(Association, RandomStreamsKeepTheGreedyInvariants) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<int64_t> ta, tb;
    int64_t t = 0;
    for (int i = 0; i < 40; ++i) ta.push_back(t += 1 + static_cast<int64_t>(rng() % 50));
    t = 0;
    for (int i = 0; i < 40; ++i) tb.push_back(t += 1 + static_cast<int64_t>(rng() % 50));
    const int64_t limit = 5 + static_cast<int64_t>(rng() % 30);
    const Association a = associate(ta, tb, limit);

    std::vector<int64_t> partner_a(ta.size(), -1), partner_b(tb.size(), -1);
    for (const auto& p : a.pairs) {
      ASSERT_EQ(partner_a[p.a], -1);
      ASSERT_EQ(partner_b[p.b], -1);
      partner_a[p.a] = static_cast<int64_t>(p.b);
      partner_b[p.b] = static_cast<int64_t>(p.a);
      ASSERT_LE(std::llabs(ta[p.a] - tb[p.b]), limit);
    }
    for (size_t i = 1; i < a.pairs.size(); ++i) ASSERT_LT(a.pairs[i - 1].a, a.pairs[i].a);
    EXPECT_EQ(a.unmatched_a + a.pairs.size(), ta.size());
    EXPECT_EQ(a.unused_b + a.pairs.size(), tb.size());
    auto diff = [&](size_t i, size_t j) { return std::llabs(ta[i] - tb[j]); };
    for (size_t i = 0; i < ta.size(); ++i) {
      for (size_t j = 0; j < tb.size(); ++j) {
        if (diff(i, j) > limit) continue;
        // Maximal: a candidate pair of two free items cannot remain.
        ASSERT_FALSE(partner_a[i] < 0 && partner_b[j] < 0) << "free pair " << i << "," << j;
        // Greedy: if i is paired farther than j is from it, j's own pair must be closer still.
        const int64_t di = partner_a[i] < 0 ? INT64_MAX : diff(i, static_cast<size_t>(partner_a[i]));
        const int64_t dj = partner_b[j] < 0 ? INT64_MAX : diff(static_cast<size_t>(partner_b[j]), j);
        ASSERT_FALSE(diff(i, j) < di && diff(i, j) < dj) << "pair " << i << "," << j << " was beaten";
      }
    }
  }
}

}  // namespace
}  // namespace kestrel::tum
