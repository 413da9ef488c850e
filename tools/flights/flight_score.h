#pragma once
// Scores one closed-loop flight against the simulator's truth (the paper's Figs. 15-17
// question: did the vehicle get there, and did it stay localised on the way?). LCM-free: the
// recording is read into a FlightRecord by flight_log.h.
//
//  * arrived: the true position within `radius_m` of the goal at the end of the flight;
//    arrival_s is when it first came within that radius and stayed.
//  * the estimator's true error: |p_STATE - p_truth| at each usable STATE (OK or DEGRADED)
//    that has a truth sample at its utime (mean, max; in the simulator's world, no alignment:
//    the estimator starts at the true pose).
//  * consistency: the position NEES e' P^-1 e under STATE's own covariance (3 dof): its mean,
//    and the share of states inside the 3-sigma bound (chi^2_3 at 99.73 %: 14.16).
//  * the belief model beside the estimator: at each planned node, tr of the planner's
//    predicted position covariance and of STATE's, at the instant the true track came
//    nearest that node after the previous one.

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace kestrel::flights {

struct TruthSample {
  int64_t utime = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< body position, world frame
};

struct StateSample {
  int64_t utime = 0;
  bool usable = false;                          ///< status OK or DEGRADED
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< body position, world frame
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();  ///< its covariance
};

struct FlightRecord {
  std::vector<TruthSample> truth;   ///< in time order
  std::vector<StateSample> states;  ///< in time order
  int64_t vo_frames = 0;
  int64_t vo_failures = 0;  ///< VO_UPDATE with a status other than OK
  int64_t vo_gross = 0;     ///< frames whose VO velocity is off by more than 1 m/s (kestrel eval's rule)
  int keyframes = 0;        ///< in SLAM's final graph
  int loop_closures = 0;    ///< loop-closure edges in SLAM's final graph
};

struct PlannedPath {
  std::vector<Eigen::Vector3d> nodes;
  std::vector<double> predicted_trace;  ///< tr of the belief model's position covariance, per node
};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct FlightScore {
  bool arrived = false;
  double arrival_s = kNaN;         ///< since the first truth sample; NaN if never
  double final_distance_m = kNaN;  ///< true position to the goal at the end
  int64_t states_scored = 0;
  double error_mean_m = kNaN, error_max_m = kNaN;
  double nees_mean = kNaN;       ///< position NEES, 3 dof (consistent: about 3)
  double inside_3sigma = kNaN;   ///< share of states with NEES below 14.16
  double flown_s = 0.0;          ///< truth span
  std::vector<double> errors_m;  ///< per scored state, for plots
  std::vector<int64_t> error_utimes;
  std::vector<double> flown_trace;  ///< tr of STATE's position covariance at each planned node (NaN: none)
};

/// Throws std::invalid_argument when the record has no truth.
FlightScore score_flight(const FlightRecord& record, const Eigen::Vector3d& goal, double radius_m,
                         const PlannedPath& plan);

/// chi^2 with 3 degrees of freedom at 99.73 % (the 3-sigma mass of one dimension).
constexpr double kChi2ThreeDof3Sigma = 14.16;

}  // namespace kestrel::flights
