#pragma once
// The kestrel processes a replay talks to, as learned from their heartbeats
// (PROCESS_STATUS): who subscribes to what, who publishes what, and whether the set has
// settled. Knows nothing of LCM; the caller feeds it decoded heartbeats and its own clock.
//
// Invariants: one entry per process name; a name heard with two different pids within
// `conflict_window_s` is reported by conflicts(), because acknowledgements carry only the
// name and two processes sharing one would make the lock-step accounting wrong.

#include <map>
#include <set>
#include <string>
#include <vector>

#include "kestrel/process_status_t.hpp"

namespace kestrel::replay {

/// Channels of the replay protocol, heartbeats and rejection counts (telemetry stamped with
/// the wall clock): never replayed, recorded or counted as data, whoever lists them.
bool is_protocol_channel(const std::string& channel);

struct ProcessInfo {
  std::string name;
  int32_t pid = 0;
  int8_t state = kestrel::process_status_t::STATE_STARTING;
  std::vector<std::string> subscriptions;  ///< sorted, without protocol channels
  std::vector<std::string> publications;   ///< sorted, without protocol channels
  double last_heard_s = 0.0;               ///< caller's clock
  std::map<int32_t, double> pids_heard_s;  ///< every pid heard under this name, when last
};

/// channel -> names of the processes that subscribe to it (sorted).
using ConsumerMap = std::map<std::string, std::vector<std::string>>;

class ProcessTable {
 public:
  explicit ProcessTable(double conflict_window_s = 3.0) : conflict_window_s_(conflict_window_s) {}

  /// Records a heartbeat heard at `now_s`; true if it added a process or changed the
  /// channels of one (the discovery is not stable yet).
  bool update(const kestrel::process_status_t& status, double now_s);

  /// Forgets `name` (a process that left a session whose membership may change).
  void remove(const std::string& name) { processes_.erase(name); }

  const std::map<std::string, ProcessInfo>& processes() const { return processes_; }
  bool contains(const std::string& name) const { return processes_.count(name) > 0; }
  /// Names in `expected` not heard from.
  std::vector<std::string> missing(const std::vector<std::string>& expected) const;
  /// "name (pids 12, 34)" for each name heard with several pids within the window before
  /// `now_s`.
  std::vector<std::string> conflicts(double now_s) const;

  ConsumerMap consumers() const;
  /// Names of the processes that list `channel` among their publications.
  std::vector<std::string> publishers(const std::string& channel) const;

 private:
  double conflict_window_s_;
  std::map<std::string, ProcessInfo> processes_;
};

/// One line per process: "name (pid N): IN, IN -> OUT, OUT".
std::vector<std::string> describe(const ProcessTable& table);

}  // namespace kestrel::replay
