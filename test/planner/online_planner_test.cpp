// The process's planner without LCM: request validation, statuses and reproducible plans.
#include <gtest/gtest.h>

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
  bad.goal[0] = NAN;
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
}

}  // namespace
}  // namespace kestrel::planner
