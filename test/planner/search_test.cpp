// PRM and BRM on graphs whose answers are known by construction.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <limits>

#include "planner/grid_environment.h"
#include "planner/search.h"

namespace kestrel::planner {
namespace {

// An edge of `length` m in 0.25 m steps, each with information M.
ScatteringTransfer edge(double length, const Mat4& M) {
  BeliefStep s;
  s.R = (0.25 * Eigen::Vector4d(0.1, 0.1, 0.02, 0.01)).asDiagonal();
  s.M = M;
  return ScatteringTransfer::from_steps(std::vector<BeliefStep>(static_cast<size_t>(length / 0.25), s));
}

// `observed` edges see the position well.
ScatteringTransfer edge(double length, bool observed) {
  return edge(length, observed ? Mat4(20.0 * Mat4::Identity()) : Mat4(Mat4::Zero()));
}

// Features that see only `seen` (information 50 per step in that direction).
ScatteringTransfer seeing(double length, const Eigen::Vector4d& seen) {
  return edge(length, Mat4(50.0 * seen * seen.transpose()));
}

// a <-> b, the same transfer both ways.
void join(Roadmap& map, int a, int b, double length, const ScatteringTransfer& transfer) {
  map.add_edge(a, b, length, transfer);
  map.add_edge(b, a, length, transfer);
}

// start 0 -> goal 1. Short route 0-2-1 (2 x 5 m) crosses a featureless hall; the long route
// 0-3-4-1 (3 x 5 m) runs along textured walls, and its last edge is observed.
Roadmap two_routes() {
  Roadmap map;
  for (int i = 0; i < 5; ++i) map.add_node(Config(i, 0, 1, 0));
  join(map, 0, 2, 5.0, edge(5.0, false));
  join(map, 2, 1, 5.0, edge(5.0, false));
  join(map, 0, 3, 5.0, edge(5.0, true));
  join(map, 3, 4, 5.0, edge(5.0, true));
  join(map, 4, 1, 5.0, edge(5.0, true));
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

// Two ways to node 4: 0-4 (2 m seeing y) arrives with the smaller tr(Sigma), 0-3-4 (2 x 2 m,
// the first seeing x) with a small x variance and a large y variance. The last edge 4-1 sees
// y only, so y's variance at 4 does not matter and x's does: the goal is better from 0-3-4.
// Algorithm 1 keeps only 0-4 at node 4 (smaller trace); the dominance rule keeps both.
Roadmap trace_trap() {
  Roadmap map;
  for (int i = 0; i < 5; ++i) map.add_node(Config(i, 0, 1, 0));
  const Eigen::Vector4d x(1, 0, 0, 0), y(0, 1, 0, 0);
  map.add_edge(0, 4, 2.0, seeing(2.0, y));
  map.add_edge(0, 3, 2.0, seeing(2.0, x));
  map.add_edge(3, 4, 2.0, seeing(2.0, Eigen::Vector4d::Zero()));
  map.add_edge(4, 1, 2.0, seeing(2.0, y));
  return map;
}

TEST(Brm, TracePruningMissesTheOptimumThatCovarianceDominanceKeeps) {
  const Roadmap map = trace_trap();
  BrmQuery q;
  q.start_covariance = Mat4::Identity();
  PlanResult direct, detour;
  direct.nodes = {0, 4, 1};
  detour.nodes = {0, 3, 4, 1};
  predict_along(map, q.start_covariance, direct);
  predict_along(map, q.start_covariance, detour);
  ASSERT_LT(direct.traces[1], detour.traces[2]);  // at node 4 the direct label looks better...
  ASSERT_LT(detour.goal_covariance.trace(), direct.goal_covariance.trace() - 0.5);  // ...and is not

  const PlanResult trace_rule = belief_search(map, 0, 1, q);
  EXPECT_EQ(trace_rule.nodes, direct.nodes);
  q.pruning = BrmPruning::kCovarianceDominance;
  const PlanResult dominance = belief_search(map, 0, 1, q);
  EXPECT_EQ(dominance.nodes, detour.nodes);
  EXPECT_NEAR(dominance.goal_covariance.trace(), detour.goal_covariance.trace(), 1e-12);
}

// Every simple path from 0 to 1, by depth-first enumeration: the least goal tr(Sigma).
double best_by_enumeration(const Roadmap& map, const Mat4& sigma0) {
  double best = std::numeric_limits<double>::infinity();
  std::vector<bool> on(map.size(), false);
  std::function<void(int, const Mat4&)> visit = [&](int n, const Mat4& sigma) {
    if (n == 1) {
      best = std::min(best, sigma.trace());
      return;
    }
    on[n] = true;
    for (const Edge& e : map.edges(n))
      if (!on[e.to]) visit(e.to, e.transfer.apply(sigma));
    on[n] = false;
  };
  visit(0, sigma0);
  return best;
}

// Random roadmaps of 7 nodes, each edge's features seeing a random direction: both rules
// against every simple path. Neither is exact (the no-revisit rule: a kept label cannot take
// a continuation through its own path), but dominance misses far less often.
TEST(Brm, CovarianceDominanceMissesTheBestSimplePathFarLessOftenThanTracePruning) {
  Rng rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n01(0.0, 1.0);
  int trace_missed = 0, dominance_missed = 0, dominance_worse = 0, slack_far = 0, trials = 0;
  for (int g = 0; g < 200; ++g) {
    Roadmap map;
    for (int i = 0; i < 7; ++i) map.add_node(Config(i, 0, 1, 0));
    for (int a = 0; a < 7; ++a)
      for (int b = a + 1; b < 7; ++b) {
        if (u(rng) > 0.5) continue;
        const double length = 1.0 + std::floor(4.0 * u(rng));
        const Eigen::Vector4d d(n01(rng), n01(rng), n01(rng), n01(rng));
        const Eigen::Vector4d seen = u(rng) < 0.3 ? Eigen::Vector4d::Zero() : Eigen::Vector4d(0.3 * d.normalized());
        join(map, a, b, length, seeing(length, seen));
      }
    const Mat4 sigma0 = 0.5 * Mat4::Identity();
    const double best = best_by_enumeration(map, sigma0);
    BrmQuery q;
    q.start_covariance = sigma0;
    const PlanResult trace_rule = belief_search(map, 0, 1, q);
    q.pruning = BrmPruning::kCovarianceDominance;
    const PlanResult dominance = belief_search(map, 0, 1, q);
    q.dominance_slack = 0.05;
    const PlanResult slack = belief_search(map, 0, 1, q);
    ASSERT_EQ(trace_rule.found, std::isfinite(best)) << "roadmap " << g;
    ASSERT_EQ(dominance.found, std::isfinite(best)) << "roadmap " << g;
    ASSERT_EQ(slack.found, std::isfinite(best)) << "roadmap " << g;
    if (!std::isfinite(best)) continue;
    ++trials;
    // Each answer is a real path: its tr(Sigma), re-predicted along it, is never below the best.
    for (const PlanResult* r : {&trace_rule, &dominance, &slack}) {
      PlanResult again;
      again.nodes = r->nodes;
      predict_along(map, sigma0, again);
      ASSERT_NEAR(again.goal_covariance.trace(), r->goal_covariance.trace(), 1e-12 * best) << "roadmap " << g;
      ASSERT_GE(r->goal_covariance.trace(), best * (1.0 - 1e-12)) << "roadmap " << g;
    }
    trace_missed += trace_rule.goal_covariance.trace() > best * (1.0 + 1e-9);
    dominance_missed += dominance.goal_covariance.trace() > best * (1.0 + 1e-9);
    dominance_worse += dominance.goal_covariance.trace() > trace_rule.goal_covariance.trace() * (1.0 + 1e-9);
    // A newcomer within 5 % of a kept label in every direction is dropped; phi(c Sigma) <=
    // c phi(Sigma) for c >= 1 bounds what that costs per edge (6 edges at most here).
    slack_far += slack.goal_covariance.trace() > dominance.goal_covariance.trace() * std::pow(1.05, 6);
  }
  std::cout << "of " << trials << " random roadmaps the best simple path was missed by trace pruning on "
            << trace_missed << ", by covariance dominance on " << dominance_missed << "; dominance worse than trace on "
            << dominance_worse << "\n";
  EXPECT_GT(trials, 150);
  EXPECT_GT(trace_missed, trials / 4) << "the roadmaps should include many where trace pruning misses the best";
  EXPECT_LT(dominance_missed * 5, trace_missed);
  EXPECT_LE(dominance_worse, trials / 50);
  EXPECT_EQ(slack_far, 0);
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
