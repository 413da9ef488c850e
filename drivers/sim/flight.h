#pragma once
// A flight: the exact motion of the simulated vehicle, from which the camera poses, the IMU
// samples and the ground truth are all derived.
//
// A subclass gives the path: position, velocity, acceleration (world frame, exact) and yaw
// as functions of path time. The base class adds what every flight shares:
//  * a take-off ramp: the vehicle starts at rest and path time tau(t) accelerates smoothly
//    (tau' = quintic smoothstep over `ramp_s`), so velocity, acceleration and jerk are
//    continuous from t = 0;
//  * the attitude of a quadrotor following the path (differential flatness): body z along
//    the thrust a + g e_z, body x as close as possible to the yaw heading;
//  * the body angular rate, R^T dR/dt, by a five-point central difference of that exact
//    attitude (step 1 ms, error O(h^4), below 1e-9 rad/s for these paths).
// Every function is defined for all t >= 0 (paths repeat), is deterministic and thread-safe.

#include <Eigen/Geometry>
#include <string>

namespace kestrel::sim {

/// Standard gravity, m/s^2 (world z up: gravity is -kGravity e_z).
constexpr double kGravity = 9.80665;

/// A point of a path (world frame, SI units).
struct PathPoint {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  double yaw = 0.0;       ///< heading of body x about world z, radians
};

/// The full motion state of the body at time t (seconds since the flight began).
struct MotionState {
  double t = 0.0;
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();      ///< m/s
  Eigen::Vector3d a_world = Eigen::Vector3d::Zero();      ///< m/s^2, kinematic (no gravity)
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();   ///< rad/s, body axes

  /// What an ideal accelerometer reads: R^T (a + g e_z), m/s^2 (+g up at rest).
  Eigen::Vector3d specific_force_body() const {
    return T_world_body.linear().transpose() * (a_world + Eigen::Vector3d(0, 0, kGravity));
  }
};

class Flight {
 public:
  explicit Flight(double ramp_s = 2.0) : ramp_s_(ramp_s) {}
  virtual ~Flight() = default;

  /// The flight's name, as on the command line.
  virtual std::string name() const = 0;

  /// The path at path time tau (tau >= 0; defined for all tau, usually periodic).
  virtual PathPoint path(double tau) const = 0;

  /// The path point at flight time t, with the take-off ramp applied.
  PathPoint point(double t) const;
  /// Body attitude at flight time t (flatness; see the header comment).
  Eigen::Matrix3d attitude(double t) const;
  /// Everything at flight time t. Virtual for paths that are smooth only piecewise (the
  /// closed-loop vehicle), which difference their attitude within one piece.
  virtual MotionState state(double t) const;

  double ramp_s() const { return ramp_s_; }

 private:
  double ramp_s_;
};

/// Attitude of a vehicle whose thrust produces acceleration `a` (world) at heading `yaw`.
Eigen::Matrix3d flat_attitude(const Eigen::Vector3d& a_world, double yaw);

/// The body angular rate at t from the attitude function R(t') near t (five-point central
/// difference, step 1 ms): R^T dR/dt, made skew.
template <typename AttitudeAt>
Eigen::Vector3d angular_rate(const Eigen::Matrix3d& R, double t, AttitudeAt&& attitude_at);

template <typename AttitudeAt>
Eigen::Vector3d angular_rate(const Eigen::Matrix3d& R, double t, AttitudeAt&& attitude_at) {
  constexpr double h = 1e-3;
  const Eigen::Matrix3d R_dot =
      (attitude_at(t - 2 * h) - 8.0 * attitude_at(t - h) + 8.0 * attitude_at(t + h) - attitude_at(t + 2 * h)) /
      (12.0 * h);
  const Eigen::Matrix3d omega_hat = R.transpose() * R_dot;
  const Eigen::Matrix3d skew = 0.5 * (omega_hat - omega_hat.transpose());
  return Eigen::Vector3d(skew(2, 1), skew(0, 2), skew(1, 0));
}

}  // namespace kestrel::sim
