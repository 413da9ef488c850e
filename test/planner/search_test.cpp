// PRM and BRM on graphs whose answers are known by construction.
#include <gtest/gtest.h>

#include "planner/grid_environment.h"
#include "planner/search.h"

namespace kestrel::planner {
namespace {

// An edge of `length` m in 0.25 m steps; `observed` edges see the position well.
ScatteringTransfer edge(double length, bool observed) {
  BeliefStep s;
  s.R = (0.25 * Eigen::Vector4d(0.1, 0.1, 0.02, 0.01)).asDiagonal();
  if (observed) s.M = Eigen::Vector4d(20.0, 20.0, 20.0, 20.0).asDiagonal();
  return ScatteringTransfer::from_steps(std::vector<BeliefStep>(static_cast<size_t>(length / 0.25), s));
}

// start 0 -> goal 1. Short route 0-2-1 (2 x 5 m) crosses a featureless hall; the long route
// 0-3-4-1 (3 x 5 m) runs along textured walls, and its last edge is observed.
Roadmap two_routes() {
  Roadmap map;
  for (int i = 0; i < 5; ++i) map.add_node(Config(i, 0, 1, 0));
  auto both = [&](int a, int b, double len, bool obs) {
    map.add_edge(a, b, len, edge(len, obs));
    map.add_edge(b, a, len, edge(len, obs));
  };
  both(0, 2, 5.0, false);
  both(2, 1, 5.0, false);
  both(0, 3, 5.0, true);
  both(3, 4, 5.0, true);
  both(4, 1, 5.0, true);
  return map;
}

TEST(Prm, FindsTheShortestRoute) {
  const PlanResult r = shortest_path(two_routes(), 0, 1);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.nodes, (std::vector<int>{0, 2, 1}));
  EXPECT_DOUBLE_EQ(r.length_m, 10.0);
}

TEST(Brm, FindsTheBestLocalisedRouteWhereItDiffersFromTheShortest) {
  const Roadmap map = two_routes();
  BrmQuery q;
  q.start_covariance = 0.5 * Mat4::Identity();
  const PlanResult brm = belief_search(map, 0, 1, q);
  ASSERT_TRUE(brm.found);
  EXPECT_EQ(brm.nodes, (std::vector<int>{0, 3, 4, 1}));
  EXPECT_DOUBLE_EQ(brm.length_m, 15.0);
  PlanResult prm = shortest_path(map, 0, 1);
  predict_along(map, q.start_covariance, prm);
  // The dark route only adds noise: 2 + 10 m x (0.1 + 0.1 + 0.02 + 0.01) = 4.3.
  EXPECT_NEAR(prm.goal_covariance.trace(), 2.0 + 10.0 * 0.23, 1e-12);
  EXPECT_LT(brm.goal_covariance.trace(), 0.1 * prm.goal_covariance.trace());
  EXPECT_DOUBLE_EQ(brm.traces.back(), brm.goal_covariance.trace());
}

TEST(Brm, ShortestBoundedObjectiveTradesLengthForTheBound) {
  const Roadmap map = two_routes();
  BrmQuery q;
  q.start_covariance = 0.5 * Mat4::Identity();
  q.objective = BrmObjective::kShortestBounded;
  q.max_trace = 100.0;  // loose: the shortest route is fine
  EXPECT_EQ(belief_search(map, 0, 1, q).nodes, (std::vector<int>{0, 2, 1}));
  q.max_trace = 4.0;  // the dark route ends at 4.3
  EXPECT_EQ(belief_search(map, 0, 1, q).nodes, (std::vector<int>{0, 3, 4, 1}));
  q.max_trace = 0.01;  // nothing is that good
  EXPECT_FALSE(belief_search(map, 0, 1, q).found);
}

// Start (0,0) and goal (10,0) are observed (|x| within 0.5 m of either end), the straight
// 10 m between them is blind; the detour 0 -> (0,3) -> (10,3) -> goal runs along an observed
// wall (y > 2.5). The blind leg's noise peaks mid-edge (0.4 + 1.15 /m x ~9 m) but the goal's
// features bring it back under 0.1, so only a check along the edge sees it.
TEST(Brm, BoundAlongEdgesRejectsAnEdgeThatPeaksBetweenWellLocalisedNodes) {
  const auto information = [](const Config& q) -> Mat4 {
    const bool seen = q[0] < 0.5 || q[0] > 9.5 || q[1] > 2.5;
    return seen ? Mat4(100.0 * Mat4::Identity()) : Mat4(Mat4::Zero());
  };
  const BeliefModel model(MotionOptions{}, information);
  Roadmap map;
  map.add_node(Config(0, 0, 1, 0));   // start
  map.add_node(Config(10, 0, 1, 0));  // goal
  map.add_node(Config(0, 3, 1, 0));
  map.add_node(Config(10, 3, 1, 0));
  map.connect(0, 1, &model);
  map.connect(0, 2, &model);
  map.connect(2, 3, &model);
  map.connect(3, 1, &model);
  BrmQuery q;
  q.start_covariance = 0.1 * Mat4::Identity();
  q.objective = BrmObjective::kShortestBounded;
  q.max_trace = 1.0;
  // Nodes only: the straight edge ends well localised, so it is taken.
  const PlanResult nodes_only = belief_search(map, 0, 1, q);
  ASSERT_TRUE(nodes_only.found);
  EXPECT_EQ(nodes_only.nodes, (std::vector<int>{0, 1}));
  EXPECT_LT(nodes_only.traces.back(), 0.1);
  const double blind_peak = peak_trace_along(model, map.node(0), map.node(1), q.start_covariance);
  EXPECT_GT(blind_peak, 8.0);  // 0.4 + 1.15 x 9 minus what the first 0.5 m see
  EXPECT_LT(blind_peak, 0.4 + 1.15 * 10.0);
  // Along edges: the detour, every step of it under the bound.
  q.edge_peak_trace = [&](int from, int to, const Mat4& sigma) {
    return peak_trace_along(model, map.node(from), map.node(to), sigma);
  };
  const PlanResult along = belief_search(map, 0, 1, q);
  ASSERT_TRUE(along.found);
  EXPECT_EQ(along.nodes, (std::vector<int>{0, 2, 3, 1}));
  EXPECT_DOUBLE_EQ(along.length_m, 16.0);
  Mat4 sigma = q.start_covariance;
  for (size_t i = 1; i < along.nodes.size(); ++i) {
    const Config &a = map.node(along.nodes[i - 1]), &b = map.node(along.nodes[i]);
    EXPECT_LT(peak_trace_along(model, a, b, sigma), 1.0);
    sigma = propagate_ekf(sigma, model.steps(a, b));
  }
  // The same check applies to the min-tr(Sigma_goal) objective's bound.
  q.objective = BrmObjective::kMinGoalUncertainty;
  EXPECT_EQ(belief_search(map, 0, 1, q).nodes, (std::vector<int>{0, 2, 3, 1}));
}

TEST(Search, ReportsUnreachableGoalsAndRejectsBadNodes) {
  Roadmap map;
  map.add_node(Config(0, 0, 1, 0));
  map.add_node(Config(1, 0, 1, 0));
  EXPECT_FALSE(shortest_path(map, 0, 1).found);
  EXPECT_FALSE(belief_search(map, 0, 1, {}).found);
  EXPECT_THROW(shortest_path(map, 0, 5), std::invalid_argument);
  PlanResult bogus;
  bogus.nodes = {0, 1};
  EXPECT_THROW(predict_along(map, Mat4::Identity(), bogus), std::invalid_argument);
}

TEST(Prm, ShortestPathAroundAnObstacleOnALattice) {
  // A 3 x 3 lattice of 1 m; a 0.4 m block on the centre node. Corner to corner the diagonal
  // is blocked, and the best detour is 1 + sqrt(2) + 1.
  OccupancyGrid g = make_grid(80, 80, 0.05, -0.975, -0.975);
  fill_rect(g, 0.8, 0.8, 1.2, 1.2, OccupancyGrid::kOccupied);
  const GridEnvironment env(g, 0.0, 2.0);
  const ConfigurationSpace space(env, SpaceOptions{0.1, 1.0, 1.0});
  Roadmap map;
  map.add_node(Config(0, 0, 1, 0));
  map.add_node(Config(2, 2, 1, 0));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!((i == 0 && j == 0) || (i == 2 && j == 2) || (i == 1 && j == 1))) map.add_node(Config(i, j, 1, 0));
  EXPECT_FALSE(space.is_valid(Config(1, 1, 1, 0)));
  for (int a = 0; a < map.size(); ++a)
    for (int b = a + 1; b < map.size(); ++b)
      if (ConfigurationSpace::distance(map.node(a), map.node(b)) < 1.5 && space.motion_valid(map.node(a), map.node(b)))
        map.connect(a, b, nullptr);
  const PlanResult r = shortest_path(map, 0, 1);
  ASSERT_TRUE(r.found);
  EXPECT_NEAR(r.length_m, 2.0 + std::sqrt(2.0), 1e-12);
}

}  // namespace
}  // namespace kestrel::planner
