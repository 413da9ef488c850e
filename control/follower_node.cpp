#include "control/follower_node.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include "common/error.h"
#include "common/text.h"
#include "common/transport/convert.h"

namespace kestrel::control {
namespace {

kestrel::vehicle_command_t to_message(const FollowerCommand& c, int64_t utime) {
  kestrel::vehicle_command_t m{};
  m.utime = utime;
  m.mode = c.mode == FollowerCommand::Mode::kHold ? kestrel::vehicle_command_t::MODE_HOLD
                                                  : kestrel::vehicle_command_t::MODE_POSITION;
  for (int i = 0; i < 3; ++i) {
    m.position[i] = c.position[i];
    m.velocity[i] = c.velocity[i];
  }
  m.yaw = c.yaw;
  m.yaw_rate = c.yaw_rate;
  return m;
}

}  // namespace

std::vector<Waypoint> read_waypoints(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open: " + std::strerror(errno));
  std::vector<Waypoint> out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (is_comment_or_blank(line)) continue;
    const auto fields = split_fields(line);
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (fields.size() < 4) throw InputError(where + "expected x y z yaw [tr], got " + std::to_string(fields.size()) + " fields");
    double v[4];
    for (int i = 0; i < 4; ++i) {
      const auto d = parse_double(fields[static_cast<size_t>(i)]);
      if (!d || !std::isfinite(*d)) throw InputError(where + "'" + std::string(fields[static_cast<size_t>(i)]) + "' is not a finite number");
      v[i] = *d;
    }
    out.push_back({Eigen::Vector3d(v[0], v[1], v[2]), v[3]});
  }
  if (out.empty()) throw InputError(path + ": no waypoint");
  return out;
}

FollowerNode::FollowerNode(const FollowerNodeOptions& options)
    : options_(options), follower_(options.follower), smoother_(options.smoothing) {
  if (!(options.command_period_s >= 0.0)) throw std::invalid_argument("follower: command period must be >= 0");
}

void FollowerNode::reset() {
  follower_.clear();
  smoother_.reset();
  active_ = hold_pending_ = commanded_ = false;
  last_command_utime_ = 0;
}

void FollowerNode::set_path(const std::vector<Waypoint>& waypoints) {
  follower_.set_path(waypoints);
  // A new path (planned from STATE as it is) starts from STATE as it is: an offset left from an
  // earlier jump would shift the whole of it.
  smoother_.clear_offset();
  active_ = true;
  hold_pending_ = false;
}

void FollowerNode::on_plan(const kestrel::plan_t& plan) {
  const auto stop = [&] {
    follower_.clear();
    hold_pending_ = active_;  // a vehicle that was following must stop
  };
  if (plan.status != kestrel::plan_t::STATUS_OK || plan.num_waypoints <= 0) {
    stop();
    return;
  }
  if (plan.num_waypoints != static_cast<int32_t>(plan.waypoints.size())) {
    stop();
    throw InputError(options_.plan_channel + ": num_waypoints disagrees with the waypoints");
  }
  std::vector<Waypoint> path;
  for (const auto& w : plan.waypoints) path.push_back({Eigen::Vector3d(w[0], w[1], w[2]), w[3]});
  try {
    set_path(path);
  } catch (const std::invalid_argument& e) {
    stop();
    throw InputError(options_.plan_channel + ": plan " + std::to_string(plan.request_id) + ": " + e.what());
  }
}

std::optional<kestrel::vehicle_command_t> FollowerNode::on_state(const kestrel::state_t& state) {
  if (!active_ && !hold_pending_) return std::nullopt;
  const bool usable = state.status == kestrel::state_t::STATUS_OK || state.status == kestrel::state_t::STATUS_DEGRADED;
  // Every usable state while following, due or not, feeds the smoother: a jump is a step
  // between two states, whichever of them is commanded on.
  std::optional<Eigen::Isometry3d> T;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  if (usable) {
    T = transport::from_message(state.T_world_body, options_.state_channel.c_str());
    const Eigen::Vector3d velocity(state.velocity[0], state.velocity[1], state.velocity[2]);
    offset = smoother_.update(state.utime, T->translation(), velocity);
  }
  const bool due = !commanded_ || hold_pending_ ||
                   state.utime - last_command_utime_ >= std::llround(options_.command_period_s * 1e6);
  if (!due) return std::nullopt;
  VehicleState s;
  if (T) {
    s.position = T->translation() - offset;
    s.yaw = std::atan2(T->linear()(1, 0), T->linear()(0, 0));
  }
  FollowerCommand c;  // kHold unless the follower says otherwise: the vehicle stops where it is
  c.position = s.position;
  c.yaw = s.yaw;
  if (usable) c = follower_.command(s);
  c.position += offset;  // back into the estimator's world, which the vehicle's controller uses
  hold_pending_ = false;
  active_ = follower_.status() != FollowStatus::kIdle;
  commanded_ = true;
  last_command_utime_ = state.utime;
  return to_message(c, state.utime);
}

}  // namespace kestrel::control
