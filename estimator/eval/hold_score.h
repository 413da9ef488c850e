#pragma once
// How well a vehicle held a point (the paper's Fig. 14): the deviation of the TRUE position
// from the hold target, and the error of the estimate the controller flew on (truth vs
// estimate at the same time stamps). No LCM here: the tool (hold_main.cpp) reads the log.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace kestrel::estimator {

/// One position (and yaw) at a time stamp, world frame of the simulation.
struct TimedPosition {
  int64_t utime = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double yaw = 0.0;
};

/// Mean and maximum of a distance over samples.
struct Spread {
  double mean = 0.0;
  double max = 0.0;
  int64_t samples = 0;
};

struct HoldScore {
  Spread truth_horizontal;  ///< |truth - target| in x, y
  Spread truth_3d;          ///< |truth - target|
  Spread error_horizontal;  ///< |truth - estimate| in x, y, at the estimate's time stamps
  Spread error_3d;
  Spread error_yaw;         ///< |wrap(truth yaw - estimate yaw)|, rad
  double scored_from_s = 0.0;  ///< seconds after the first truth sample
  double scored_to_s = 0.0;
  int64_t unmatched_estimates = 0;  ///< estimates with no truth sample within the tolerance
};

/// Scores the truth samples with utime in [first truth + from_s, last truth] against
/// `target`, and the estimates in that window against the truth sample nearest in time
/// (within `match_tolerance_us`; farther ones are counted as unmatched). Both sequences must
/// be in time order; throws std::invalid_argument if the truth is empty, out of order, or no
/// truth sample falls in the window.
HoldScore score_hold(const std::vector<TimedPosition>& truth,
                     const std::vector<TimedPosition>& estimate, const Eigen::Vector3d& target,
                     double from_s, int64_t match_tolerance_us = 3000);

}  // namespace kestrel::estimator
