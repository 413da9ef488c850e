// The history's ring: order kept across wrap-around and growth, slots reused.

#include <gtest/gtest.h>

#include "estimator/ring.h"

namespace kestrel::estimator {
namespace {

TEST(Ring, KeepsOrderAcrossWrapAroundAndGrowth) {
  Ring<int> r;
  int next = 0, oldest = 0;
  // Push 3, drop 2, many times: the ring wraps around its 16 slots, then grows.
  for (int round = 0; round < 40; ++round) {
    for (int k = 0; k < 3; ++k) r.push_back() = next++;
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(r.front(), oldest++);
      r.pop_front();
    }
    ASSERT_EQ(r.size(), static_cast<size_t>(next - oldest));
    for (size_t i = 0; i < r.size(); ++i) ASSERT_EQ(r[i], oldest + static_cast<int>(i));
    EXPECT_EQ(r.back(), next - 1);
  }
  EXPECT_EQ(r.partition_point([&](int v) { return v < oldest + 5; }), 5u);
  EXPECT_EQ(r.partition_point([](int) { return false; }), 0u);
  EXPECT_EQ(r.partition_point([](int) { return true; }), r.size());
  r.pop_back();
  EXPECT_EQ(r.back(), next - 2);
  r.clear();
  EXPECT_TRUE(r.empty());
}

TEST(Ring, APushReusesTheSlotDroppedBefore) {
  Ring<int> r;
  for (int k = 0; k < 16; ++k) r.push_back() = k;
  const int* dropped = &r.front();
  r.pop_front();
  int& reused = r.push_back();       // full again, no growth: the same slot
  EXPECT_EQ(&reused, dropped);
  EXPECT_EQ(reused, 0);  // stale contents: the caller overwrites them
}

}  // namespace
}  // namespace kestrel::estimator
