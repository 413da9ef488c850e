// The process's planner without LCM: request validation, statuses and reproducible plans.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "planner/floor_plan.h"
#include "planner/online_planner.h"

namespace kestrel::planner {
namespace {

OnlinePlanner floor_planner() {
  OnlinePlannerOptions o;
  o.map_z_min_m = 0.0;
  o.map_z_max_m = 3.0;
  OnlinePlanner p(o);
  p.set_map(stata_like_floor());
  return p;
}

TEST(OnlinePlanner, AnswersWithStatusesForEveryBadCase) {
  OnlinePlanner none{OnlinePlannerOptions{}};
  PlanQuery q;
  q.start = Config(2.5, 2.5, 1.0, 0.0);
  q.start_trace = 0.4;
  q.goal = Config(10.5, 20.0, 1.0, 0.0);
  EXPECT_EQ(none.plan(q).status, PlanAnswer::kNoMap);
  const OnlinePlanner p = floor_planner();
  PlanQuery bad = q;
  bad.goal[0] = static_cast<double>(NAN);
  EXPECT_EQ(p.plan(bad).status, PlanAnswer::kBadRequest);
  bad = q;
  bad.start.reset();  // from the state, but there is none
  EXPECT_EQ(p.plan(bad).status, PlanAnswer::kBadRequest);
  bad = q;
  bad.start = Config(0.1, 0.1, 1.0, 0.0);  // in the outer wall
  EXPECT_EQ(p.plan(bad).status, PlanAnswer::kStartInCollision);
  bad = q;
  bad.goal = Config(6.3, 5.0, 5.0, 0.0);  // above the walls
  EXPECT_EQ(p.plan(bad).status, PlanAnswer::kGoalInCollision);
}

TEST(OnlinePlanner, PlansReproduciblyAndPredictsCovariances) {
  const OnlinePlanner p = floor_planner();
  PlanQuery q;
  q.request_id = 7;
  q.start = Config(2.5, 2.5, 1.0, 0.0);
  q.start_trace = 0.4;
  q.goal = Config(10.5, 20.0, 1.0, 0.0);
  const PlanAnswer a = p.plan(q), b = p.plan(q);
  ASSERT_EQ(a.status, PlanAnswer::kOk) << a.message;
  EXPECT_EQ(a.waypoints.size(), b.waypoints.size());
  EXPECT_EQ(a.traces, b.traces);
  EXPECT_TRUE(a.waypoints.front().isApprox(*q.start));
  EXPECT_TRUE(a.waypoints.back().isApprox(q.goal));
  EXPECT_NEAR(a.traces.front(), 0.4, 1e-12);
  EXPECT_GE(a.length_m, (q.goal - *q.start).head<3>().norm());
  // The covariance at each waypoint is the one whose trace PLAN carries: symmetric, positive.
  ASSERT_EQ(a.covariances.size(), a.waypoints.size());
  for (size_t i = 0; i < a.covariances.size(); ++i) {
    EXPECT_EQ(a.covariances[i].trace(), a.traces[i]) << i;
    EXPECT_TRUE(a.covariances[i].isApprox(a.covariances[i].transpose(), 1e-12)) << i;
    EXPECT_GT(a.covariances[i].ldlt().vectorD().minCoeff(), 0.0) << i;
  }
}

TEST(OnlinePlanner, CovarianceDominanceSearchesTheSameRoadmapExactlyOrWithinItsSlack) {
  const OnlinePlanner p = floor_planner();
  PlanQuery q;
  q.request_id = 7;  // the same id: the same roadmap
  q.start = Config(2.5, 2.5, 1.0, 0.0);
  q.start_trace = 0.4;
  q.goal = Config(10.5, 20.0, 1.0, 0.0);
  const PlanAnswer trace_rule = p.plan(q);
  q.pruning = BrmPruning::kCovarianceDominance;
  const PlanAnswer slack = p.plan(q);  // the default 1 %
  q.dominance_slack = 0.0;
  const PlanAnswer exact = p.plan(q);
  for (const PlanAnswer* a : {&trace_rule, &slack, &exact}) {
    ASSERT_EQ(a->status, PlanAnswer::kOk) << a->message;
    EXPECT_TRUE(a->waypoints.back().isApprox(q.goal));
  }
  EXPECT_LE(exact.traces.back(), trace_rule.traces.back() * (1.0 + 1e-12));
  // At most 1 % per edge above what the exact rule finds (and it may be above the trace rule).
  EXPECT_LE(slack.traces.back(), exact.traces.back() * std::pow(1.01, static_cast<double>(slack.waypoints.size() - 1)));
  std::cout << "goal tr(Sigma): trace rule " << trace_rule.traces.back() << ", dominance " << exact.traces.back()
            << ", at 1 % " << slack.traces.back() << "\n";
}

// A 6 x 3 m free room whose cells around the vehicle at (1, 1.5) the camera never saw (all
// within 0.8 m of it, the default start_unknown_free_m).
OccupancyGrid room_with_unseen_vehicle_space() {
  OccupancyGrid g = make_grid(60, 30, 0.1, 0.05, 0.05);
  fill_rect(g, 0.5, 1.0, 1.5, 2.0, OccupancyGrid::kUnknown);
  return g;
}

TEST(OnlinePlanner, FromTheStateTheSpaceTheVehicleFillsIsFreeButNotFromAGivenStart) {
  OnlinePlannerOptions o;
  o.map_z_min_m = 0.0;
  o.map_z_max_m = 3.0;
  OnlinePlanner p(o);
  p.set_map(room_with_unseen_vehicle_space());
  p.set_state(Config(1.0, 1.5, 1.0, 0.0), 0.01 * Mat4::Identity());
  PlanQuery q;
  q.request_id = 3;
  q.goal = Config(5.0, 1.5, 1.0, 0.0);
  const PlanAnswer from_state = p.plan(q);
  ASSERT_EQ(from_state.status, PlanAnswer::kOk) << from_state.message;
  EXPECT_TRUE(from_state.waypoints.front().head<2>().isApprox(Eigen::Vector2d(1.0, 1.5)));
  // The same place given as the start: unknown, so refused (nobody says a vehicle is there).
  q.start = Config(1.0, 1.5, 1.0, 0.0);
  q.start_trace = 0.04;
  EXPECT_EQ(p.plan(q).status, PlanAnswer::kStartInCollision);
  // The map may end at the camera, in front of the vehicle: the grid grows to hold it.
  OccupancyGrid ahead = make_grid(60, 30, 0.1, 1.25, 0.05);  // x from 1.2 m on
  p.set_map(ahead);
  q.start.reset();
  const PlanAnswer behind = p.plan(q);
  ASSERT_EQ(behind.status, PlanAnswer::kOk) << behind.message;
  // A wall seen 0.2 m from the vehicle stays a wall.
  OccupancyGrid walled = room_with_unseen_vehicle_space();
  fill_rect(walled, 1.15, 1.0, 1.25, 2.0, OccupancyGrid::kOccupied);
  p.set_map(walled);
  EXPECT_EQ(p.plan(q).status, PlanAnswer::kStartInCollision);
}

}  // namespace
}  // namespace kestrel::planner
