#include "drivers/sim/flight.h"

#include <algorithm>
#include <cmath>

#include "common/geometry/so3.h"

namespace kestrel::sim {
namespace {

// Path time tau(t) and its first two derivatives: tau' = s(t / T) with the quintic
// smoothstep s(x) = 10x^3 - 15x^4 + 6x^5 (s, s', s'' vanish at 0 and are 1, 0, 0 at 1), so
// the vehicle's acceleration and jerk are continuous through the ramp.
struct TimeWarp {
  double tau, d1, d2;
};

TimeWarp warp(double t, double ramp) {
  if (ramp <= 0.0) return {t, 1.0, 0.0};
  if (t <= 0.0) return {0.0, 0.0, 0.0};
  if (t >= ramp) return {t - 0.5 * ramp, 1.0, 0.0};  // integral of s over [0, 1] is 1/2
  const double x = t / ramp;
  const double x2 = x * x, x3 = x2 * x;
  // tau = T * integral of s = T (2.5 x^4 - 3 x^5 + x^6).
  const double tau = ramp * (2.5 * x3 * x - 3.0 * x3 * x2 + x3 * x3);
  const double s = 10 * x3 - 15 * x3 * x + 6 * x3 * x2;
  const double ds = (30 * x2 - 60 * x3 + 30 * x3 * x) / ramp;
  return {tau, s, ds};
}

}  // namespace

Eigen::Matrix3d flat_attitude(const Eigen::Vector3d& a_world, double yaw) {
  const Eigen::Vector3d z_b = (a_world + Eigen::Vector3d(0, 0, kGravity)).normalized();
  const Eigen::Vector3d heading(std::cos(yaw), std::sin(yaw), 0.0);
  const Eigen::Vector3d y_b = z_b.cross(heading).normalized();
  Eigen::Matrix3d R;
  R.col(0) = y_b.cross(z_b);
  R.col(1) = y_b;
  R.col(2) = z_b;
  return R;
}

PathPoint Flight::point(double t) const {
  const TimeWarp w = warp(t, ramp_s_);
  const PathPoint q = path(w.tau);
  PathPoint out;
  out.p = q.p;
  out.v = q.v * w.d1;
  out.a = q.a * (w.d1 * w.d1) + q.v * w.d2;
  out.yaw = q.yaw;
  return out;
}

Eigen::Matrix3d Flight::attitude(double t) const {
  const PathPoint q = point(t);
  return flat_attitude(q.a, q.yaw);
}

MotionState Flight::state(double t) const {
  const PathPoint q = point(t);
  MotionState s;
  s.t = t;
  s.T_world_body.linear() = flat_attitude(q.a, q.yaw);
  s.T_world_body.translation() = q.p;
  s.v_world = q.v;
  s.a_world = q.a;
  s.omega_body = angular_rate(s.T_world_body.linear(), t, [this](double x) { return attitude(x); });
  return s;
}

}  // namespace kestrel::sim
