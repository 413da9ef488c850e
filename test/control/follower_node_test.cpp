// FollowerNode (follower_node.h): PLAN and STATE messages to VEHICLE_COMMAND: nothing before a
// plan, commands at most once per period, a hold when the plan has no path or the state no
// pose, bad plans and states refused naming the channel, waypoint files.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <optional>

#include "common/error.h"
#include "common/transport/convert.h"
#include "control/follower_node.h"
#include "test/support/test_support.h"

namespace kestrel::control {
namespace {

kestrel::state_t state(int64_t utime, double x, double y, int8_t status = kestrel::state_t::STATUS_OK) {
  kestrel::state_t m{};
  m.utime = utime;
  m.status = status;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, 1.0);
  m.T_world_body = transport::to_message(T);
  return m;
}

// A state of a vehicle flying along x at 0.5 m/s (what the jump smoother predicts steps from).
kestrel::state_t moving(int64_t utime, double x, double y) {
  kestrel::state_t m = state(utime, x, y);
  m.velocity[0] = 0.5;
  return m;
}

kestrel::plan_t plan(int8_t status = kestrel::plan_t::STATUS_OK) {
  kestrel::plan_t p{};
  p.request_id = 7;
  p.status = status;
  if (status == kestrel::plan_t::STATUS_OK) {
    p.waypoints = {{0, 0, 1, 0}, {4, 0, 1, 0}};
    p.covariance_trace = {0.4, 1.0};
    p.num_waypoints = 2;
  }
  return p;
}

TEST(FollowerNode, PublishesNothingBeforeAPlanThenCommandsOncePerPeriod) {
  FollowerNodeOptions o;
  o.command_period_s = 0.02;
  FollowerNode node(o);
  EXPECT_FALSE(node.on_state(state(1'000'000, 0, 0)));
  node.on_plan(plan());
  const auto first = node.on_state(state(1'005'000, 1, 0));
  ASSERT_TRUE(first);
  EXPECT_EQ(first->mode, kestrel::vehicle_command_t::MODE_POSITION);
  EXPECT_EQ(first->utime, 1'005'000);
  EXPECT_NEAR(first->position[0], 1.0, 1e-12);
  EXPECT_NEAR(first->velocity[0], 0.5, 1e-12);
  EXPECT_FALSE(node.on_state(state(1'010'000, 1, 0))) << "5 ms later: within the 20 ms period";
  EXPECT_FALSE(node.on_state(state(1'020'000, 1, 0)));
  EXPECT_TRUE(node.on_state(state(1'025'000, 1, 0))) << "20 ms after the last command";
}

TEST(FollowerNode, APlanWithoutAPathStopsTheVehicleOnce) {
  FollowerNode node(FollowerNodeOptions{});
  node.on_plan(plan());
  ASSERT_TRUE(node.on_state(state(1'000'000, 1, 0)));
  node.on_plan(plan(kestrel::plan_t::STATUS_NO_PATH));
  const auto hold = node.on_state(state(1'001'000, 1.2, 0));
  ASSERT_TRUE(hold) << "the hold goes out at once, whatever the period";
  EXPECT_EQ(hold->mode, kestrel::vehicle_command_t::MODE_HOLD);
  EXPECT_NEAR(hold->position[0], 1.2, 1e-12);
  EXPECT_FALSE(node.on_state(state(1'100'000, 1.2, 0))) << "then the follower is idle";
}

TEST(FollowerNode, AStateWithoutAPoseGivesAHold) {
  FollowerNode node(FollowerNodeOptions{});
  node.on_plan(plan());
  const auto c = node.on_state(state(1'000'000, 0, 0, kestrel::state_t::STATUS_FAILED));
  ASSERT_TRUE(c);
  EXPECT_EQ(c->mode, kestrel::vehicle_command_t::MODE_HOLD);
  const auto again = node.on_state(state(1'100'000, 1, 0));
  ASSERT_TRUE(again);
  EXPECT_EQ(again->mode, kestrel::vehicle_command_t::MODE_POSITION) << "the path is kept";
}

// A late SLAM correction moves STATE 0.45 m sideways within one 5 ms step while the vehicle
// follows the path at 0.5 m/s: the set point moves with it, so the controller's error (set point
// less state) does not step; then it goes back onto the path at the release speed.
TEST(FollowerNode, AJumpOfTheStateMovesTheSetPointWithItAndIsLetGoSlowly) {
  FollowerNodeOptions o;
  o.command_period_s = 0.0;  // a command on every state
  FollowerNode node(o);
  node.on_plan(plan());
  const auto before = node.on_state(moving(1'000'000, 1.0, 0.0));
  ASSERT_TRUE(before);
  EXPECT_NEAR(before->position[1], 0.0, 1e-12);
  const auto after = node.on_state(moving(1'005'000, 1.0025, 0.45));
  ASSERT_TRUE(after);
  EXPECT_NEAR(after->position[1] - 0.45, before->position[1] - 0.0, 1e-9) << "set point less state: no step";
  EXPECT_NEAR(node.smoother().largest_jump_m(), 0.45, 1e-9);
  EXPECT_NEAR(node.follower().deviation_m(), 0.0, 1e-9) << "the follower sees the state less the jump";
  // One second on, 0.1 m of it let go: the set point is 0.35 m off the path, towards the state.
  std::optional<kestrel::vehicle_command_t> later;
  for (int k = 2; k <= 201; ++k) later = node.on_state(moving(1'000'000 + 5'000 * k, 1.0 + 0.0025 * k, 0.45));
  ASSERT_TRUE(later);
  EXPECT_NEAR(later->position[1], 0.35, 1e-6);
}

// The smoother sees every state while following, not only those a command is due on; a jump
// beyond the largest offset still takes the vehicle off the path (hold); a new plan starts from
// the state as it is.
TEST(FollowerNode, JumpsBetweenCommandsCountBeyondTheLargestOffsetTheVehicleHoldsAndANewPlanStartsAfresh) {
  FollowerNodeOptions o;
  o.command_period_s = 0.02;
  FollowerNode node(o);
  node.on_plan(plan());
  ASSERT_TRUE(node.on_state(moving(1'000'000, 1.0, 0.0)));
  EXPECT_FALSE(node.on_state(moving(1'005'000, 1.0025, 0.3))) << "no command due: the jump is taken all the same";
  EXPECT_NEAR(node.smoother().offset().y(), 0.3, 1e-9);
  const auto next = node.on_state(moving(1'020'000, 1.01, 0.3));
  ASSERT_TRUE(next);
  EXPECT_NEAR(next->position[1], 0.3 - 0.1 * 0.015, 1e-9) << "the set point moved with it, 15 ms of it let go";
  // 1.5 m more: 0.5 m is held, the rest passes; 1.2 m off a path whose limit is 1 m: hold.
  const auto off = node.on_state(moving(1'040'000, 1.02, 1.8));
  ASSERT_TRUE(off);
  EXPECT_EQ(node.follower().status(), FollowStatus::kOffPath);
  // A new plan from the state as it is: no offset left to shift it.
  node.on_plan(plan());
  EXPECT_EQ(node.smoother().offset().norm(), 0.0);
}

TEST(FollowerNode, RefusesBadPlansAndStatesNamingTheChannel) {
  FollowerNode node(FollowerNodeOptions{});
  node.on_plan(plan());
  ASSERT_TRUE(node.on_state(state(1'000'000, 1, 0)));
  kestrel::plan_t bad = plan();
  bad.waypoints[1][1] = std::nan("");
  try {
    node.on_plan(bad);
    ADD_FAILURE() << "a plan with a NaN waypoint was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("PLAN"), std::string::npos) << e.what();
  }
  const auto hold = node.on_state(state(1'001'000, 1, 0));
  ASSERT_TRUE(hold) << "a refused plan stops a vehicle that was following";
  EXPECT_EQ(hold->mode, kestrel::vehicle_command_t::MODE_HOLD);
  kestrel::plan_t short_plan = plan();
  short_plan.num_waypoints = 3;
  EXPECT_THROW(node.on_plan(short_plan), InputError);
  node.on_plan(plan());
  kestrel::state_t nan_state = state(1'200'000, 1, 0);
  nan_state.T_world_body.orientation[0] = std::nan("");
  try {
    node.on_state(nan_state);
    ADD_FAILURE() << "a state with a NaN orientation was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("STATE"), std::string::npos) << e.what();
  }
}

TEST(FollowerNode, ReadsKestrelPlansOutputAndNamesTheLineOfAnError) {
  test::TempDir dir;
  const std::string good = (dir / "path.txt").string();
  {
    std::ofstream out(good);
    out << "# x y z yaw tr(Sigma)   length 4 m, goal tr(Sigma) 1\n0 0 1 0 0.4\n\n4 0 1 0.5 1.0\n";
  }
  const std::vector<Waypoint> w = read_waypoints(good);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_TRUE(w[1].position.isApprox(Eigen::Vector3d(4, 0, 1)));
  EXPECT_DOUBLE_EQ(w[1].yaw, 0.5);
  const std::string bad = (dir / "bad.txt").string();
  {
    std::ofstream out(bad);
    out << "0 0 1 0\n1 2 nan 0\n";
  }
  try {
    read_waypoints(bad);
    ADD_FAILURE() << "a NaN waypoint was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_waypoints((dir / "missing.txt").string()), InputError);
}

}  // namespace
}  // namespace kestrel::control
