// kestrel-follow: flies the planner's path. PLAN (or --waypoints FILE) and STATE in,
// VEHICLE_COMMAND out for the vehicle's position controller (the sim's `--flight vehicle`, or a
// real one). A thin adapter around FollowerNode (follower_node.h); lock-step replay resets it.
#include <spdlog/spdlog.h>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "control/follower_node.h"

namespace {

using namespace kestrel;
using namespace kestrel::control;

struct Options {
  std::string lcm_url;
  std::string waypoints;
  std::string command_channel = channel::kVehicleCommand;
  FollowerNodeOptions node;
};

int run(const Options& o) {
  FollowerNode follower(o.node);
  std::vector<Waypoint> given;
  if (!o.waypoints.empty()) {
    given = read_waypoints(o.waypoints);  // InputError: exit 3, naming the file and line
    follower.set_path(given);
  }
  transport::Node node("follow", o.lcm_url);  // UnavailableError: exit 4
  node.advertise(o.command_channel);
  int jumps_said = 0;
  node.on_reset([&] {
    follower.reset();
    jumps_said = 0;
    if (!given.empty()) follower.set_path(given);
  });
  auto health = [&] {
    const FollowStatus s = follower.follower().status();
    node.set_health(s == FollowStatus::kOffPath ? kestrel::process_status_t::STATE_DEGRADED
                                                 : kestrel::process_status_t::STATE_RUNNING,
                     to_string(s));
  };
  health();
  node.subscribe<kestrel::plan_t>(o.node.plan_channel, [&](const kestrel::plan_t& m) {
    follower.on_plan(m);  // throws: Node counts and logs, and the vehicle holds
    if (m.status == kestrel::plan_t::STATUS_OK && m.num_waypoints > 0) {
      spdlog::info("plan {}: {} waypoints, {:.2f} m", m.request_id, m.num_waypoints, follower.follower().length_m());
    } else {
      spdlog::info("plan {}: no path ({}); holding", m.request_id, m.message);
    }
    health();
  });
  FollowStatus last = follower.follower().status();
  node.subscribe<kestrel::state_t>(o.node.state_channel, [&](const kestrel::state_t& m) {
    if (const auto command = follower.on_state(m)) node.publish(o.command_channel, *command);
    if (follower.smoother().jumps() > jumps_said) {
      jumps_said = follower.smoother().jumps();
      spdlog::info("STATE jumped {:.3f} m: taken out of the control (up to {:.2f} m), let go at {:.2f} m/s",
                   follower.smoother().last_jump_m(), o.node.smoothing.max_offset_m, o.node.smoothing.release_speed_m_s);
    }
    const FollowStatus now = follower.follower().status();
    if (now != last) {
      spdlog::info("{} at {:.2f} of {:.2f} m (deviation {:.2f} m)", to_string(now), follower.follower().progress_m(),
                   follower.follower().length_m(), follower.follower().deviation_m());
      last = now;
      health();
    }
  }, 400);
  const int status = node.spin();
  spdlog::info("{} STATE jumps taken out of the control, the largest {:.3f} m", follower.smoother().jumps(),
               follower.smoother().largest_jump_m());
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("follow", "Path follower: PLAN (or --waypoints) + STATE -> VEHICLE_COMMAND");
  Options o;
  FollowerOptions& f = o.node.follower;
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--waypoints", o.waypoints, "Fly these waypoints at once (x y z yaw [tr] per line: `kestrel plan`'s output)");
  app.add_option("--speed", f.cruise_speed_m_s, "Cruise speed along the path (m/s)")->check(cli::Positive)->capture_default_str();
  app.add_option("--decel", f.decel_m_s2, "Deceleration for the stop at the end (m/s^2)")->check(cli::Positive)->capture_default_str();
  app.add_option("--lookahead", f.lookahead_m, "Where the velocity aims, ahead along the path (m)")->check(cli::Positive)->capture_default_str();
  app.add_option("--arrive-radius", f.arrive_radius_m, "Arrived within this of the last waypoint (m)")->check(cli::Positive)->capture_default_str();
  app.add_option("--max-deviation", f.max_deviation_m, "Farther than this from the path: hold and wait for a new plan (m)")->check(cli::Positive)->capture_default_str();
  app.add_option("--jump-min", o.node.smoothing.min_jump_m,
                 "A step of STATE its velocity does not explain, beyond this, is taken out of the control and let go slowly (m; 100: never)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--jump-release-speed", o.node.smoothing.release_speed_m_s, "How fast a jump taken out is let go (m/s)")
      ->check(cli::Positive)->capture_default_str();
  app.add_option("--jump-max", o.node.smoothing.max_offset_m,
                 "At most this much of jumps is held out of the control; the rest passes, so the off-path hold sees it (m)")
      ->check(cli::Positive)->capture_default_str();
  app.add_option("--period", o.node.command_period_s, "At most one command per this much sensor time (s)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--plan-channel", o.node.plan_channel, "Channel of plan_t")->capture_default_str();
  app.add_option("--state-channel", o.node.state_channel, "Channel of state_t")->capture_default_str();
  app.add_option("--command-channel", o.command_channel, "Channel of vehicle_command_t")->capture_default_str();
  return app.run(argc, argv, [&] {
    try {
      o.node.follower.validate();
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError(e.what());  // a bad option: exit 2
    }
    return run(o);
  });
}
