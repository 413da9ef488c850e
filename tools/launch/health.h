#pragma once
// What the launcher knows of each process's health: its latest heartbeat (PROCESS_STATUS),
// matched to the child by pid, and how long ago it came; and the CPU each one uses, from the
// launcher (the kernel's count, not the process's word). Rendered as a small table.
//
// Invariants: a process is "silent" when its last heartbeat is older than `silent_after_s`
// (or it never sent one that long after starting); heartbeats of processes the launcher did
// not start are kept under their own name, so a stray peer is visible too.

#include <sys/types.h>

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "kestrel/process_status_t.hpp"
#include "kestrel/rejection_counts_t.hpp"

namespace kestrel::launch {

class HealthBoard {
 public:
  using Clock = std::chrono::steady_clock;

  explicit HealthBoard(double silent_after_s = 3.0) : silent_after_s_(silent_after_s) {}

  /// A process the launcher (re)started; forgets the heartbeat of its previous pid. A source
  /// such as `kestrel replay` need not heartbeat (`heartbeats` false): it is then "running"
  /// until it ends, and all_running() does not wait for it.
  void started(const std::string& name, pid_t pid, Clock::time_point now, bool heartbeats = true);
  /// A process that ended at `now`, with how ("exited with status 1") and the CPU time it
  /// used (s; negative when unknown).
  void ended(const std::string& name, const std::string& how, Clock::time_point now, double cpu_s = -1.0);
  /// The CPU time (s) a running process has used so far.
  void cpu(const std::string& name, double cpu_s);
  void heartbeat(const process_status_t& status, Clock::time_point now);
  /// A process's rejection counts (PROCESS_REJECTIONS), matched like its heartbeat.
  void rejections(const rejection_counts_t& counts);

  struct Row {
    std::string name;
    pid_t pid = -1;
    std::string state;  ///< RUNNING, DEGRADED..., "silent 4.2 s", "no heartbeat", "ended: ..."
    bool healthy = false;
    std::optional<process_status_t> last;
    std::optional<double> cpu_s;  ///< CPU time used (user + system), s
    /// CPU time over wall time since it started (until it ended), in % of one core.
    std::optional<double> cpu_percent;
  };
  std::vector<Row> rows(Clock::time_point now) const;
  /// One line per process: name, pid, messages in/out/rejected, CPU s and %, state, message.
  std::string table(Clock::time_point now) const;
  /// What each process refused, by channel and reason, with the count and the latest one in
  /// full; "" when nothing was refused. A restarted process's table starts again.
  std::string rejections_table() const;
  /// True once every started, running process has sent a RUNNING heartbeat.
  bool all_running(Clock::time_point now) const;
  /// The started, still running processes that heartbeat but have not sent one yet. A
  /// process's first heartbeat follows its subscriptions, so once this is empty nothing a
  /// source sends goes unheard.
  std::vector<std::string> not_yet_heard() const;

 private:
  struct Entry {
    pid_t pid = -1;
    Clock::time_point since{};
    std::optional<process_status_t> last;
    Clock::time_point last_at{};
    std::optional<rejection_counts_t> rejections;
    std::optional<std::string> ended;
    Clock::time_point ended_at{};
    double cpu_s = -1.0;
    bool launched = false;
    bool heartbeats = true;
  };
  // The entry of the process with this pid (a launched one, still running or ended under
  // that name), else one kept under "<name> (not launched here)".
  Entry& entry_of(pid_t pid, const std::string& name);

  double silent_after_s_;
  std::map<std::string, Entry> entries_;  // by launch name
  std::vector<std::string> order_;
};

/// "RUNNING", "DEGRADED", ... for process_status_t::state.
std::string state_name(int8_t state);

}  // namespace kestrel::launch
