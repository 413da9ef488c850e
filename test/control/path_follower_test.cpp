// PathFollower (path_follower.h) against hand-worked cases: the command on a straight path,
// the stop profile at the end, arrival, progress that never goes back (also on a path that
// passes close to itself), yaw interpolated the short way round with its rate, off the path, bad input.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "common/numbers.h"
#include "control/path_follower.h"

namespace kestrel::control {
namespace {

std::vector<Waypoint> straight() {  // 4 m along x at 1 m height, facing +x
  return {{Eigen::Vector3d(0, 0, 1), 0.0}, {Eigen::Vector3d(4, 0, 1), 0.0}};
}

VehicleState at(double x, double y, double z = 1.0) {
  VehicleState s;
  s.position = Eigen::Vector3d(x, y, z);
  return s;
}

TEST(PathFollower, IdleHoldsWhereTheVehicleIs) {
  PathFollower f;
  const FollowerCommand c = f.command(at(1, 2));
  EXPECT_EQ(f.status(), FollowStatus::kIdle);
  EXPECT_EQ(c.mode, FollowerCommand::Mode::kHold);
  EXPECT_TRUE(c.position.isApprox(Eigen::Vector3d(1, 2, 1)));
}

// The vehicle jumps along the path between commands in these cases: a search window as long as
// the path lets the progress follow (the window matters only where the path comes back).
FollowerOptions wide_window() {
  FollowerOptions o;  // cruise 0.5 m/s, decel 0.3 m/s^2, lookahead 0.3 m
  o.search_window_m = 10.0;
  return o;
}

TEST(PathFollower, OnAStraightPathCommandsTheNearestPointAndCruisesAlongIt) {
  PathFollower f(wide_window());
  f.set_path(straight());
  // 10 cm to the side of x = 1: the set point is the foot of the perpendicular, the velocity
  // is along the path at cruise speed (3 m left: sqrt(2 * 0.3 * 3) > 0.5).
  const FollowerCommand c = f.command(at(1.0, 0.1));
  EXPECT_EQ(c.mode, FollowerCommand::Mode::kPosition);
  EXPECT_NEAR(f.progress_m(), 1.0, 1e-12);
  EXPECT_NEAR(f.deviation_m(), 0.1, 1e-12);
  EXPECT_TRUE(c.position.isApprox(Eigen::Vector3d(1, 0, 1), 1e-12));
  EXPECT_TRUE(c.velocity.isApprox(Eigen::Vector3d(0.5, 0, 0), 1e-12));
  EXPECT_NEAR(c.yaw, 0.0, 1e-12);
  // 0.15 m from the end: v = sqrt(2 * 0.3 * 0.15) = 0.3 m/s.
  const FollowerCommand slow = f.command(at(3.85, 0.0));
  EXPECT_NEAR(slow.velocity.norm(), 0.3, 1e-9);
  EXPECT_EQ(f.status(), FollowStatus::kFollowing);
}

TEST(PathFollower, TheLastStretchAimsAtTheEndAndArrivesWithinTheRadius) {
  PathFollower f(wide_window());
  f.set_path(straight());
  f.command(at(3.95, 0.12));  // progress 3.95: within the 0.1 m radius of the end along the path
  EXPECT_EQ(f.status(), FollowStatus::kFollowing) << "0.13 m from the end: not yet arrived";
  const FollowerCommand c = f.command(at(3.97, 0.05));
  EXPECT_EQ(f.status(), FollowStatus::kArrived);
  EXPECT_TRUE(c.position.isApprox(Eigen::Vector3d(4, 0, 1)));
  EXPECT_TRUE(c.velocity.isZero());
  // Arrived is kept: the vehicle holds the end even when pushed off it a little.
  f.command(at(3.8, 0.1));
  EXPECT_EQ(f.status(), FollowStatus::kArrived);
}

TEST(PathFollower, ProgressNeverGoesBackNorShortCutsAPathThatPassesCloseToItself) {
  // A hairpin: out 3 m along y = 0, across 0.4 m, back along y = 0.4.
  FollowerOptions o;
  o.search_window_m = 1.0;
  PathFollower f(o);
  f.set_path({{Eigen::Vector3d(0, 0, 1), 0.0},
              {Eigen::Vector3d(3, 0, 1), 0.0},
              {Eigen::Vector3d(3, 0.4, 1), kPi},
              {Eigen::Vector3d(0, 0.4, 1), kPi}});
  f.command(at(1.0, 0.0));
  EXPECT_NEAR(f.progress_m(), 1.0, 1e-12);
  // Nearer the return leg (y = 0.3) than the outbound one, but the return leg's nearest point
  // is at s = 5.2 m, outside the search window: the progress stays on the outbound leg.
  f.command(at(1.2, 0.3));
  EXPECT_NEAR(f.progress_m(), 1.2, 1e-12);
  // Pushed back: the progress stays.
  f.command(at(0.5, 0.0));
  EXPECT_NEAR(f.progress_m(), 1.2, 1e-12);
}

// The yaw is the path's where the vehicle is along it (as the planner's belief model turns the
// camera), with the rate at which it turns there at the commanded speed.
TEST(PathFollower, YawIsInterpolatedTheShortWayRoundAtTheProgressWithItsRate) {
  PathFollower f;  // cruise 0.5 m/s
  // From yaw 170 deg to -170 deg over 2 m: the short way is +20 deg through 180.
  const double a = 170.0 * kPi / 180.0;
  f.set_path({{Eigen::Vector3d(0, 0, 1), a}, {Eigen::Vector3d(2, 0, 1), -a}});
  const FollowerCommand c = f.command(at(1.0, 0.0));  // half way: 180 deg
  EXPECT_NEAR(std::cos(c.yaw), -1.0, 1e-12);
  EXPECT_NEAR(std::remainder(c.yaw - kPi, 2 * kPi), 0.0, 1e-9);
  EXPECT_NEAR(c.yaw_rate, 0.5 * (20.0 * kPi / 180.0) / 2.0, 1e-12);  // 0.5 m/s * 10 deg per metre
  // A turn on the spot (two waypoints at one place) is a step: no rate to feed forward.
  PathFollower g;
  g.set_path({{Eigen::Vector3d(0, 0, 1), 0.0}, {Eigen::Vector3d(0, 0, 1), 1.0}, {Eigen::Vector3d(2, 0, 1), 1.0}});
  EXPECT_EQ(g.yaw_slope_at(0.0), 0.0);
  EXPECT_NEAR(g.yaw_at(0.5), 1.0, 1e-12);
}

TEST(PathFollower, FartherThanTheLargestDeviationItHoldsUntilANewPath) {
  PathFollower f;  // max deviation 1 m
  f.set_path(straight());
  f.command(at(1.0, 0.5));
  EXPECT_EQ(f.status(), FollowStatus::kFollowing);
  const FollowerCommand c = f.command(at(1.0, 1.2));
  EXPECT_EQ(f.status(), FollowStatus::kOffPath);
  EXPECT_EQ(c.mode, FollowerCommand::Mode::kHold);
  EXPECT_EQ(f.command(at(1.0, 0.0)).mode, FollowerCommand::Mode::kHold) << "back near the path: still waits";
  f.set_path(straight());
  EXPECT_EQ(f.command(at(1.0, 0.0)).mode, FollowerCommand::Mode::kPosition);
}

TEST(PathFollower, ASingleWaypointIsFlownTo) {
  PathFollower f;
  f.set_path({{Eigen::Vector3d(1, 0, 1), 0.3}});
  const FollowerCommand c = f.command(at(0.5, 0.0));
  EXPECT_EQ(c.mode, FollowerCommand::Mode::kPosition);
  EXPECT_TRUE(c.position.isApprox(Eigen::Vector3d(1, 0, 1)));
  EXPECT_NEAR(c.yaw, 0.3, 1e-12);
}

TEST(PathFollower, RefusesBadPathsStatesAndOptions) {
  PathFollower f;
  EXPECT_THROW(f.set_path({}), std::invalid_argument);
  EXPECT_THROW(f.set_path({{Eigen::Vector3d(0, std::nan(""), 1), 0.0}}), std::invalid_argument);
  EXPECT_EQ(f.status(), FollowStatus::kIdle);
  f.set_path(straight());
  EXPECT_THROW(f.command(at(std::nan(""), 0.0)), std::invalid_argument);
  FollowerOptions o;
  o.lookahead_m = 0.0;
  EXPECT_THROW(PathFollower{o}, std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::control
