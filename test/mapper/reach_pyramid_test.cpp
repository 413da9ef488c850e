// The reach pyramid's answers equal a brute-force scan of the rectangle (exact maximum, never a
// bound below it), and KeySpace::key equals OctoMap's floor-based rule at cell edges, signs and
// the ends of the key range. The four-pixel reach masks (SSE2 where built with it) equal the
// scalar fallback and a pixel-by-pixel test. The index-only ray walk (branch-free, SSE2 where
// built with it) visits OctoMap's computeRayKeys cells.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <octomap/OcTree.h>

#include "mapper/key_space.h"
#include "mapper/ray.h"
#include "mapper/reach_mask.h"
#include "mapper/reach_pyramid.h"

namespace kestrel::mapper {
namespace {

float brute_max(const std::vector<float>& image, int cols, int i0, int i1, int j0, int j1) {
  float best = -std::numeric_limits<float>::infinity();
  for (int v = j0; v <= j1; ++v)
    for (int u = i0; u <= i1; ++u) best = std::max(best, image[static_cast<size_t>(v) * cols + u]);
  return best;
}

TEST(ReachPyramid, KnownSmallImage) {
  // 5 x 3, one large value at (3, 1).
  const std::vector<float> image = {1, 2, 3, 4, 5,  //
                                    6, 7, 8, 30, 9,  //
                                    0, 0, 0, 0, 0};
  ReachPyramid p;
  p.build(image.data(), 5, 3);
  EXPECT_EQ(p.max_over(0, 4, 0, 2), 30.0f);
  EXPECT_EQ(p.max_over(0, 2, 0, 2), 8.0f);
  EXPECT_EQ(p.max_over(4, 4, 0, 2), 9.0f);
  EXPECT_EQ(p.max_over(0, 4, 2, 2), 0.0f);
  EXPECT_EQ(p.square(1, 2, 0), 30.0f);  // [2, 4) x [0, 2)
  EXPECT_EQ(p.square(1, 4, 1), 9.0f);   // clipped at the right and bottom edges
  EXPECT_EQ(p.square(2, 0, 0), 30.0f);  // [0, 4) x [0, 3)
  EXPECT_TRUE(p.any_at_least(3, 3, 1, 1, 30.0f));
  EXPECT_FALSE(p.any_at_least(0, 2, 0, 2, 8.5f));
  EXPECT_TRUE(p.any_at_least(0, 2, 0, 2, 8.0f));
}

TEST(ReachPyramid, EqualsBruteForceOnRandomRectangles) {
  std::mt19937 rng(3);
  for (const auto& [cols, rows] : {std::pair{128, 96}, std::pair{37, 23}, std::pair{1, 1}, std::pair{640, 480}}) {
    std::vector<float> image(static_cast<size_t>(cols) * rows);
    std::uniform_real_distribution<float> value(0.0f, 4.0f);
    std::bernoulli_distribution hole(0.3);
    for (float& x : image) x = hole(rng) ? 0.0f : value(rng);
    ReachPyramid p;
    p.build(image.data(), cols, rows);
    // Every square of every level is the exact clipped maximum.
    for (int level = 0; level < ReachPyramid::kLevels; ++level) {
      const int side = 1 << level;
      for (int k = 0; k < 200; ++k) {
        const int u = std::uniform_int_distribution<int>(0, cols - 1)(rng);
        const int v = std::uniform_int_distribution<int>(0, rows - 1)(rng);
        ASSERT_EQ(p.square(level, u, v),
                  brute_max(image, cols, u, std::min(u + side, cols) - 1, v, std::min(v + side, rows) - 1));
      }
    }
    for (int k = 0; k < 2000; ++k) {
      std::uniform_int_distribution<int> cu(0, cols - 1), cv(0, rows - 1);
      int i0 = cu(rng), i1 = cu(rng), j0 = cv(rng), j1 = cv(rng);
      if (k % 3 == 0) i1 = std::min(cols - 1, i0 + k % 7);  // thin ones too
      if (i0 > i1) std::swap(i0, i1);
      if (j0 > j1) std::swap(j0, j1);
      const float truth = brute_max(image, cols, i0, i1, j0, j1);
      ASSERT_EQ(p.max_over(i0, i1, j0, j1), truth) << cols << "x" << rows << " [" << i0 << "," << i1 << "]x[" << j0 << "," << j1 << "]";
      ASSERT_TRUE(p.any_at_least(i0, i1, j0, j1, truth));
      ASSERT_FALSE(p.any_at_least(i0, i1, j0, j1, std::nextafter(truth, 1e9f)));
    }
  }
}

TEST(KeySpace, KeyIsOctomapsFloorRule) {
  const KeySpace keys(0.1);
  auto reference = [&](double c, uint16_t& k) {  // OcTreeBaseImpl::coordToKeyChecked
    const int scaled = static_cast<int>(std::floor(10.0 * c)) + 32768;
    if (scaled < 0 || scaled >= 65536) return false;
    k = static_cast<uint16_t>(scaled);
    return true;
  };
  std::vector<double> coords = {0.0, -0.0, 0.05, -0.05, 0.1, -0.1, 1.0, -1.0, 0.3, -0.3, 1e-300, -1e-300,
                                -3276.8, -3276.8 - 1e-9, 3276.7, 3276.8 - 1e-9, 3276.8, 1e6, -1e6};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> any(-4000.0, 4000.0);
  for (int i = 0; i < 20000; ++i) coords.push_back(i % 2 ? any(rng) : static_cast<double>(static_cast<float>(any(rng) * 1e-3)));
  for (const double c : coords) {
    uint16_t mine = 0, theirs = 0;
    const bool ok = keys.key(c, mine);
    ASSERT_EQ(ok, reference(c, theirs)) << c;
    if (ok) {
      ASSERT_EQ(mine, theirs) << c;
    }
  }
  uint16_t k = 0;
  EXPECT_FALSE(keys.key(std::numeric_limits<double>::quiet_NaN(), k));
  EXPECT_FALSE(keys.key(std::numeric_limits<double>::infinity(), k));
  EXPECT_TRUE(keys.key(-0.05, k));
  EXPECT_EQ(k, 32767);
}

TEST(KeySpace, FirstFloatIsTheLowestFloatOfTheKey) {
  // first_float(k) has key k and the float below it key k - 1, at cell edges near 0, at
  // coordinates where a float's spacing is a sizeable fraction of a millimetre, and for
  // resolutions that are not powers of two or tenths.
  std::mt19937 rng(9);
  for (const double resolution : {0.1, 0.05, 0.07, 0.25}) {
    const KeySpace keys(resolution);
    std::uniform_int_distribution<int> any(1, 65535);
    std::vector<int> ks = {32768, 32767, 32769, 32768 + 10, 32768 - 10, 40000, 20000};
    for (int i = 0; i < 3000; ++i) ks.push_back(any(rng));
    for (const int k : ks) {
      const float x = keys.first_float(k);
      uint16_t got = 0;
      ASSERT_TRUE(keys.key(static_cast<double>(x), got)) << k;
      ASSERT_EQ(got, k) << resolution << " " << k;
      const float below = std::nextafter(x, -HUGE_VALF);
      ASSERT_TRUE(keys.key(static_cast<double>(below), got)) << k;
      ASSERT_EQ(got, k - 1) << resolution << " " << k;
    }
  }
}

TEST(Ray, IndexOnlyWalksVisitOctomapsRayCells) {
  // Rays from random origins (some on cell corners and edges) to random points (some on cell
  // faces, some along an axis or a diagonal): trace_index_only() visits, by grid index, exactly
  // the cells of OctoMap's computeRayKeys, in order, and so does each walk when
  // walk_index_walks() interleaves them.
  std::mt19937 rng(11);
  const double res = 0.1;
  const KeySpace keys(res);
  octomap::OcTree tree(res);
  std::uniform_real_distribution<double> any(-3.0, 3.0), offset(-2.0, 2.0);
  std::uniform_int_distribution<int> cell(-30, 30), kind(0, 5);
  const int side = 101;  // a grid of side^3 cells centred on the origin's cell
  const int stride[3] = {1, side, side * side};
  size_t walked = 0;
  std::vector<IndexWalk> walks;
  std::vector<std::vector<int>> wanted;
  // One KeyRay for every trial: each allocates and clears room for 100,000 keys, which was
  // most of this test's time (and, under ASan, an mmap per trial). computeRayKeys resets it.
  octomap::KeyRay expected;
  for (int trial = 0; trial < 20000; ++trial) {
    const int k = kind(rng);
    octomap::point3d origin(static_cast<float>(any(rng)), static_cast<float>(any(rng)), static_cast<float>(any(rng)));
    if (k == 1) origin = octomap::point3d(static_cast<float>(cell(rng) * res), static_cast<float>(cell(rng) * res), 0.5f);
    octomap::point3d end = origin + octomap::point3d(static_cast<float>(offset(rng)), static_cast<float>(offset(rng)),
                                                     static_cast<float>(offset(rng)));
    if (k == 2) end = octomap::point3d(static_cast<float>(cell(rng) * res), end.y(), static_cast<float>(cell(rng) * res));
    if (k == 3) end = octomap::point3d(origin.x() + 1.3f, origin.y(), origin.z());
    if (k == 4) end = origin + octomap::point3d(0.7f, -0.7f, 0.7f);
    Key key_origin;
    ASSERT_TRUE(keys.key(origin, key_origin));
    const Ray ray = make_ray(keys, origin, key_origin, end, 10.0);
    if (!ray.clears) continue;
    ASSERT_TRUE(tree.computeRayKeys(origin, ray.end, expected));
    auto grid_index = [&](const Key& key) {
      int idx = 0;
      for (int a = 0; a < 3; ++a) idx += (key[a] - key_origin[a] + side / 2) * stride[a];
      return idx;
    };
    std::vector<int> got;
    trace_index_only(keys, origin, key_origin, ray, grid_index(key_origin), grid_index(ray.key_end), stride,
                     [&](int idx) { got.push_back(idx); });
    std::vector<int> want;
    for (const Key& key : expected) want.push_back(grid_index(key));
    ASSERT_EQ(got, want) << "trial " << trial;
    ++walked;
    walks.push_back(start_index_walk(keys, origin, key_origin, ray, grid_index(key_origin), grid_index(ray.key_end), stride));
    want.erase(want.begin());  // the walks below start in the origin's cell, already visited
    wanted.push_back(want);
  }
  EXPECT_GT(walked, 15000u);
  // The same walks interleaved (two at a time where built with SSE2), in batches of every size
  // from 0 to 9 and then larger: each walk's cells in order.
  size_t begin = 0;
  for (size_t batch = 0; begin < walks.size(); batch = batch < 9 ? batch + 1 : 2 * batch) {
    const size_t n = std::min(batch, walks.size() - begin);
    std::vector<std::vector<int>> got(n);
    walk_index_walks(walks.data() + begin, n, [&](int idx, size_t k) {
      ASSERT_LT(k, n);
      got[k].push_back(idx);
    });
    for (size_t k = 0; k < n; ++k) ASSERT_EQ(got[k], wanted[begin + k]) << "walk " << begin + k << " of a batch of " << n;
    begin += n;
  }
}

TEST(ReachMask, FourPixelMaskEqualsScalarAndPixelByPixel) {
  std::mt19937 rng(7);
  const float special[] = {0.0f, -0.0f, -1.0f, 1e-6f, 0.5f, 2.0f, std::numeric_limits<float>::quiet_NaN(),
                           std::numeric_limits<float>::infinity(), std::numeric_limits<float>::denorm_min()};
  std::uniform_int_distribution<int> pick(0, 8);
  std::uniform_real_distribution<float> any(-1.0f, 3.0f);
  for (int trial = 0; trial < 20000; ++trial) {
    float values[4];
    for (float& v : values) v = trial % 2 ? special[pick(rng)] : any(rng);
    const float threshold = trial % 3 ? any(rng) : special[pick(rng)];
    unsigned expected = 0;
    for (int k = 0; k < 4; ++k) {
      if (values[k] >= threshold && values[k] > 0.0f) expected |= 1u << k;
    }
    ASSERT_EQ(reaching4(values, threshold), expected) << trial;
    ASSERT_EQ(reaching4_scalar(values, threshold), expected) << trial;
    for (int count = 0; count <= 4; ++count)
      ASSERT_EQ(reaching_scalar(values, count, threshold), expected & ((1u << count) - 1u)) << trial;
  }
}

TEST(ReachMask, PixelBitsAreTheRangeWithinTheFourPixels) {
  for (int u0 = 0; u0 <= 12; u0 += 4) {
    for (int lo = -2; lo <= 18; ++lo) {
      for (int hi = -2; hi <= 18; ++hi) {
        unsigned expected = 0;
        for (int k = 0; k < 4; ++k) {
          if (u0 + k >= lo && u0 + k <= hi) expected |= 1u << k;
        }
        ASSERT_EQ(pixel_bits(lo, hi, u0), expected) << u0 << " " << lo << " " << hi;
      }
    }
  }
}

}  // namespace
}  // namespace kestrel::mapper
