#pragma once
// Flies a planned path: turns a polyline of waypoints (x, y, z, yaw; the planner's PLAN or
// `kestrel plan`'s output) and the vehicle's estimated state into position commands for the
// vehicle's own controller (vehicle_command_t's MODE_POSITION with a feed-forward velocity).
//
// Along the path the follower keeps a progress s (metres of path), the point of the path
// nearest the vehicle, searched only forward of the last progress and within a window, so a
// path that passes close to itself is not short-cut and s never decreases. Each command is:
//   position  = path(s), so the vehicle's position loop corrects only the cross-track error;
//   velocity  = v(s) * the unit vector from path(s) to path(s + lookahead), which rounds the
//               corners; v(s) = min(cruise, sqrt(2 a (L - s))), a stop at the end without
//               overshoot for a vehicle that tracks its velocity;
//   yaw       = the waypoints' yaw interpolated at s (shortest way round), with the feed-forward
//               yaw rate v(s) * dyaw/ds, so the camera turns along an edge as the planner's
//               belief model has it turn (its predicted covariance assumes that yaw).
// (Until 27 Nov the yaw was the path's at s + lookahead with no feed-forward: 0.19 rad ahead
// of the path's at the progress on vehicle_loop_test's L; 0.086 rad with the rate, 0.038 with
// the shorter lookahead too.)
// At the end (within arrive_radius of the last waypoint, s at the end) the command holds the
// last waypoint. A vehicle farther than max_deviation from the path is off it: the follower
// commands a hold where it is and stays off the path until it is given a new one (a replan).
//
// Invariants: progress_m() is non-decreasing for one path; every command is finite; with no
// path (or after clear()) the follower is idle and command() holds where the vehicle is.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace kestrel::control {

struct Waypoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< world, m
  double yaw = 0.0;                                    ///< rad
};

struct FollowerOptions {
  // The lookahead and the deceleration suit a vehicle whose velocity loop lags ~1/3 s (the
  // simulator's: velocity gain 3/s): a vehicle lags a deceleration a by a * lag in speed, so a
  // gentler stop ends without overshoot, and the lookahead rounds a corner by a bit more than
  // the lag's 0.17 m at cruise speed. Against 0.5 / 0.5 (until 27 Nov), on three closed-loop
  // paths with wind: the largest distance from the path 9.6 -> 5.4, 9.5 -> 7.6, 10.6 -> 6.2 cm,
  // the yaw's error about halved, 2-10 % more time (control/README.md, "Measured").
  double cruise_speed_m_s = 0.5;    ///< along the path
  double decel_m_s2 = 0.3;          ///< for the stop at the end
  double lookahead_m = 0.3;         ///< where the velocity aims
  double search_window_m = 1.0;     ///< how far ahead of the progress the nearest point is sought
  double arrive_radius_m = 0.10;    ///< at the end within this: arrived
  double max_deviation_m = 1.0;     ///< farther from the path: off it, hold
  /// Throws std::invalid_argument naming the first bad value.
  void validate() const;
};

/// What the follower needs of the vehicle's state (from STATE).
struct VehicleState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0.0;
};

struct FollowerCommand {
  enum class Mode { kHold, kPosition };
  Mode mode = Mode::kHold;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< kPosition: the set point; kHold: where the vehicle is
  double yaw = 0.0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< feed-forward, world, m/s
  double yaw_rate = 0.0;                               ///< feed-forward, rad/s
};

enum class FollowStatus { kIdle, kFollowing, kArrived, kOffPath };
std::string to_string(FollowStatus status);

class PathFollower {
 public:
  explicit PathFollower(const FollowerOptions& options = {});

  /// Follows `waypoints` from their start. Throws std::invalid_argument for an empty path or
  /// a value that is not finite (the follower is then idle).
  void set_path(const std::vector<Waypoint>& waypoints);
  /// Forgets the path: idle.
  void clear();

  /// The command for the vehicle at `state`. Throws std::invalid_argument for a state that is
  /// not finite.
  FollowerCommand command(const VehicleState& state);

  FollowStatus status() const { return status_; }
  double progress_m() const { return progress_m_; }
  double length_m() const { return cumulative_.empty() ? 0.0 : cumulative_.back(); }
  /// Distance of the vehicle from the path at the last command.
  double deviation_m() const { return deviation_m_; }
  /// The path's yaw `s` metres along it: the waypoints' yaw interpolated the short way round,
  /// as the planner's belief model turns the camera along an edge (planner/roadmap.h).
  double yaw_at(double s) const;
  /// dyaw/ds there, rad per metre of path (0 on a turn on the spot, which is a step in yaw).
  double yaw_slope_at(double s) const;

 private:
  Eigen::Vector3d point_at(double s) const;
  size_t segment_at(double s) const;
  struct Place {
    size_t segment;  ///< from waypoint `segment` to the next
    double t;        ///< fraction along it, [0, 1]
  };
  /// Where s metres of path fall (at least two waypoints).
  Place locate(double s) const;
  /// The path's point nearest p within [from, to] metres of path.
  double nearest(const Eigen::Vector3d& p, double from, double to) const;

  FollowerOptions options_;
  std::vector<Waypoint> path_;
  std::vector<double> cumulative_;  ///< path length at each waypoint
  FollowStatus status_ = FollowStatus::kIdle;
  double progress_m_ = 0.0;
  double deviation_m_ = 0.0;
};

}  // namespace kestrel::control
