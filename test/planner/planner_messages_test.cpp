// The planner process's gates (planner/planner_messages.h): every request a planner cannot
// use is refused naming the field, before any planning; every usable one becomes the query
// it asks for.

#include "planner/planner_messages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "common/error.h"
#include "test/support/test_support.h"

namespace kestrel::planner {
namespace {

using R = kestrel::plan_request_t;

R usable() {
  R r{};
  r.utime = 1000;
  r.request_id = 7;
  r.start_mode = R::START_GIVEN;
  r.start[0] = 1.0, r.start[1] = 2.0, r.start[2] = 1.0, r.start[3] = 0.1;
  r.start_covariance_trace = 0.05;
  r.goal[0] = 6.5, r.goal[1] = 1.0, r.goal[2] = 1.0, r.goal[3] = -0.2;
  r.planner = R::PLANNER_BRM;
  r.objective = R::OBJECTIVE_SHORTEST_BOUNDED;
  r.max_covariance_trace = 0.5;
  return r;
}

std::string refusal(const R& r) {
  try {
    query_from_message(r, 0.01);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PlanRequestGate, AUsableRequestBecomesTheQueryItAsksFor) {
  const PlanQuery q = query_from_message(usable(), 0.01);
  EXPECT_EQ(q.request_id, 7);
  ASSERT_TRUE(q.start.has_value());
  EXPECT_EQ(*q.start, Config(1.0, 2.0, 1.0, 0.1));
  EXPECT_EQ(q.start_trace, 0.05);
  EXPECT_EQ(q.goal, Config(6.5, 1.0, 1.0, -0.2));
  EXPECT_TRUE(q.brm);
  EXPECT_EQ(q.objective, BrmObjective::kShortestBounded);
  EXPECT_EQ(q.max_trace, 0.5);

  R from_state = usable();
  from_state.start_mode = R::START_FROM_STATE;
  from_state.start[0] = std::nan("");  // not used: the start is the latest STATE
  from_state.planner = R::PLANNER_BRM_DOMINANCE;
  from_state.objective = R::OBJECTIVE_MIN_GOAL_UNCERTAINTY;
  from_state.max_covariance_trace = -1.0;  // not used by this objective
  const PlanQuery s = query_from_message(from_state, 0.25);
  EXPECT_FALSE(s.start.has_value());
  EXPECT_EQ(s.pruning, BrmPruning::kCovarianceDominance);
  EXPECT_EQ(s.dominance_slack, 0.25);
  EXPECT_EQ(s.objective, BrmObjective::kMinGoalUncertainty);
}

TEST(PlanRequestGate, EveryUnusableFieldIsRefusedNamingIt) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* field;
    void (*spoil)(R&, double);
    double value;
  };
  const Case cases[] = {
      {"goal", [](R& r, double v) { r.goal[0] = v; }, nan},
      {"goal", [](R& r, double v) { r.goal[1] = v; }, inf},
      {"goal", [](R& r, double v) { r.goal[3] = v; }, nan},
      {"goal", [](R& r, double v) { r.goal[2] = v; }, 2e4},
      {"start", [](R& r, double v) { r.start[0] = v; }, -inf},
      {"start", [](R& r, double v) { r.start[1] = v; }, -1e300},
      {"start_covariance_trace", [](R& r, double v) { r.start_covariance_trace = v; }, -0.1},
      {"start_covariance_trace", [](R& r, double v) { r.start_covariance_trace = v; }, nan},
      {"max_covariance_trace", [](R& r, double v) { r.max_covariance_trace = v; }, 0.0},
      {"max_covariance_trace", [](R& r, double v) { r.max_covariance_trace = v; }, inf},
      {"start mode", [](R& r, double v) { r.start_mode = static_cast<int8_t>(v); }, 2},
      {"planner", [](R& r, double v) { r.planner = static_cast<int8_t>(v); }, -1},
      {"objective", [](R& r, double v) { r.objective = static_cast<int8_t>(v); }, 9},
  };
  for (const Case& c : cases) {
    R r = usable();
    c.spoil(r, c.value);
    const std::string why = refusal(r);
    EXPECT_EQ(why.rfind("PLAN_REQUEST: ", 0), 0u) << c.field << " = " << c.value << ": " << (why.empty() ? "accepted" : why);
    EXPECT_NE(why.find(c.field), std::string::npos) << c.field << " = " << c.value << ": " << why;
  }
}

TEST(PlanRequestGate, ARefusedRequestIsAnsweredWithItsIdAndWhy) {
  R r = usable();
  PlanAnswer refused;
  refused.status = PlanAnswer::kBadRequest;
  refused.message = "PLAN_REQUEST: goal is not finite";
  const kestrel::plan_t p = plan_message(r, refused, 0.0);
  EXPECT_EQ(p.request_id, 7);
  EXPECT_EQ(p.utime, 1000);
  EXPECT_EQ(p.status, kestrel::plan_t::STATUS_BAD_REQUEST);
  EXPECT_EQ(p.message, refused.message);
  EXPECT_EQ(p.num_waypoints, 0);
}

TEST(PlanCovariance, GoesWithItsPlanRowMajorAndOnlyWithAPath) {
  R r = usable();
  PlanAnswer a;
  a.status = PlanAnswer::kOk;
  a.waypoints = {Config(0, 0, 1, 0), Config(1, 0, 1, 0)};
  a.traces = {0.1, 0.2};
  Mat4 sigma = Mat4::Identity() * 0.05;
  sigma(0, 1) = 0.01;  // x-y, row 0 column 1
  sigma(1, 0) = 0.02;  // (not symmetric, so that the order shows)
  a.covariances = {Mat4::Identity() * 0.025, sigma};
  const kestrel::plan_t p = plan_message(r, a, 1.0);
  const auto c = plan_covariance_message(p, a);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->utime, p.utime);
  EXPECT_EQ(c->request_id, p.request_id);
  EXPECT_EQ(c->num_waypoints, 2);
  ASSERT_EQ(c->covariance.size(), 2u);
  EXPECT_EQ(c->covariance[1][1], 0.01);
  EXPECT_EQ(c->covariance[1][4], 0.02);
  EXPECT_EQ(c->covariance[1][15], 0.05);
  PlanAnswer none;
  none.status = PlanAnswer::kNoPath;
  EXPECT_FALSE(plan_covariance_message(plan_message(r, none, 1.0), none).has_value());
}

TEST(StateForThePlanner, NonFiniteOrNonRigidStatesAreRefused) {
  kestrel::state_t s{};
  s.T_world_body.orientation[0] = 1.0;
  s.T_world_body.position[0] = 2.0;
  EXPECT_EQ(state_from_message(s).first, Config(2.0, 0.0, 0.0, 0.0));
  kestrel::state_t bad = s;
  bad.T_world_body.orientation[0] = 2.0;
  EXPECT_THROW(state_from_message(bad), InputError);
  bad = s;
  bad.T_world_body.position[2] = std::nan("");
  EXPECT_THROW(state_from_message(bad), InputError);
  bad = s;
  bad.cov_dim = 9;
  bad.covariance.assign(9, std::vector<double>(9, 0.0));
  bad.covariance[8][8] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(state_from_message(bad), InputError);
}

}  // namespace
}  // namespace kestrel::planner
