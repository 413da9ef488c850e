#pragma once
// Static alignment: the first state of the filter from IMU readings taken while the vehicle
// stands still. The mean specific force gives roll and pitch (gravity is the only force), the
// mean rate gives the gyro bias, and the magnitude of the mean specific force the
// accelerometer bias along gravity. Yaw and position are not observable: they come from the
// options (they define the world frame). The window restarts while the readings vary more
// than a still vehicle allows.

#include <optional>
#include <vector>

#include "estimator/imu.h"
#include "estimator/nav_state.h"
#include "estimator/options.h"

namespace kestrel::estimator {

struct InitialState {
  NavState nav;
  Matrix15d P;
  ImuSample last;  ///< the sample the state is for (its utime and reading)
};

class StaticInitializer {
 public:
  StaticInitializer(const InitOptions& options, double gravity)
      : options_(options), gravity_(gravity) {}
  /// Adds a sample (in time order); returns the initial state once a still window is full.
  std::optional<InitialState> add(const ImuSample& sample);
  void reset() { window_.clear(); }
  int restarts() const { return restarts_; }

 private:
  InitOptions options_;
  double gravity_;
  std::vector<ImuSample> window_;
  int restarts_ = 0;
};

/// R_world_body with the given yaw whose z axis agrees with a measured specific force.
Eigen::Matrix3d attitude_from_gravity(const Eigen::Vector3d& specific_force_body, double yaw);

}  // namespace kestrel::estimator
