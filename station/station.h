#pragma once
// The ground station's logic without LCM, files or clocks: decoded kestrel messages in, the
// page's updates out (through an UpdateHub), and the page's commands in, the messages to
// publish out. main.cpp wires it to a Node and to the web server; tests call it directly.
//
// Invariants:
//  * Only the LCM thread calls it (the hub carries everything across threads).
//  * STATE is forwarded at most once per state_period_s of its utime, the paths at most once
//    per slow_period_s and only when they grew; every MAP_OCTOMAP becomes a new snapshot (a
//    map the mapper sent again unchanged is not posted twice).
//  * A command is answered on its own socket with a "notice" (what was sent, or why not), and
//    yields at most one message to publish: a PLAN_REQUEST for an accepted goal, a PLAN
//    without a path for a hold (commands.h).
//  * reset() (lock-step RESET) forgets the flight: map, paths, graph, plan, previews; so does a
//    controlled replay's seek (a new seek count on PLAYBACK_STATUS): what follows the seek
//    draws the flight at its new position.
//  * A transport command (play, pause, seek, speed) is sent only once a controlled replay has
//    said where it is, and a seek only within its log.

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "kestrel/ground_truth_t.hpp"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/state_t.hpp"
#include "station/commands.h"
#include "station/hub.h"
#include "station/images.h"
#include "station/updates.h"

namespace kestrel::station {

struct StationOptions {
  std::string token;               ///< "" = commands need no token (localhost)
  double state_period_s = 0.05;    ///< STATE to the page at most this often (utime)
  double slow_period_s = 0.5;      ///< paths to the page at most this often (utime)
  double path_step_m = 0.05;       ///< a path keeps a point per this much motion
  size_t path_max_points = 4000;   ///< then thins itself by half
  PreviewOptions preview;
  GoalCheckOptions goal;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// What a command asks to publish.
struct CommandResult {
  std::optional<kestrel::plan_request_t> request;  ///< on PLAN_REQUEST
  std::optional<kestrel::plan_t> hold;             ///< on PLAN
  std::optional<kestrel::playback_command_t> playback;  ///< on PLAYBACK_COMMAND (utime left to the sender)
  std::string notice;                              ///< what the page shows
  bool ok = false;
};

class Station {
 public:
  /// `first_request_id`: ids of the station's requests count up from it (the caller makes it
  /// unique, e.g. from the wall clock at start, as kestrel goto does).
  Station(const StationOptions& options, UpdateHub& hub, int64_t first_request_id);

  void on_state(const kestrel::state_t& m, const char* channel);
  void on_truth(const kestrel::ground_truth_t& m, const char* channel);
  void on_graph(const kestrel::slam_graph_t& m, const char* channel);
  void on_plan(const kestrel::plan_t& m, const char* channel);
  /// The belief model's Sigma along a PLAN: the plan is drawn again with its ellipses once
  /// both have come (either may come first; they are matched by utime and request_id).
  void on_plan_covariance(const kestrel::plan_covariance_t& m, const char* channel);
  void on_map(const kestrel::octomap_t& m, const char* channel);
  void on_frame(const kestrel::rgbd_frame_t& m, const char* channel);
  void on_status(const kestrel::process_status_t& m, double now_s);
  void on_playback(const kestrel::playback_status_t& m, const char* channel);
  /// Every message on the bus, for the rates.
  void on_traffic(const std::string& channel, size_t bytes) { rates_.on_message(channel, bytes); }
  /// Posts the rates and the health table (call about once a second).
  void post_periodic(double now_s);

  /// A command from the page's client `client`; answers it with a notice.
  CommandResult on_command(UpdateHub::ClientId client, std::string_view text);

  void reset();

  const CellSet* map() const { return map_.get(); }
  const HealthTable& health() const { return health_; }

 private:
  void post_json(const std::string& kind, const nlohmann::json& update);
  void notice(UpdateHub::ClientId client, bool ok, const std::string& text);

  StationOptions options_;
  UpdateHub& hub_;
  int64_t next_request_id_;
  std::shared_ptr<const CellSet> map_;
  PathTrace path_, truth_path_;
  HealthTable health_;
  ChannelRates rates_;
  PreviewThinner previews_;
  std::optional<int64_t> last_state_utime_, last_path_utime_, last_truth_utime_;
  std::optional<kestrel::plan_t> plan_;                        // the last PLAN
  std::optional<kestrel::plan_covariance_t> plan_covariance_;  // the last PLAN_COVARIANCE
  int64_t path_posted_ = -1, truth_path_posted_ = -1;  ///< added() when last posted: unchanged paths are not sent again
  int64_t latest_utime_ = 0;  ///< newest sensor time seen, stamps what the station sends
  std::optional<kestrel::playback_status_t> playback_;  ///< the controlled replay's latest status
};

/// A JSON update as text, invalid UTF-8 (a name off the bus) replaced rather than thrown on.
std::string json_text(const nlohmann::json& update);

}  // namespace kestrel::station
