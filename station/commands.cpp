#include "station/commands.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <sstream>

namespace kestrel::station {
namespace {

std::string metres(const Eigen::Vector3d& p) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(2);
  s << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return s.str();
}

}  // namespace

bool token_matches(std::string_view given, std::string_view expected) {
  // Every byte of the longer string is looked at, so the time says only the lengths.
  const size_t n = std::max(given.size(), expected.size());
  unsigned diff = given.size() == expected.size() ? 0u : 1u;
  for (size_t i = 0; i < n; ++i) {
    const unsigned a = i < given.size() ? static_cast<unsigned char>(given[i]) : 0u;
    const unsigned b = i < expected.size() ? static_cast<unsigned char>(expected[i]) : 0u;
    diff |= a ^ b;
  }
  return diff == 0;
}

Command parse_command(std::string_view text, const std::string& token) {
  if (text.size() > kMaxCommandBytes)
    throw CommandError("command of " + std::to_string(text.size()) + " bytes refused (at most " +
                       std::to_string(kMaxCommandBytes) + ")");
  const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) throw CommandError("command refused: not a JSON object");
  if (!token.empty()) {
    const auto t = j.find("token");
    if (t == j.end() || !t->is_string() || !token_matches(t->get_ref<const std::string&>(), token))
      throw CommandError("command refused: missing or wrong token");
  }
  const auto cmd = j.find("cmd");
  if (cmd == j.end() || !cmd->is_string()) throw CommandError("command refused: no \"cmd\"");
  const std::string& name = cmd->get_ref<const std::string&>();
  if (name == "hold") return HoldCommand{};
  if (name == "play") return PlaybackCommand{kestrel::playback_command_t::COMMAND_PLAY, 0.0, 1.0};
  if (name == "pause") return PlaybackCommand{kestrel::playback_command_t::COMMAND_PAUSE, 0.0, 1.0};
  if (name == "seek" || name == "speed") {
    const char* field = name == "seek" ? "t" : "speed";
    const auto v = j.find(field);
    if (v == j.end() || !v->is_number() || !std::isfinite(v->get<double>()))
      throw CommandError(name + " refused: \"" + field + "\" must be a finite number");
    const double x = v->get<double>();
    if (name == "seek") {
      if (x < 0.0) throw CommandError("seek refused: t is seconds from the log's start, not negative");
      return PlaybackCommand{kestrel::playback_command_t::COMMAND_SEEK, x, 1.0};
    }
    if (!(x > 0.0 && x <= kMaxPlaybackSpeed))
      throw CommandError("speed refused: it must be above 0 and at most " + std::to_string(static_cast<int>(kMaxPlaybackSpeed)));
    return PlaybackCommand{kestrel::playback_command_t::COMMAND_SPEED, 0.0, x};
  }
  if (name != "goal") throw CommandError("command refused: unknown cmd '" + name.substr(0, 40) + "'");
  const auto goal = j.find("goal");
  if (goal == j.end() || !goal->is_array() || goal->size() != 4)
    throw CommandError("goal refused: \"goal\" must be [x, y, z, yaw]");
  GoalCommand g;
  for (size_t i = 0; i < 4; ++i) {
    const auto& v = (*goal)[i];
    if (!v.is_number()) throw CommandError("goal refused: [x, y, z, yaw] must be numbers");
    g.goal[i] = v.get<double>();
    if (!std::isfinite(g.goal[i])) throw CommandError("goal refused: [x, y, z, yaw] must be finite");
  }
  return g;
}

std::string check_goal(const GoalCommand& goal, const CellSet* map, const GoalCheckOptions& options) {
  const Eigen::Vector3d p(goal.goal[0], goal.goal[1], goal.goal[2]);
  if (!p.allFinite() || !std::isfinite(goal.goal[3])) return "goal refused: not a finite point";
  if (std::abs(goal.goal[3]) > options.yaw_limit_rad) return "goal refused: yaw out of range";
  if (!map || map->known_bounds.isEmpty()) return "goal refused: no map yet";
  if (!map->known_bounds.contains(p)) {
    const Eigen::AlignedBox3d& b = map->known_bounds;
    return "goal " + metres(p) + " refused: outside the map's bounds " + metres(b.min()) + " to " + metres(b.max());
  }
  if (map->occupied_within(p, options.clearance_m)) {
    std::ostringstream s;
    s.precision(2);
    s << "goal " << metres(p) << " refused: occupied space within " << options.clearance_m << " m";
    return s.str();
  }
  return "";
}

kestrel::plan_request_t plan_request(const GoalCommand& goal, int64_t request_id, int64_t utime) {
  kestrel::plan_request_t r{};
  r.utime = utime;
  r.request_id = request_id;
  r.start_mode = kestrel::plan_request_t::START_FROM_STATE;
  for (size_t i = 0; i < 4; ++i) r.goal[i] = goal.goal[i];
  r.planner = kestrel::plan_request_t::PLANNER_BRM;
  r.objective = kestrel::plan_request_t::OBJECTIVE_MIN_GOAL_UNCERTAINTY;
  r.max_covariance_trace = 0.0;
  return r;
}

kestrel::playback_command_t playback_command(const PlaybackCommand& c, const kestrel::playback_status_t& replay,
                                             int64_t request_id, std::string& refusal) {
  kestrel::playback_command_t m{};
  m.request_id = request_id;
  m.command = c.command;
  m.speed = c.speed;
  refusal.clear();
  if (c.command == kestrel::playback_command_t::COMMAND_SEEK) {
    const double length_s = 1e-6 * static_cast<double>(replay.end_utime - replay.start_utime);
    if (c.seek_s > length_s) {
      std::ostringstream s;
      s.setf(std::ios::fixed);
      s.precision(1);
      s << "seek to " << c.seek_s << " s refused: the log is " << length_s << " s long";
      refusal = s.str();
      return m;  // no seek_utime: t may be far beyond what a utime holds
    }
    m.seek_utime = replay.start_utime + static_cast<int64_t>(std::llround(c.seek_s * 1e6));
  }
  return m;
}

kestrel::plan_t hold_plan(int64_t request_id, int64_t utime) {
  kestrel::plan_t p{};
  p.utime = utime;
  p.request_id = request_id;
  p.status = kestrel::plan_t::STATUS_NO_PATH;
  p.message = "hold: asked by the operator at the station";
  p.num_waypoints = 0;
  return p;
}

}  // namespace kestrel::station
