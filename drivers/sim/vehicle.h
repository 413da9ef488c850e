#pragma once
// The closed-loop vehicle: a holonomic point mass with yaw, flown by a position controller
// from commands (hold, velocity, position; the fields of vehicle_command_t) and from what
// the controller believes the state is (the estimator's STATE, or the truth).
//
// Dynamics, exact within each control period h (inputs held constant, ZOH):
//   a'' = (a_cmd + w - a) / T^2 - 2 a' / T  thrust/attitude lag, critically damped,
//   p'' = a                                  T = response_s / 2: a and the jerk a' are
//                                            continuous, so are the flatness attitude
//                                            (flight.h) and its angular rate (the gyro)
//   r' = (r_cmd - r) / yaw_response_s       yaw rate r, yaw' = r
// with w a slow random acceleration (wind, an Ornstein-Uhlenbeck process drawn from the
// seed), so holding position needs feedback. The solution is closed-form (exponentials), so
// path(tau) is exact at any time inside the committed history; the IMU and the camera read
// the vehicle through the ordinary Flight interface.
//
// Invariants: the history is committed in order, one control period at a time (step());
// path(tau) for tau past the committed end continues the last segment's inputs, so it is
// final only for tau <= end_s(); a driver keeps end_s() ahead of every state() it asks for
// by the IMU's 2 ms difference step plus half a motion-blur exposure (VehicleLoop does).
// |a_cmd| <= max_accel_m_s2 and the velocity the controller aims at is within max_speed_m_s.

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <string>

#include "drivers/sim/flight.h"
#include "drivers/sim/random.h"

namespace kestrel::sim {

/// What the vehicle is told to do (vehicle_command_t's fields, world frame, SI units).
struct VehicleCommand {
  enum Mode { kHold = 0, kVelocity = 1, kPosition = 2 };
  Mode mode = kHold;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< kVelocity: target; kPosition: feed-forward
  double yaw_rate = 0.0;                               ///< kVelocity: target; kPosition: feed-forward
};

/// What the controller believes (from STATE, or the truth).
struct VehicleEstimate {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  double yaw = 0.0;
};

struct VehicleOptions {
  double control_period_s = 0.005;   ///< controller and input update period (200 Hz)
  double response_s = 0.12;          ///< acceleration lag (attitude loop, two poles at 2/response_s), s
  double yaw_response_s = 0.1;       ///< yaw-rate lag, s
  double max_speed_m_s = 1.5;
  double max_accel_m_s2 = 3.0;
  double max_yaw_rate = 2.1;         ///< rad/s (120 deg/s)
  double position_gain = 1.2;        ///< 1/s: commanded velocity per metre of position error
  double velocity_gain = 3.0;        ///< 1/s: commanded acceleration per m/s of velocity error
  double yaw_gain = 2.0;             ///< 1/s
  double wind_sigma_m_s2 = 0.08;     ///< stationary std of the wind acceleration, per axis (z: half)
  double wind_time_s = 3.0;          ///< its correlation time
  double history_s = 30.0;           ///< how much of the past path stays queryable
};

/// The controller: cascaded P position -> P velocity loops with limits. Pure function of
/// its inputs, so the same estimates give the same commands.
struct ControlOutput {
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  ///< world, m/s^2, gravity not included
  double yaw_rate = 0.0;
};
ControlOutput control(const VehicleCommand& command, const VehicleEstimate& estimate, const VehicleOptions& o);

class VehicleFlight : public Flight {
 public:
  /// At rest at `start` (x, y, z, yaw), hovering; `seed` keys the wind.
  VehicleFlight(const Eigen::Vector4d& start, const VehicleOptions& options, uint64_t seed);

  std::string name() const override { return "vehicle"; }
  PathPoint path(double tau) const override;
  /// As Flight::state, but the angular rate differences the attitude of the control period
  /// that holds t (continued analytically past its ends): across periods the angular
  /// acceleration jumps, and a stencil straddling a jump would be off by O(h * jump).
  MotionState state(double t) const override;

  /// Commits the next control period under these inputs (the wind is added here).
  void step(const ControlOutput& input);
  /// End of the committed history, seconds since t = 0.
  double end_s() const { return end_s_; }
  /// Back to rest at the start, t = 0, with the same wind.
  void reset();
  const VehicleOptions& options() const { return options_; }

 private:
  struct Segment {
    double t0;
    Eigen::Vector3d p0, v0, a0, j0, a_in;  // a_in: commanded acceleration plus wind
    double yaw0, r0, r_in;
  };
  PathPoint evaluate(const Segment& s, double tau, Eigen::Vector3d* jerk = nullptr) const;

  Eigen::Vector4d start_;
  VehicleOptions options_;
  uint64_t seed_;
  Rng wind_rng_;
  Eigen::Vector3d wind_ = Eigen::Vector3d::Zero();
  std::deque<Segment> history_;
  int64_t first_step_ = 0;  // index of history_.front(): it starts at first_step_ * period
  double end_s_ = 0.0;
};

/// Drives a VehicleFlight from commands and estimates: keeps its history committed far
/// enough ahead of the simulation's next event.
class VehicleLoop {
 public:
  /// `lookahead_s`: how far past the asked time the path must be final (2 ms for the IMU's
  /// difference, plus half the exposure with motion blur).
  VehicleLoop(VehicleFlight& vehicle, double lookahead_s);

  /// kHold is latched into a position command at the next advance_to's estimate.
  void set_command(const VehicleCommand& command);
  /// The estimates now come from another source (the first usable STATE after the truth stood
  /// in). A hold no command has replaced yet is latched again at the next estimate: "hold where
  /// it is" is then where the new source says it is, whatever its world (an estimator started
  /// at its own origin does not share the sim's).
  void estimate_source_changed();
  const VehicleCommand& command() const { return command_; }
  /// Commits control periods, each from `estimate`, until the path is final up to t_s.
  void advance_to(double t_s, const VehicleEstimate& estimate);

 private:
  VehicleFlight& vehicle_;
  double lookahead_s_;
  VehicleCommand command_;
  bool latch_hold_ = true;  // the vehicle starts holding where it is
  bool commanded_ = false;  // a command has come (the start's hold is no longer in force)
};

/// A hold command at the world's start pose (x, y, z, yaw).
VehicleCommand hold_at(const Eigen::Vector4d& pose);

}  // namespace kestrel::sim
