#pragma once
// Starts a set of processes, notices when one ends, restarts it if asked, and stops them all.
// Each child runs in its own process group (so a terminal's Ctrl-C reaches only the
// launcher, which then stops the children in order) with stdout and stderr appended to
// <log_dir>/<name>.log. Each child also gets SIGTERM from the kernel when the launcher ends,
// however it ends (kill -9 included), so only a child that ignores SIGTERM can outlive it.
//
// Invariants: every child started is reaped by poll() or stop_all(); stop_all() returns only
// when no child is left (SIGTERM, then SIGKILL after `stop_timeout_s`); a child that keeps
// failing is restarted at most `max_restarts` times, each after `restart_delay_s`. The
// parent-death signal follows the thread that forked the child, so start_all() and poll() are
// called from a thread that lives as long as the launcher (its main thread).

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tools/launch/process_set.h"

namespace kestrel::launch {

struct SupervisorOptions {
  std::filesystem::path log_dir;
  std::vector<std::string> environment;  ///< "KEY=value" added to every child's environment
  bool restart = false;
  double restart_delay_s = 1.0;
  int max_restarts = 5;
  double stop_timeout_s = 5.0;
  /// A network namespace (an open fd of one, /proc/PID/ns/net) per side: a child of that side
  /// enters it before exec (`kestrel launch --link`); a side not named here runs in the
  /// launcher's namespace. A child that cannot enter its namespace exits 4 at once.
  std::map<std::string, int> netns_by_side;
};

/// How a process ended: "exited with status 3", "killed by SIGSEGV".
struct Ending {
  int code = 0;  ///< exit status, or 128 + signal number (the shell's convention)
  std::string description;
  /// CPU time it used (user + system; with its children it waited for, as wait4 counts), s;
  /// -1 when unknown.
  double cpu_s = -1.0;
  std::chrono::steady_clock::time_point at{};  ///< when it was reaped
};
Ending describe_wait_status(int wait_status);

/// CPU time (user + system) a running process has used so far, with that of its children it
/// waited for (as wait4 will count it at its end), from /proc/<pid>/stat; nullopt if that
/// cannot be read (it has ended, or no /proc).
std::optional<double> process_cpu_seconds(pid_t pid);

/// The last `lines` lines of a child's log, each indented as "    | ": usually the reason it
/// died. Empty if the log cannot be read.
std::string log_tail(const std::filesystem::path& log, size_t lines);

/// Something that happened to a child, for the launcher to report.
struct ChildEvent {
  enum Kind { kStarted, kEnded, kRestarting, kGaveUp } kind;
  std::string name;
  pid_t pid = -1;
  Ending ending;  ///< kEnded only
};

class Supervisor {
 public:
  using Clock = std::chrono::steady_clock;

  struct Child {
    ProcessSpec spec;
    std::filesystem::path executable;
    std::filesystem::path log;
    pid_t pid = -1;  ///< -1 when not running
    int restarts = 0;
    std::optional<Ending> last_ending;
    std::optional<Clock::time_point> restart_at;
  };

  /// `executables[i]` runs `set[i]` (see resolve_executable). Starts nothing yet.
  Supervisor(const ProcessSet& set, const std::vector<std::filesystem::path>& executables,
             SupervisorOptions options);
  ~Supervisor();  ///< stops whatever still runs
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// Starts every child not yet running, in set order, except the one named `except`.
  std::vector<ChildEvent> start_all(const std::string& except = "");
  /// Reaps ended children and performs due restarts; never blocks.
  std::vector<ChildEvent> poll(Clock::time_point now = Clock::now());
  /// SIGTERM to every running child in reverse start order, waits, then SIGKILL.
  std::vector<ChildEvent> stop_all();

  const std::vector<Child>& children() const { return children_; }
  const Child* find(pid_t pid) const;
  const Child* find(const std::string& name) const;
  size_t running() const;

 private:
  ChildEvent start(Child& child);
  std::optional<ChildEvent> reap(Child& child, bool block);

  std::vector<Child> children_;
  SupervisorOptions options_;
};

}  // namespace kestrel::launch
