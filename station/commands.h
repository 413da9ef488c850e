#pragma once
// What the page may ask, and whether it may: commands arrive as JSON text on the socket,
//   {"cmd":"goal", "goal":[x, y, z, yaw], "token":"..."}   fly there (a PLAN_REQUEST)
//   {"cmd":"hold", "token":"..."}                            stop and hold (see hold_plan)
//   {"cmd":"play"} {"cmd":"pause"} {"cmd":"seek", "t":s} {"cmd":"speed", "speed":x}
//                         a replay's transport (`kestrel replay LOG --control`): t in seconds
//                         from the log's start, 0 < speed <= kMaxPlaybackSpeed
// parse_command checks the form and the token; check_goal checks a goal against the map
// before anything reaches the bus.
//
// Invariants: a command that is not exactly one of these (not JSON, too long, an unknown
// cmd, a missing, non-numeric or non-finite field, a wrong token) throws CommandError with a
// sentence the page shows; nothing is published for it. The token comparison takes the same
// time whatever the first differing byte.

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>

#include "kestrel/plan_request_t.hpp"
#include "kestrel/playback_command_t.hpp"
#include "kestrel/playback_status_t.hpp"
#include "kestrel/plan_t.hpp"
#include "station/map_cells.h"

namespace kestrel::station {

class CommandError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct GoalCommand {
  std::array<double, 4> goal{};  ///< x, y, z (m), yaw (rad), world frame
};
struct HoldCommand {};
struct PlaybackCommand {
  int8_t command = 0;   ///< kestrel::playback_command_t::COMMAND_*
  double seek_s = 0.0;  ///< COMMAND_SEEK: seconds from the log's start, >= 0
  double speed = 1.0;   ///< COMMAND_SPEED
};
using Command = std::variant<GoalCommand, HoldCommand, PlaybackCommand>;

/// The fastest replay the page may ask for (log seconds per wall second).
inline constexpr double kMaxPlaybackSpeed = 100.0;

/// Longest command text accepted, bytes: a goal is under 200.
inline constexpr size_t kMaxCommandBytes = 4096;

/// Whether `given` equals `expected`, comparing every byte whatever the first difference.
bool token_matches(std::string_view given, std::string_view expected);

/// Parses one command; `token` empty means none is required (the station on localhost).
Command parse_command(std::string_view text, const std::string& token);

struct GoalCheckOptions {
  double clearance_m = 0.2;   ///< no occupied cell within this of the goal (the vehicle's size)
  double yaw_limit_rad = 100.0;  ///< |yaw| above this is a typing error, not an angle
};

/// "" if the goal may be sent; else why not, for the operator: no map yet, outside the map's
/// known bounds, or an occupied cell within the clearance.
std::string check_goal(const GoalCommand& goal, const CellSet* map, const GoalCheckOptions& options);

/// The request `kestrel goto` sends for this goal: from the latest STATE, BRM, the smallest
/// uncertainty at the goal.
kestrel::plan_request_t plan_request(const GoalCommand& goal, int64_t request_id, int64_t utime);

/// The command for the replay whose latest status is `replay`; "" in `refusal` if it may be
/// sent, else why not (a seek beyond the log's end).
kestrel::playback_command_t playback_command(const PlaybackCommand& c, const kestrel::playback_status_t& replay,
                                             int64_t request_id, std::string& refusal);

/// The hold command: a PLAN without a path. It is how kestrel already says "stop": the
/// follower drops its path on any PLAN that is not OK and commands MODE_HOLD where the vehicle
/// is (control/follower_node.h), so a hold needs no second path to the vehicle.
kestrel::plan_t hold_plan(int64_t request_id, int64_t utime);

}  // namespace kestrel::station
