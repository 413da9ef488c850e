// The closed-loop vehicle (vehicle.h): position hold against wind with and without feedback,
// a step to a set point within the speed and acceleration limits, velocity tracking, the
// hold latch, a turning yaw with its rate fed forward, an exact smooth path (derivatives and angular rate), noiseless IMU samples that
// integrate back to its truth, and determinism.

#include <gtest/gtest.h>

#include <cmath>

#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "drivers/sim/imu.h"
#include "drivers/sim/vehicle.h"

namespace kestrel::sim {
namespace {

const Eigen::Vector4d kStart(1.0, 2.0, 1.2, 0.5);

// Flies the vehicle from t0 to t1 with the controller fed the exact state every control
// period (or, with `feedback` false, no control at all: it drifts with the wind).
struct Flown {
  double max_error = 0.0, max_speed = 0.0, max_accel = 0.0;
};
Flown fly(VehicleFlight& vehicle, VehicleLoop& loop, double t0, double t1, bool feedback = true,
          const Eigen::Vector3d& target = kStart.head<3>()) {
  Flown f;
  const double h = vehicle.options().control_period_s;
  for (double t = t0; t < t1; t += h) {
    const PathPoint q = vehicle.point(t);
    f.max_error = std::max(f.max_error, (q.p - target).norm());
    f.max_speed = std::max(f.max_speed, q.v.norm());
    f.max_accel = std::max(f.max_accel, q.a.norm());
    if (feedback) {
      loop.advance_to(t, VehicleEstimate{q.p, q.v, q.yaw});
    } else {
      while (vehicle.end_s() < t + 0.01) vehicle.step(ControlOutput{});
    }
  }
  return f;
}

TEST(VehicleTest, HoldsPositionAgainstTheWindOnlyWithFeedback) {
  VehicleFlight held(kStart, VehicleOptions{}, 3), drifting(kStart, VehicleOptions{}, 3);
  VehicleLoop hold_loop(held, 0.003), idle_loop(drifting, 0.003);
  const Flown with = fly(held, hold_loop, 0.0, 90.0);
  const Flown without = fly(drifting, idle_loop, 0.0, 90.0, false);
  EXPECT_LT(with.max_error, 0.08);      // a few centimetres of wind-driven wobble
  EXPECT_GT(without.max_error, 1.0);    // the same wind carries an uncontrolled vehicle away
  EXPECT_LT(with.max_speed, 0.15);
}

TEST(VehicleTest, FliesToASetPointWithinItsLimits) {
  VehicleOptions o;
  o.wind_sigma_m_s2 = 0.0;
  VehicleFlight vehicle(kStart, o, 1);
  VehicleLoop loop(vehicle, 0.003);
  fly(vehicle, loop, 0.0, 1.0);
  VehicleCommand go;
  go.mode = VehicleCommand::kPosition;
  go.position = kStart.head<3>() + Eigen::Vector3d(3.0, -2.0, 0.5);
  go.yaw = kStart[3] + 2.0;
  loop.set_command(go);
  const Flown f = fly(vehicle, loop, 1.0, 9.0, true, go.position);
  EXPECT_GT(f.max_speed, 0.9 * o.max_speed_m_s);  // long enough a hop to reach cruise speed
  EXPECT_LT(f.max_speed, 1.03 * o.max_speed_m_s);
  EXPECT_LT(f.max_accel, o.max_accel_m_s2 + 1e-9);
  const PathPoint end = vehicle.point(9.0);
  EXPECT_LT((end.p - go.position).norm(), 0.02);
  EXPECT_LT(end.v.norm(), 0.02);
  EXPECT_NEAR(std::remainder(end.yaw - go.yaw, 2 * kPi), 0.0, 0.01);
}

TEST(VehicleTest, TracksAVelocityCommandAndLatchesAHold) {
  VehicleOptions o;
  o.wind_sigma_m_s2 = 0.0;
  VehicleFlight vehicle(kStart, o, 1);
  VehicleLoop loop(vehicle, 0.003);
  VehicleCommand move;
  move.mode = VehicleCommand::kVelocity;
  move.velocity = Eigen::Vector3d(0.4, 0.3, 0.0);
  move.yaw_rate = 0.5;
  loop.set_command(move);
  fly(vehicle, loop, 0.0, 4.0);
  const PathPoint moving = vehicle.point(4.0);
  EXPECT_LT((moving.v - move.velocity).norm(), 0.01);
  EXPECT_NEAR(std::remainder(vehicle.point(4.0).yaw - vehicle.point(3.0).yaw, 2 * kPi), 0.5, 0.01);
  VehicleCommand stop;
  stop.mode = VehicleCommand::kHold;
  loop.set_command(stop);
  fly(vehicle, loop, 4.0, 10.0, true, moving.p);
  // Held where the hold arrived, give or take the braking distance (v^2 / (2 a) ~ 0.1 m).
  const PathPoint held = vehicle.point(10.0);
  EXPECT_LT((held.p - moving.p).norm(), 0.25);
  EXPECT_LT(held.v.norm(), 0.01);
  EXPECT_LT((vehicle.point(9.0).p - held.p).norm(), 0.005);
}

// Flying on an estimator whose world is not the sim's (started at its own origin): the hold
// latched on the truth before the first STATE is latched again on the first estimate of the
// new source, so the vehicle stays where it is instead of flying to the truth's coordinates
// in the estimator's world. Once commanded, a change of source changes nothing.
TEST(VehicleTest, AChangeOfEstimateSourceLatchesTheStartsHoldAgainUntilCommanded) {
  VehicleOptions o;
  o.wind_sigma_m_s2 = 0.0;
  const Eigen::Isometry3d T_estimator_sim(Eigen::Translation3d(-kStart.head<3>()));  // the estimator's origin at the start
  const auto in_estimator = [&](const PathPoint& q) { return VehicleEstimate{T_estimator_sim * q.p, q.v, q.yaw}; };
  VehicleFlight vehicle(kStart, o, 1);
  VehicleLoop loop(vehicle, 0.003);
  const double h = o.control_period_s;
  double t = 0.0;
  for (; t < 0.5; t += h) loop.advance_to(t, [&] { const PathPoint q = vehicle.point(t); return VehicleEstimate{q.p, q.v, q.yaw}; }());
  loop.estimate_source_changed();
  for (; t < 5.0; t += h) loop.advance_to(t, in_estimator(vehicle.point(t)));
  EXPECT_LT((vehicle.point(5.0).p - kStart.head<3>()).norm(), 0.01) << "it flew to the truth's start in the estimator's world";

  VehicleCommand go;  // in the estimator's world: 1 m along x from where it is
  go.mode = VehicleCommand::kPosition;
  go.position = Eigen::Vector3d(1.0, 0.0, 0.0);
  go.yaw = kStart[3];
  loop.set_command(go);
  loop.estimate_source_changed();  // a commanded flight keeps its command
  for (; t < 12.0; t += h) loop.advance_to(t, in_estimator(vehicle.point(t)));
  EXPECT_LT((vehicle.point(12.0).p - (kStart.head<3>() + Eigen::Vector3d(1.0, 0.0, 0.0))).norm(), 0.02);
}

// A position command whose yaw turns at 0.5 rad/s: with that rate as feed-forward the yaw
// follows it (zero steady error; only the yaw rate's 0.1 s lag while it builds up), without
// it the yaw loop lags by rate / gain = 0.25 rad.
TEST(VehicleTest, PositionModeTracksATurningYawWithTheYawRateFeedForward) {
  VehicleOptions o;
  o.wind_sigma_m_s2 = 0.0;
  for (const bool feed_forward : {true, false}) {
    VehicleFlight vehicle(kStart, o, 1);
    VehicleLoop loop(vehicle, 0.003);
    const double h = o.control_period_s, rate = 0.5;
    double error_at_4s = 0.0;
    for (double t = 0.0; t < 4.0 + h / 2; t += h) {
      VehicleCommand turn = hold_at(kStart);
      turn.yaw = kStart[3] + rate * t;
      turn.yaw_rate = feed_forward ? rate : 0.0;
      loop.set_command(turn);
      const PathPoint q = vehicle.point(t);
      error_at_4s = std::remainder(turn.yaw - q.yaw, 2 * kPi);
      loop.advance_to(t, VehicleEstimate{q.p, q.v, q.yaw});
    }
    if (feed_forward) {
      EXPECT_NEAR(error_at_4s, 0.0, 0.005);
    } else {
      EXPECT_NEAR(error_at_4s, rate / o.yaw_gain, 0.01);
    }
  }
}

TEST(VehicleTest, PathIsSmoothAndItsDerivativesAreExact) {
  VehicleFlight vehicle(kStart, VehicleOptions{}, 7);
  VehicleLoop loop(vehicle, 0.003);
  VehicleCommand go = hold_at(kStart + Eigen::Vector4d(1.0, 1.0, 0.0, 1.0));
  loop.set_command(go);
  fly(vehicle, loop, 0.0, 6.0);
  const double h = 1e-5;
  for (double t = 0.0517; t < 5.9; t += 0.4931) {
    const MotionState s = vehicle.state(t);
    const Eigen::Vector3d v = (vehicle.point(t + h).p - vehicle.point(t - h).p) / (2 * h);
    const Eigen::Vector3d a = (vehicle.point(t + h).v - vehicle.point(t - h).v) / (2 * h);
    EXPECT_LT((v - s.v_world).norm(), 1e-6) << "t = " << t;
    EXPECT_LT((a - s.a_world).norm(), 1e-5) << "t = " << t;
    const Eigen::Matrix3d predicted = s.T_world_body.linear() * so3::exp(s.omega_body * 1e-4);
    EXPECT_LT(so3::angle(predicted.transpose() * vehicle.attitude(t + 1e-4)), 1e-6) << "t = " << t;
  }
  // Continuity across a segment boundary.
  const double b = 200 * vehicle.options().control_period_s;
  EXPECT_LT((vehicle.point(b - 1e-9).a - vehicle.point(b + 1e-9).a).norm(), 1e-6);
}

TEST(VehicleTest, NoiselessImuIntegratesBackToItsTruth) {
  VehicleFlight vehicle(kStart, VehicleOptions{}, 2);
  VehicleLoop loop(vehicle, 0.003);
  loop.set_command(hold_at(kStart + Eigen::Vector4d(1.5, -1.0, 0.3, -1.0)));
  fly(vehicle, loop, 0.0, 10.1);  // the whole path is committed before the IMU reads it
  ImuOptions io;
  io.noise = false;
  io.rate_hz = 1000.0;
  ImuSimulator imu(vehicle, io, 1);
  // The inputs change every control period, so the motion is smooth only within a period
  // (the snap jumps between periods): RK4 across those kinks (sim_fixture's integrate) is
  // first-order. Trapezoidal steps of one sample period, each inside one control period, are
  // second-order accurate; at 1 kHz their error (~dt^2 times the snap of a saturated
  // 2 m hop) is well under the 1 mm asked.
  const double dt = 1.0 / io.rate_hz;
  const MotionState s0 = vehicle.state(0.0);
  Eigen::Matrix3d R = s0.T_world_body.linear();
  Eigen::Vector3d v = s0.v_world, p = s0.T_world_body.translation();
  const Eigen::Vector3d g(0, 0, -kGravity);
  ImuSample a = imu.next();
  for (int k = 0; k < 10000; ++k) {
    const ImuSample b = imu.next();
    const Eigen::Matrix3d R_next = R * so3::exp(0.5 * dt * (a.gyro + b.gyro));
    const Eigen::Vector3d f0 = R * a.accel + g, f1 = R_next * b.accel + g;
    p += v * dt + dt * dt / 6.0 * (2.0 * f0 + f1);
    v += 0.5 * dt * (f0 + f1);
    R = R_next;
    a = b;
  }
  const MotionState truth = vehicle.state(10.0);
  EXPECT_LT((p - truth.T_world_body.translation()).norm(), 1e-3);
  EXPECT_LT((v - truth.v_world).norm(), 1e-3);
  EXPECT_LT(so3::angle(R.transpose() * truth.T_world_body.linear()), 1e-5);
}

TEST(VehicleTest, SameSeedSamePathAndResetReplays) {
  VehicleFlight a(kStart, VehicleOptions{}, 11), b(kStart, VehicleOptions{}, 11), c(kStart, VehicleOptions{}, 12);
  VehicleLoop la(a, 0.003), lb(b, 0.003), lc(c, 0.003);
  fly(a, la, 0.0, 5.0);
  fly(b, lb, 0.0, 5.0);
  fly(c, lc, 0.0, 5.0);
  EXPECT_EQ(a.point(4.9).p, b.point(4.9).p);
  EXPECT_NE(a.point(4.9).p, c.point(4.9).p);
  const Eigen::Vector3d before = a.point(4.9).p;
  a.reset();
  VehicleLoop again(a, 0.003);
  fly(a, again, 0.0, 5.0);
  EXPECT_EQ(a.point(4.9).p, before);
  // Only the last history_s seconds stay queryable.
  VehicleOptions short_memory;
  short_memory.history_s = 1.0;
  VehicleFlight d(kStart, short_memory, 11);
  VehicleLoop ld(d, 0.003);
  fly(d, ld, 0.0, 5.0);
  EXPECT_EQ(d.point(4.9).p, before);
  EXPECT_THROW(d.point(2.0), std::out_of_range);
}

}  // namespace
}  // namespace kestrel::sim
