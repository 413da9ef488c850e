#pragma once
// The message side of kestrel-follow, without LCM: PLAN and STATE in, VEHICLE_COMMAND out.
// main.cpp wires it to a Node; tests feed it directly.
//
// A PLAN with status OK replaces the path (any other status, or no waypoints, makes the
// follower stop and hold: the planner found no way, so the vehicle must not go on). A
// command goes out on STATE, at most once per command_period_s of sensor time and only
// while there is a path (before the first plan nothing is published, so the vehicle keeps
// whatever command it was given by someone else). A STATE without a usable pose (status
// INITIALIZING or FAILED) gives a hold. While following, every usable STATE goes through a
// JumpSmoother (jump_smoother.h): the follower sees the position less the absorbed jumps (held
// within 0.5 m, so a larger jump still makes the vehicle hold off the path), and set points go
// out plus them, so a late SLAM correction that moves STATE at once reaches the vehicle's
// controller as a slow drift onto the corrected path, not as a step. A new path drops the
// offset: it starts from STATE as it is. Waypoints can also come from a file (`kestrel plan`'s
// output: x y z yaw [tr(Sigma)] per line, '#' comments).

#include <optional>
#include <string>
#include <vector>

#include "control/jump_smoother.h"
#include "control/path_follower.h"
#include "kestrel/plan_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vehicle_command_t.hpp"

namespace kestrel::control {

struct FollowerNodeOptions {
  FollowerOptions follower;
  JumpSmoothingOptions smoothing;
  double command_period_s = 0.02;   ///< at most one VEHICLE_COMMAND per this much sensor time
  std::string plan_channel = "PLAN";
  std::string state_channel = "STATE";
};

/// Reads waypoints from a text file. Throws InputError naming the file and line.
std::vector<Waypoint> read_waypoints(const std::string& path);

class FollowerNode {
 public:
  explicit FollowerNode(const FollowerNodeOptions& options);

  /// Throws InputError naming the channel for a plan with a non-finite waypoint or a count
  /// that disagrees with its arrays (the path is then dropped: hold).
  void on_plan(const kestrel::plan_t& plan);
  /// Starts following waypoints given directly (the tool's --waypoints).
  void set_path(const std::vector<Waypoint>& waypoints);
  /// The command for this state, if one is due; while following, every usable state feeds the
  /// smoother. Throws InputError naming the channel for such a state whose pose is not a finite
  /// rigid transform.
  std::optional<kestrel::vehicle_command_t> on_state(const kestrel::state_t& state);
  void reset();

  const PathFollower& follower() const { return follower_; }
  const JumpSmoother& smoother() const { return smoother_; }
  /// A plan that said "no path" (or was refused) is pending a hold command.
  bool holding() const { return hold_pending_; }

 private:
  FollowerNodeOptions options_;
  PathFollower follower_;
  JumpSmoother smoother_;
  bool active_ = false;        ///< a path was given: commands go out
  bool hold_pending_ = false;  ///< stop: the last plan had no path
  int64_t last_command_utime_ = 0;
  bool commanded_ = false;
};

}  // namespace kestrel::control
