#pragma once
// The first state of the filter from IMU readings, when no state is given.
//
// Still start (static alignment): over a window of duration_s in which the vehicle stands
// still, the mean specific force gives roll and pitch (gravity is the only force), the mean
// rate the gyro bias, and the magnitude of the mean specific force the accelerometer bias
// along gravity. The window restarts while the readings vary more than a still vehicle
// allows, or turn at a steady rate no gyro bias has.
//
// Moving start: after moving_start_after_s without a still window, the last window's
// specific forces, rotated by the integrated gyro into the body frame of its last sample, are
// averaged. That mean is gravity plus the window's mean acceleration, so it gives roll and
// pitch up to a tilt of about |a| / g, and the covariance says so (moving_sigma_tilt); the
// velocity is unknown (moving_sigma_velocity) and the gyro bias unmeasured. The visual
// odometry then makes velocity, tilt and biases observable.
//
// An IMU cannot tell standing still from cruising at a constant velocity; the visual odometry
// can. A window in which a VO update showed the camera moving (significantly, and faster
// than max_still_vo_speed against its reference frame) is not still: the filter then starts
// on the move, where the velocity is unknown rather than wrongly known to be zero (an
// estimator restarted in flight found "still" windows in the demo's figure-eight).
//
// Either way yaw and position are not observable: they come from the options (they define
// the world frame).

#include <optional>
#include <vector>

#include "estimator/imu.h"
#include "estimator/inputs.h"
#include "estimator/nav_state.h"
#include "estimator/options.h"

namespace kestrel::estimator {

struct InitialState {
  NavState nav;
  Matrix15d P;
  ImuSample last;       ///< the sample the state is for (its utime and reading)
  bool moving = false;  ///< started on the move (no still window)
};

class Initializer {
 public:
  Initializer(const InitOptions& options, double gravity) : options_(options), gravity_(gravity) {}
  /// Adds a sample (in time order); returns the initial state once a still window is full,
  /// or once moving_start_after_s has passed without one.
  std::optional<InitialState> add(const ImuSample& sample);
  /// A VO update received before the start (any order against the IMU samples).
  void add_vo(const VoUpdate& update);
  void reset();
  /// Windows that were not still.
  int restarts() const { return restarts_; }

 private:
  InitialState still_start(const Eigen::Vector3d& mean_w, const Eigen::Vector3d& mean_a) const;
  InitialState moving_start() const;

  InitOptions options_;
  double gravity_;
  std::vector<ImuSample> window_;
  int64_t first_utime_ = -1;
  int64_t last_vo_motion_utime_ = -1;  ///< the newest frame at which the VO saw motion
  int restarts_ = 0;
};

/// R_world_body with the given yaw whose z axis agrees with a measured specific force.
Eigen::Matrix3d attitude_from_gravity(const Eigen::Vector3d& specific_force_body, double yaw);

/// Covariance of dtheta (body frame) for an attitude whose tilt is known to sigma_tilt and its
/// yaw (about world z) to sigma_yaw.
Eigen::Matrix3d attitude_covariance(const Eigen::Matrix3d& R_world_body, double sigma_tilt,
                                    double sigma_yaw);

/// The largest standard deviation of roll and pitch (tilt) in a covariance of dtheta (body
/// frame), whatever the yaw's: the inverse of attitude_covariance for its tilt.
double tilt_sigma(const Eigen::Matrix3d& R_world_body, const Eigen::Matrix3d& P_theta);

/// The mean of the window's specific forces, each rotated into the body frame of the last
/// sample by the gyro integrated between them (bias ignored): gravity plus the mean
/// acceleration, in one frame even when the vehicle turns.
Eigen::Vector3d mean_specific_force_in_last_frame(const std::vector<ImuSample>& window);

}  // namespace kestrel::estimator
