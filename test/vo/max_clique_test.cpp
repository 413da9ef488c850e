// The greedy max-clique on hand-built graphs with known answers, and the distance-preservation
// graph on points moved rigidly with a few gross outliers.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "vo/max_clique.h"

namespace kestrel::vo {
namespace {

BitGraph graph(int n, const std::vector<std::pair<int, int>>& edges) {
  BitGraph g;
  g.reset(n);
  for (auto [a, b] : edges) g.connect(a, b);
  return g;
}

bool is_clique(const BitGraph& g, const std::vector<int>& c) {
  for (size_t i = 0; i < c.size(); ++i)
    for (size_t j = i + 1; j < c.size(); ++j)
      if (!g.adjacent(c[i], c[j])) return false;
  return true;
}

TEST(MaxClique, EmptyAndEdgelessGraphs) {
  EXPECT_TRUE(greedy_max_clique(graph(0, {})).empty());
  // No edges: a single vertex, the first of highest degree (all 0).
  EXPECT_EQ(greedy_max_clique(graph(4, {})), std::vector<int>({0}));
}

TEST(MaxClique, FindsTheFourCliqueBesideAPath) {
  // K4 on {2, 4, 6, 7}, a path 0-1-3-5 hanging off vertex 2.
  const BitGraph g = graph(8, {{2, 4}, {2, 6}, {2, 7}, {4, 6}, {4, 7}, {6, 7}, {0, 1}, {1, 3}, {3, 5}, {5, 2}});
  EXPECT_EQ(greedy_max_clique(g), std::vector<int>({2, 4, 6, 7}));
  EXPECT_EQ(g.degree(2), 4);
  EXPECT_FALSE(g.adjacent(2, 2));
  EXPECT_TRUE(g.adjacent(7, 4));
}

TEST(MaxClique, GreedyFollowsDegreeNotSize) {
  // A hub 0 joined to everyone, a triangle {0, 1, 2} and leaves: the greedy start is the hub
  // (degree 5), then the highest-degree neighbour (1 or 2, degree 2, lower index first).
  const BitGraph g = graph(6, {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {0, 5}, {1, 2}});
  EXPECT_EQ(greedy_max_clique(g), std::vector<int>({0, 1, 2}));
}

TEST(MaxClique, WorksAcrossWordBoundaries) {
  // 150 vertices: a clique on every third vertex (50 of them, spanning three 64-bit words).
  BitGraph g;
  g.reset(150);
  for (int a = 0; a < 150; a += 3)
    for (int b = a + 3; b < 150; b += 3) g.connect(a, b);
  for (int a = 1; a < 149; a += 3) g.connect(a, a + 1);
  const std::vector<int> c = greedy_max_clique(g);
  ASSERT_EQ(c.size(), 50u);
  EXPECT_TRUE(is_clique(g, c));
  for (int v : c) EXPECT_EQ(v % 3, 0);
}

TEST(MaxClique, ConsistencyGraphSeparatesOutliers) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const Eigen::Isometry3f T = Eigen::Translation3f(0.1f, -0.05f, 0.2f) *
                              Eigen::AngleAxisf(0.2f, Eigen::Vector3f(0.3f, 1.0f, 0.1f).normalized());
  std::vector<Eigen::Vector3f> ref, cur;
  for (int i = 0; i < 80; ++i) {
    const Eigen::Vector3f p(u(rng), u(rng), 2.0f + u(rng));
    ref.push_back(p);
    cur.push_back(T * p);
  }
  const std::vector<int> outliers = {3, 17, 40, 41, 66};
  for (int i : outliers) cur[size_t(i)] += Eigen::Vector3f(0.3f, -0.2f, 0.25f) * (1.0f + 0.1f * float(i));
  const std::vector<float> var(ref.size(), 1e-6f);
  BitGraph g;
  build_consistency_graph(ref, cur, var, 0.01f, 3.0f, g);
  const std::vector<int> c = greedy_max_clique(g);
  EXPECT_TRUE(is_clique(g, c));
  ASSERT_EQ(c.size(), 75u);
  for (int i : outliers) EXPECT_EQ(std::count(c.begin(), c.end(), i), 0) << i;
}

}  // namespace
}  // namespace kestrel::vo
