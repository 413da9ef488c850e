// The follower closing the loop around the simulator's vehicle (drivers/sim/vehicle.h), in
// process: an L-shaped path and a staircase of right angles flown with the wind on, the
// controller fed the true state every 5 ms and the follower's command every 20 ms. The vehicle
// must keep to the path, turn its yaw with the path's at its progress, reach the end, stop
// there, and not overshoot it.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>

#include "common/numbers.h"
#include "common/transport/convert.h"
#include "control/follower_node.h"
#include "control/path_follower.h"
#include "drivers/sim/vehicle.h"

namespace kestrel::control {
namespace {

// Distance from p to the polyline.
double distance_to(const std::vector<Waypoint>& path, const Eigen::Vector3d& p) {
  double best = (p - path.front().position).norm();
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector3d a = path[i].position, b = path[i + 1].position;
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    best = std::min(best, (p - (a + t * (b - a))).norm());
  }
  return best;
}

struct Flight {
  double worst_m = 0.0;        ///< largest distance from the path, the whole 20 s
  double worst_yaw = 0.0;      ///< largest yaw error against the path's at the progress
  double fastest = 0.0;
  double arrived_at = -1.0;    ///< s
  sim::PathPoint end;          ///< at 20 s
  FollowStatus status = FollowStatus::kIdle;
  double progress_m = 0.0, length_m = 0.0;
};

Flight fly(const std::vector<Waypoint>& path) {
  const Eigen::Vector4d start(path.front().position.x(), path.front().position.y(), path.front().position.z(),
                              path.front().yaw);
  sim::VehicleFlight vehicle(start, sim::VehicleOptions{}, 5);  // default wind
  sim::VehicleLoop loop(vehicle, 0.003);
  PathFollower follower;  // 0.5 m/s
  follower.set_path(path);
  const double h = vehicle.options().control_period_s;
  Flight f;
  for (int k = 0; k * h < 20.0; ++k) {
    const double t = k * h;
    const sim::PathPoint q = vehicle.point(t);
    if (k % 4 == 0) {
      VehicleState s;
      s.position = q.p;
      s.yaw = q.yaw;
      const FollowerCommand c = follower.command(s);
      sim::VehicleCommand command;
      command.mode = c.mode == FollowerCommand::Mode::kHold ? sim::VehicleCommand::kHold : sim::VehicleCommand::kPosition;
      command.position = c.position;
      command.velocity = c.velocity;
      command.yaw = c.yaw;
      command.yaw_rate = c.yaw_rate;
      loop.set_command(command);
      if (f.arrived_at < 0 && follower.status() == FollowStatus::kArrived) f.arrived_at = t;
      if (follower.status() == FollowStatus::kFollowing)
        f.worst_yaw = std::max(f.worst_yaw, std::abs(std::remainder(q.yaw - follower.yaw_at(follower.progress_m()), 2 * kPi)));
    }
    f.worst_m = std::max(f.worst_m, distance_to(path, q.p));
    f.fastest = std::max(f.fastest, q.v.norm());
    loop.advance_to(t, sim::VehicleEstimate{q.p, q.v, q.yaw});
  }
  f.end = vehicle.point(20.0);
  f.status = follower.status();
  f.progress_m = follower.progress_m();
  f.length_m = follower.length_m();
  std::cout << "largest distance from the path " << f.worst_m << " m, yaw error " << f.worst_yaw
            << " rad, arrived after " << f.arrived_at << " s\n";
  return f;
}

TEST(FollowerWithVehicle, FliesAnLShapedPathWithinCentimetresAndStopsAtItsEnd) {
  const std::vector<Waypoint> path = {{Eigen::Vector3d(1, 1, 1), 0.0},
                                      {Eigen::Vector3d(4, 1, 1), 0.0},
                                      {Eigen::Vector3d(4, 3, 1.5), kPi / 2}};
  const Flight f = fly(path);
  // 5.7 m at 0.5 m/s with a stop: about 12 s.
  ASSERT_GT(f.arrived_at, 0.0) << "never arrived; status " << to_string(f.status) << " at " << f.progress_m << " of "
                               << f.length_m << " m";
  EXPECT_LT(f.arrived_at, 15.0);
  // 5.4 cm (the corner, rounded by the 0.3 m lookahead); 9.6 cm with the 0.5 m lookahead and
  // 0.5 m/s^2 stop of before 27 Nov.
  EXPECT_LT(f.worst_m, 0.07) << "distance from the path";
  EXPECT_LT(f.fastest, 0.5 * 1.2);
  // The camera turns where the planner's belief model has it turn: 0.038 rad at worst (at the
  // corner, where the rate steps), 0.086 with the 0.5 m lookahead, 0.19 with the yaw aimed at
  // the lookahead and no rate fed forward.
  EXPECT_LT(f.worst_yaw, 0.06);
  EXPECT_LT((f.end.p - path.back().position).norm(), 0.05);
  EXPECT_LT(f.end.v.norm(), 0.05);
  EXPECT_NEAR(std::remainder(f.end.yaw - kPi / 2, 2 * kPi), 0.0, 0.05);
}

// Right angles one metre apart, left and right, the yaw swinging with each leg: no leg is
// long enough to settle on before the next corner.
TEST(FollowerWithVehicle, FliesAStaircaseOfRightAnglesWithinCentimetres) {
  const std::vector<Waypoint> path = {{Eigen::Vector3d(1, 1, 1), 0.0}, {Eigen::Vector3d(2, 1, 1), 0.0},
                                      {Eigen::Vector3d(2, 2, 1), 1.5}, {Eigen::Vector3d(3, 2, 1), 0.0},
                                      {Eigen::Vector3d(3, 3, 1), 1.5}, {Eigen::Vector3d(4, 3, 1), 0.0}};
  const Flight f = fly(path);
  ASSERT_GT(f.arrived_at, 0.0) << "never arrived; status " << to_string(f.status);
  EXPECT_LT(f.arrived_at, 12.0);  // 5 m: 10.4 s
  EXPECT_LT(f.worst_m, 0.08);     // 6.2 cm; 10.6 cm with the 0.5 m lookahead and 0.5 m/s^2 stop
  EXPECT_LT(f.worst_yaw, 0.13);   // 0.109 rad; 0.18 with them
  EXPECT_LT((f.end.p - path.back().position).norm(), 0.05);
}

// A late SLAM correction in closed loop: the vehicle follows a straight path on an estimate
// 0.45 m off the truth sideways until, at 6 s, a correction puts the estimate on the truth
// in one 5 ms step (as the loop closure of floor's loop moved STATE). Fed to the controller
// as is, the step is a 0.45 m position error at once; through the follower's smoother it is let
// go at 0.1 m/s. Both reach the path; the smoothed one without the jolt.
struct Correction {
  double peak_accel = 0.0;  ///< the truth's largest sideways acceleration after the correction
  double off_path_end = 0.0;  ///< the truth's distance from the path line at the end
};

Correction fly_through_a_correction(double min_jump_m) {
  const std::vector<Waypoint> path = {{Eigen::Vector3d(0, 0, 1), 0.0}, {Eigen::Vector3d(12, 0, 1), 0.0}};
  const Eigen::Vector3d error_before(0.0, 0.45, 0.0);  // the estimate less the truth, until 6 s
  // The vehicle starts where its estimate puts it on the path's start.
  sim::VehicleFlight vehicle(Eigen::Vector4d(0.0, -0.45, 1.0, 0.0), sim::VehicleOptions{}, 5);
  sim::VehicleLoop loop(vehicle, 0.003);
  FollowerNodeOptions o;
  o.smoothing.min_jump_m = min_jump_m;
  FollowerNode node(o);
  node.set_path(path);
  const double h = vehicle.options().control_period_s;
  Correction c;
  for (int k = 0; k * h < 20.0; ++k) {
    const double t = k * h;
    const sim::PathPoint q = vehicle.point(t);
    const Eigen::Vector3d p = q.p + (t < 6.0 ? error_before : Eigen::Vector3d::Zero());
    kestrel::state_t m{};
    m.utime = static_cast<int64_t>(std::llround(t * 1e6));
    m.status = kestrel::state_t::STATUS_OK;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(q.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = p;
    m.T_world_body = transport::to_message(T);
    for (int i = 0; i < 3; ++i) m.velocity[i] = q.v[i];
    if (const auto command = node.on_state(m)) {
      sim::VehicleCommand v;
      v.mode = command->mode == kestrel::vehicle_command_t::MODE_HOLD ? sim::VehicleCommand::kHold
                                                                       : sim::VehicleCommand::kPosition;
      v.position = Eigen::Vector3d(command->position[0], command->position[1], command->position[2]);
      v.velocity = Eigen::Vector3d(command->velocity[0], command->velocity[1], command->velocity[2]);
      v.yaw = command->yaw;
      v.yaw_rate = command->yaw_rate;
      loop.set_command(v);
    }
    if (t >= 6.0) c.peak_accel = std::max(c.peak_accel, std::abs(q.a.y()));
    loop.advance_to(t, sim::VehicleEstimate{p, q.v, q.yaw});
  }
  c.off_path_end = std::abs(vehicle.point(20.0).p.y());
  std::cout << "min jump " << min_jump_m << " m: peak sideways acceleration " << c.peak_accel
            << " m/s^2 after the correction; " << c.off_path_end << " m off the path at the end\n";
  return c;
}

TEST(FollowerWithVehicle, ACorrectionThatMovesTheStateAtOnceIsFlownOntoThePathWithoutAJolt) {
  const Correction smoothed = fly_through_a_correction(JumpSmoothingOptions{}.min_jump_m);
  const Correction raw = fly_through_a_correction(std::numeric_limits<double>::infinity());
  EXPECT_LT(smoothed.off_path_end, 0.05);
  EXPECT_LT(raw.off_path_end, 0.05);
  // The wind alone gives a few tenths of a m/s^2 (wind_sigma 0.08 m/s^2 and the control's answer).
  EXPECT_LT(smoothed.peak_accel, 0.5);
  EXPECT_GT(raw.peak_accel, 2.0 * smoothed.peak_accel) << "the step the smoother takes out is a jolt without it";
}

}  // namespace
}  // namespace kestrel::control
