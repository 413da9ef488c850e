#pragma once
// Decoded kestrel messages as the page's JSON updates, one function per message type, and
// the small histories the page shows (the estimator's path, the truth's, the health table,
// channel rates).
//
// Every update is an object with "kind" (the page's slot for it: a newer update of a kind
// replaces an older one not yet sent, see hub.h). A message that cannot be drawn (a non-finite
// or non-rigid pose, arrays that disagree with their counts) throws InputError naming the
// channel, so the Node counts and skips it; a covariance that is unusable (non-finite, wrong
// size) is left out of the update rather than drawn wrong. No update holds a NaN.
// Time is the messages' utime, and for the health table and the rates a `now_s` the caller
// passes (the process's steady clock); nothing here reads a clock.

#include <nlohmann/json.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "kestrel/ground_truth_t.hpp"
#include "kestrel/plan_covariance_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/playback_status_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/state_t.hpp"

namespace kestrel::station {

/// {"kind":"state", utime, status, p:[x,y,z], q:[w,x,y,z], yaw, cov?: {radii:[3], q:[w,x,y,z]}}:
/// T_world_body and the 1-sigma ellipsoid of the position covariance (state indices 0..2),
/// its axes as a rotation of the world's.
nlohmann::json state_update(const kestrel::state_t& m, const char* channel);

/// {"kind":"truth_pose", utime, frame:"body"|"camera", p, q}
nlohmann::json truth_update(const kestrel::ground_truth_t& m, const char* channel);

/// {"kind":"graph", revision, keyframes:[[x,y,z]...] (mm), odometry:[[i,j]...], loops:[[i,j]...]}:
/// the keyframes' camera positions and the edges as indices into them (an edge naming an
/// unknown keyframe is left out).
nlohmann::json graph_update(const kestrel::slam_graph_t& m, const char* channel);

/// {"kind":"plan", request_id, status, status_name, message, length, waypoints:[[x,y,z,yaw]...],
///  sigma:[...]}: sigma_i = sqrt(tr(Sigma_i) / 4), the RMS 1-sigma over (x, y, z, yaw) that the
/// planner's predicted trace gives; with the plan's PLAN_COVARIANCE (same utime and request_id)
/// also ellipses:[[a, b, angle]...]: the 1-sigma ellipse of each waypoint's horizontal position
/// (semi-axes in m, a along `angle` rad from x). Throws InputError on arrays that disagree, a
/// covariance of another plan, or one that is not finite.
nlohmann::json plan_update(const kestrel::plan_t& m, const char* channel,
                           const kestrel::plan_covariance_t* covariance = nullptr);

/// {"kind":"playback", log, t, length, speed, paused, at_end, seeks}: where a controlled replay
/// is (t and length in seconds from the log's start). Throws InputError on a window that ends
/// before it starts or spans more than a year, or a speed that is not a positive number.
nlohmann::json playback_update(const kestrel::playback_status_t& m, const char* channel);

/// A path thinned by distance: a point is kept when it is at least `min_step_m` from the last
/// kept one; beyond `max_points` every second point is dropped (the path's start stays), so it
/// stays bounded on any flight.
class PathTrace {
 public:
  PathTrace(double min_step_m, size_t max_points);
  /// true if the point was kept.
  bool add(const Eigen::Vector3d& p_in_world);
  void clear() { points_.clear(); }
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  /// How many points were ever kept (grows when the path does; thinning does not lower it).
  int64_t added() const { return added_; }
  /// {"kind": kind, "points":[[x,y,z]...]}, millimetres
  nlohmann::json to_json(const std::string& kind) const;

 private:
  double min_step_m_;
  size_t max_points_;
  std::vector<Eigen::Vector3d> points_;
  int64_t added_ = 0;
};

/// The latest heartbeat of every process, by name.
class HealthTable {
 public:
  /// At most this many processes are listed; heartbeats of others are ignored.
  static constexpr size_t kMaxProcesses = 64;
  void on_status(const kestrel::process_status_t& m, double now_s);
  void clear() { rows_.clear(); }
  std::vector<std::string> names() const;
  /// {"kind":"health", processes:[{name, pid, state, state_name, message, in, out, rejected,
  ///  age_s, subscriptions, publications}...]} sorted by name.
  nlohmann::json to_json(double now_s) const;

 private:
  struct Row {
    kestrel::process_status_t status;
    double heard_s = 0.0;
  };
  std::map<std::string, Row> rows_;
};

/// Messages and bytes per channel over the interval between two snapshots.
class ChannelRates {
 public:
  /// Channels counted one by one; the rest are counted together as "(other)", so a bus with
  /// any number of names keeps this bounded.
  static constexpr size_t kMaxChannels = 64;
  void on_message(const std::string& channel, size_t bytes);
  /// {"kind":"rates", channels:[{channel, hz, bytes_per_s}...]} over the time since the last
  /// snapshot (the first one: since `now_s` was first passed), then starts a new interval.
  /// Channels silent for a whole interval show 0 Hz and are then forgotten.
  nlohmann::json snapshot(double now_s);

 private:
  struct Count {
    int64_t messages = 0;
    int64_t bytes = 0;
    bool seen_last_interval = false;
  };
  std::map<std::string, Count> counts_;
  double since_s_ = -1.0;
};

/// process_status_t::STATE_* and plan_t::STATUS_* as words.
std::string process_state_name(int8_t state);
std::string plan_status_name(int8_t status);

}  // namespace kestrel::station
