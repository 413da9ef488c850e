// The belief model of an edge: where the vehicle is and where it looks at each step, and how
// much process noise the edge adds — the same motion the follower (control/) flies.
#include <gtest/gtest.h>

#include <cmath>

#include "common/numbers.h"
#include "planner/roadmap.h"
#include "test/planner/test_environments.h"

namespace kestrel::planner {
namespace {

// Records the configuration each step's information is asked for.
struct Recorder {
  std::vector<Config> seen;
  BeliefModel model(MotionOptions motion = {}) {
    return BeliefModel(motion, [this](const Config& q) {
      seen.push_back(q);
      return Mat4::Zero().eval();
    });
  }
};

TEST(BeliefModel, TurnsFromTheStartYawToTheEndYawTheShortWayRound) {
  Recorder r;
  // 2 m along x while turning from 170 deg to -170 deg: 20 deg through +-180, not 340 back.
  const auto steps = r.model().steps(Config(0, 0, 1, 170 * kPi / 180), Config(2, 0, 1, -170 * kPi / 180));
  ASSERT_EQ(steps.size(), 8u);  // 2 m / 0.25 m; 20 deg needs fewer steps
  ASSERT_EQ(r.seen.size(), 8u);
  for (size_t k = 0; k < r.seen.size(); ++k) {
    const double f = (k + 1) / 8.0;
    EXPECT_NEAR(r.seen[k].x(), 2.0 * f, 1e-12);
    EXPECT_NEAR(std::remainder(r.seen[k][3] - (170.0 + 20.0 * f) * kPi / 180, 2 * kPi), 0.0, 1e-12) << k;
  }
  EXPECT_NEAR(std::remainder(r.seen.back()[3] + 170 * kPi / 180, 2 * kPi), 0.0, 1e-12);
}

TEST(BeliefModel, ALargeTurnOnAShortEdgeIsCutIntoYawSteps) {
  Recorder r;
  // 0.1 m and a half turn: one distance step, but pi / 0.25 rad -> 13 yaw steps, so the
  // sensor's view is sampled every 14 deg, under half the paper camera's 30 deg.
  const auto steps = r.model().steps(Config(0, 0, 1, 0), Config(0, 0.1, 1, kPi));
  EXPECT_EQ(steps.size(), 13u);
  for (size_t k = 1; k < r.seen.size(); ++k)
    EXPECT_LE(std::abs(std::remainder(r.seen[k][3] - r.seen[k - 1][3], 2 * kPi)), 0.25 + 1e-12);
}

TEST(BeliefModel, ProcessNoiseGrowsWithTheDistanceFlownNotWithTheSteps) {
  MotionOptions motion;
  motion.variance_per_m = Eigen::Vector4d(0.5, 0.4, 0.1, 0.05);
  Recorder r;
  // 3 m with a half turn (13 yaw steps > 12 distance steps): the noise still adds up to 3 m's.
  const auto steps = r.model(motion).steps(Config(1, 1, 1, 0), Config(1, 4, 1, kPi));
  ASSERT_EQ(steps.size(), 13u);
  Mat4 total = Mat4::Zero();
  for (const BeliefStep& s : steps) {
    EXPECT_TRUE(s.G.isIdentity());
    total += s.R;
  }
  EXPECT_TRUE(total.isApprox(Mat4((3.0 * motion.variance_per_m).asDiagonal()), 1e-12)) << total;
}

TEST(BeliefModel, AZeroLengthEdgeHasNoSteps) {
  Recorder r;
  EXPECT_TRUE(r.model().steps(Config(1, 2, 1, 0), Config(1, 2, 1, 0)).empty());
}

// Two 10 x 10 m rooms split by a wall at x = 10 with a 0.3 m gap at y in [4.85, 5.15]: few
// samples rarely join them.
testing::PredicateEnvironment two_rooms() {
  return testing::PredicateEnvironment(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(20, 10, 1)),
                                       [](const Eigen::Vector3d& p) {
                                         return std::abs(p.x() - 10.0) > 0.1 || std::abs(p.y() - 5.0) < 0.15;
                                       });
}

bool joins(const Roadmap& map, int from, int to) {
  std::vector<int> stack{from};
  std::vector<bool> seen(map.size(), false);
  seen[from] = true;
  while (!stack.empty()) {
    const int a = stack.back();
    stack.pop_back();
    for (const Edge& e : map.edges(a))
      if (!seen[e.to]) seen[e.to] = true, stack.push_back(e.to);
  }
  return seen[to];
}

TEST(BuildRoadmap, GrowsUntilStartAndGoalConnectAndEqualsTheRoadmapBuiltAtOnce) {
  const auto env = two_rooms();
  SpaceOptions so;
  so.radius_m = 0.1;
  const ConfigurationSpace space(env, so);
  const Config start(2, 2, 1, 0), goal(18, 8, 1, 0);
  RoadmapOptions fixed;
  fixed.samples = 20;
  fixed.connect_radius_m = 8.0;
  fixed.max_neighbours = 0;
  RoadmapOptions grown = fixed;
  grown.max_samples = 2000;
  auto uniform = make_uniform_sampler(space);
  Rng rng_fixed(7), rng_grown(7);
  const Roadmap small = build_roadmap(space, *uniform, start, goal, fixed, nullptr, rng_fixed);
  ASSERT_FALSE(joins(small, 0, 1)) << "the test needs a seed whose 20 samples do not cross the gap";
  const Roadmap big = build_roadmap(space, *uniform, start, goal, grown, nullptr, rng_grown);
  EXPECT_TRUE(joins(big, 0, 1));
  const int samples = big.size() - 2;
  EXPECT_EQ(samples % 20, 0);  // whole batches
  EXPECT_LT(samples, 2000);

  // The same as drawing all those samples at once: nodes and edges alike.
  RoadmapOptions at_once = fixed;
  at_once.samples = samples;
  Rng rng_once(7);
  const Roadmap once = build_roadmap(space, *uniform, start, goal, at_once, nullptr, rng_once);
  ASSERT_EQ(once.size(), big.size());
  for (int i = 0; i < big.size(); ++i) {
    EXPECT_TRUE(once.node(i) == big.node(i)) << i;
    ASSERT_EQ(once.edges(i).size(), big.edges(i).size()) << i;
    for (size_t k = 0; k < big.edges(i).size(); ++k) EXPECT_EQ(once.edges(i)[k].to, big.edges(i)[k].to);
  }
}

// Returns the given configurations in order, then nothing.
class ListSampler : public Sampler {
 public:
  explicit ListSampler(std::vector<Config> list) : list_(std::move(list)) {}
  std::string name() const override { return "list"; }
  std::optional<Config> sample(Rng&, SampleTrace*) override {
    if (next_ >= list_.size()) return std::nullopt;
    return list_[next_++];
  }

 private:
  std::vector<Config> list_;
  size_t next_ = 0;
};

testing::PredicateEnvironment open_plane() {
  return testing::PredicateEnvironment(Eigen::AlignedBox3d(Eigen::Vector3d(-20, -20, 1), Eigen::Vector3d(20, 20, 1)),
                                       [](const Eigen::Vector3d&) { return true; });
}

TEST(BuildRoadmap, ThePapersRuleJoinsAPairBeyondTheRadius) {
  // Start and goal 10 m apart in open space, no samples: the line is free, so Algorithm 1
  // joins them; a 6 m radius does not.
  const auto env = open_plane();
  const ConfigurationSpace space(env, SpaceOptions{});
  const Config start(0, 0, 1, 0), goal(10, 0, 1, 0);
  Rng rng(1);
  ListSampler none_a({}), none_b({});
  RoadmapOptions limited;
  limited.samples = 0;
  const Roadmap a = build_roadmap(space, none_a, start, goal, limited, nullptr, rng);
  EXPECT_EQ(a.edge_count(), 0);
  RoadmapOptions paper = RoadmapOptions::all_pairs();
  paper.samples = 0;
  const Roadmap b = build_roadmap(space, none_b, start, goal, paper, nullptr, rng);
  ASSERT_EQ(b.edges(0).size(), 1u);
  EXPECT_EQ(b.edges(0)[0].to, 1);
  EXPECT_DOUBLE_EQ(b.edges(0)[0].length_m, 10.0);
}

TEST(BuildRoadmap, ThePapersRuleJoinsClustersANeighbourLimitKeepsApart) {
  // 21 samples within 0.3 m of the start and 21 within 0.3 m of the goal, 5 m away, all in
  // view of each other: every node's 20 nearest lie in its own cluster, so with 20 neighbours
  // (inside the 6 m radius) no edge crosses; the paper's rule joins every pair: 44 nodes,
  // 44 * 43 / 2 undirected edges.
  const auto env = open_plane();
  const ConfigurationSpace space(env, SpaceOptions{});
  const Config start(0, 0, 1, 0), goal(5, 0, 1, 0);
  std::vector<Config> list;
  for (int k = 0; k < 21; ++k) {
    const double a = 2.0 * kPi * k / 21.0, r = 0.1 + 0.01 * k;
    list.push_back(Config(r * std::cos(a), r * std::sin(a), 1, 0));
    list.push_back(Config(5 + r * std::cos(a), r * std::sin(a), 1, 0));
  }
  Rng rng(1);
  RoadmapOptions limited;
  limited.samples = 42;
  ListSampler la(list), lb(list);
  const Roadmap a = build_roadmap(space, la, start, goal, limited, nullptr, rng);
  EXPECT_FALSE(joins(a, 0, 1));
  RoadmapOptions paper = RoadmapOptions::all_pairs();
  paper.samples = 42;
  const Roadmap b = build_roadmap(space, lb, start, goal, paper, nullptr, rng);
  EXPECT_TRUE(joins(b, 0, 1));
  EXPECT_EQ(b.edge_count(), 44 * 43);  // directed: both ways
}

TEST(BuildRoadmap, StopsGrowingAtItsBudget) {
  // A wall with no gap: start and goal never connect; the roadmap stops at max_samples.
  const testing::PredicateEnvironment env(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(20, 10, 1)),
                                          [](const Eigen::Vector3d& p) { return std::abs(p.x() - 10.0) > 0.1; });
  const ConfigurationSpace space(env, SpaceOptions{});
  RoadmapOptions o;
  o.samples = 30;
  o.max_samples = 100;
  auto uniform = make_uniform_sampler(space);
  Rng rng(1);
  const Roadmap map = build_roadmap(space, *uniform, Config(2, 2, 1, 0), Config(18, 8, 1, 0), o, nullptr, rng);
  EXPECT_EQ(map.size(), 2 + 100);  // 30 + 30 + 30 + 10
  EXPECT_FALSE(joins(map, 0, 1));
}

}  // namespace
}  // namespace kestrel::planner
