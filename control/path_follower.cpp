#include "control/path_follower.h"

#include "common/numbers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kestrel::control {
namespace {

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("path follower: ") + what);
}

}  // namespace

void FollowerOptions::validate() const {
  require(cruise_speed_m_s > 0.0, "cruise speed must be > 0");
  require(decel_m_s2 > 0.0, "deceleration must be > 0");
  require(lookahead_m > 0.0, "lookahead must be > 0");
  require(search_window_m > 0.0, "search window must be > 0");
  require(arrive_radius_m > 0.0, "arrival radius must be > 0");
  require(max_deviation_m > arrive_radius_m, "largest deviation must exceed the arrival radius");
}

std::string to_string(FollowStatus status) {
  switch (status) {
    case FollowStatus::kIdle:
      return "idle";
    case FollowStatus::kFollowing:
      return "following";
    case FollowStatus::kArrived:
      return "arrived";
    case FollowStatus::kOffPath:
      return "off the path";
  }
  return "unknown";
}

PathFollower::PathFollower(const FollowerOptions& options) : options_(options) { options_.validate(); }

void PathFollower::set_path(const std::vector<Waypoint>& waypoints) {
  clear();
  require(!waypoints.empty(), "the path has no waypoint");
  for (const Waypoint& w : waypoints) require(w.position.allFinite() && std::isfinite(w.yaw), "a waypoint is not finite");
  path_ = waypoints;
  cumulative_.assign(1, 0.0);
  for (size_t i = 1; i < path_.size(); ++i)
    cumulative_.push_back(cumulative_.back() + (path_[i].position - path_[i - 1].position).norm());
  status_ = FollowStatus::kFollowing;
}

void PathFollower::clear() {
  path_.clear();
  cumulative_.clear();
  status_ = FollowStatus::kIdle;
  progress_m_ = 0.0;
  deviation_m_ = 0.0;
}

size_t PathFollower::segment_at(double s) const {
  if (path_.size() < 2) return 0;
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  const size_t i = it == cumulative_.begin() ? 0 : static_cast<size_t>(it - cumulative_.begin()) - 1;
  return std::min(i, path_.size() - 2);
}

PathFollower::Place PathFollower::locate(double s) const {
  const size_t i = segment_at(s);
  const double len = cumulative_[i + 1] - cumulative_[i];
  // A zero-length segment (a turn on the spot) is at its end: its end's yaw.
  return {i, len > 0.0 ? std::clamp((s - cumulative_[i]) / len, 0.0, 1.0) : 1.0};
}

Eigen::Vector3d PathFollower::point_at(double s) const {
  if (path_.size() < 2) return path_.front().position;
  const Place at = locate(s);
  return path_[at.segment].position + at.t * (path_[at.segment + 1].position - path_[at.segment].position);
}

double PathFollower::yaw_slope_at(double s) const {
  if (path_.size() < 2) return 0.0;
  const size_t i = segment_at(s);
  const double len = cumulative_[i + 1] - cumulative_[i];
  return len > 0.0 ? wrap_angle(path_[i + 1].yaw - path_[i].yaw) / len : 0.0;
}

double PathFollower::yaw_at(double s) const {
  if (path_.size() < 2) return path_.front().yaw;
  const Place at = locate(s);
  const double from = path_[at.segment].yaw;
  return wrap_angle(from + at.t * wrap_angle(path_[at.segment + 1].yaw - from));
}

double PathFollower::nearest(const Eigen::Vector3d& p, double from, double to) const {
  if (path_.size() < 2) return 0.0;
  double best_s = from, best_d2 = (point_at(from) - p).squaredNorm();
  for (size_t i = segment_at(from); i + 1 < path_.size() && cumulative_[i] <= to; ++i) {
    const double len = cumulative_[i + 1] - cumulative_[i];
    if (len <= 0.0) continue;
    const Eigen::Vector3d d = (path_[i + 1].position - path_[i].position) / len;
    const double lo = std::max(from, cumulative_[i]), hi = std::min(to, cumulative_[i + 1]);
    if (lo > hi) continue;
    const double s = std::clamp(cumulative_[i] + d.dot(p - path_[i].position), lo, hi);
    const double d2 = (point_at(s) - p).squaredNorm();
    if (d2 < best_d2) {  // strictly: on a tie the earlier point keeps the progress back
      best_d2 = d2;
      best_s = s;
    }
  }
  return best_s;
}

FollowerCommand PathFollower::command(const VehicleState& state) {
  require(state.position.allFinite() && std::isfinite(state.yaw), "the vehicle state is not finite");
  FollowerCommand hold;
  hold.mode = FollowerCommand::Mode::kHold;
  hold.position = state.position;
  hold.yaw = state.yaw;
  if (status_ == FollowStatus::kIdle || status_ == FollowStatus::kOffPath) return hold;

  const double length = length_m();
  const Waypoint& end = path_.back();
  FollowerCommand c;
  c.mode = FollowerCommand::Mode::kPosition;
  if (status_ == FollowStatus::kArrived) {
    deviation_m_ = (state.position - end.position).norm();
    c.position = end.position;
    c.yaw = end.yaw;
    return c;
  }

  progress_m_ = std::max(progress_m_, nearest(state.position, progress_m_, progress_m_ + options_.search_window_m));
  const Eigen::Vector3d on_path = point_at(progress_m_);
  deviation_m_ = (state.position - on_path).norm();
  if (deviation_m_ > options_.max_deviation_m) {
    status_ = FollowStatus::kOffPath;
    return hold;
  }
  const double remaining = length - progress_m_;
  if (remaining <= options_.arrive_radius_m) {
    // The last stretch: straight to the end, which the vehicle's position loop settles.
    if ((state.position - end.position).norm() <= options_.arrive_radius_m) status_ = FollowStatus::kArrived;
    c.position = end.position;
    c.yaw = end.yaw;
    return c;
  }
  const double ahead = std::min(length, progress_m_ + options_.lookahead_m);
  const Eigen::Vector3d aim = point_at(ahead) - on_path;
  const double speed = std::min(options_.cruise_speed_m_s, std::sqrt(2.0 * options_.decel_m_s2 * remaining));
  c.position = on_path;
  c.velocity = aim.norm() > 1e-9 ? Eigen::Vector3d(speed * aim.normalized()) : Eigen::Vector3d::Zero();
  c.yaw = yaw_at(progress_m_);
  c.yaw_rate = speed * yaw_slope_at(progress_m_);
  return c;
}

}  // namespace kestrel::control
