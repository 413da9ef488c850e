#pragma once
// LiveSystem: kestrel processes running together inside a test, watched over LCM.
//
// What it does:
//  * On construction it puts the test process into a private network namespace
//    (launch::enter_private_network, once per process), so the LCM traffic of the processes it
//    starts, and of the test, stays within the test. Call LiveSystem::isolate() first and skip
//    the test when it says why it cannot (KESTREL_SKIP_ENVIRONMENT()).
//  * It subscribes in-process, on a thread of its own, to the channels the test names (and
//    always to PROCESS_STATUS), keeps every message received (channel, receive time, bytes)
//    and, if asked, writes those of the named channels to an LCM log as they arrive.
//  * start() forks and execs a program (usually test::tool("name")) in a process group of its
//    own, its stdout and stderr going to <dir>/<label>.log.
//  * wait_for() blocks until a message on a channel satisfies a predicate: tests wait on what
//    the processes publish (STATE reaching a time, a heartbeat saying RUNNING) instead of
//    sleeping, and learn a process's pid from its heartbeat, never from a log.
//  * kill(), wait_exit(), stop() and run() (start, then wait for the exit) drive the children,
//    e.g. a lock-step `kestrel replay LOG --expect a,b --record OUT` (replay()).
//
// Invariants:
//  * isolate() runs before the test process starts any thread: enter_private_network needs
//    that for a user namespace, and a plain one moves only the calling thread (the threads it
//    starts later follow it). Each ctest entry of a gtest_discover_tests binary is a process
//    of its own, so this holds when a test calls isolate() first. A process enters the
//    namespace once; the LiveSystems of later tests in the same process share it.
//  * Every child started, and every process left behind by one (the test process is made a
//    child subreaper), is killed and reaped by the destructor: a failed test leaves nothing
//    running. Children still running are sent SIGINT first (a clean stop, flushing their
//    logs), SIGKILL a few seconds later. A test process killed outright runs no destructor:
//    its children are then sent SIGTERM by the kernel (PR_SET_PDEATHSIG).
//  * Messages are kept in arrival order; wait_for() sees every message received since the
//    LiveSystem started (or since the index `from` it is given), so a message that arrived
//    before the wait is not missed.
//  * A wait that times out is a test failure (ADD_FAILURE, naming the channel and what was
//    waited for) and returns nothing; callers ASSERT on the result.

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "common/transport/message.h"
#include "kestrel/process_status_t.hpp"
#include "test/support/test_support.h"

namespace kestrel::test {

/// One message the LiveSystem received.
struct ReceivedMessage {
  std::string channel;
  int64_t received_utime = 0;  ///< wall clock at reception, microseconds since the epoch
  std::vector<uint8_t> data;
};

class LiveSystem {
 public:
  struct Options {
    /// Channels to subscribe to (exact names); PROCESS_STATUS is always subscribed to.
    std::vector<std::string> channels;
    /// If not empty, the messages on `recorded` are written here as an LCM log (stamped with
    /// their reception time, as lcm-logger does); closed by finish() or the destructor.
    std::filesystem::path record;
    /// The channels written to `record` (each must be in `channels`); empty: all of `channels`.
    std::vector<std::string> recorded;
  };

  /// "" if this process is, or can be put, in a private network namespace; else why not.
  /// Enters the namespace on the first call (so call it before any thread starts).
  static std::string isolate();

  /// Enters the private network (isolate() must have succeeded: throws otherwise), starts
  /// listening. `dir` holds the children's logs (<dir>/<label>.log).
  LiveSystem(std::filesystem::path dir, Options options);
  ~LiveSystem();
  LiveSystem(const LiveSystem&) = delete;
  LiveSystem& operator=(const LiveSystem&) = delete;

  const std::filesystem::path& dir() const { return dir_; }

  /// Starts argv[0] (a path, or a name looked up in PATH) with the rest as arguments; `label`
  /// names the child (unique among those running) and its log. Returns the pid.
  pid_t start(const std::string& label, const std::vector<std::string>& argv);
  /// The child's log file, and its text so far.
  std::filesystem::path log_path(const std::string& label) const { return dir_ / (label + ".log"); }
  std::string output(const std::string& label) const { return read_file(log_path(label)); }
  /// The pid of the child last started as `label` (0 if none).
  pid_t pid(const std::string& label) const;

  /// Sends `signal` to the child `label` (its whole process group).
  void kill(const std::string& label, int signal);
  /// Sends `signal` to a process that is not a child, e.g. one a launcher started, whose pid
  /// a heartbeat gave.
  static void kill_pid(pid_t pid, int signal);
  /// Waits at most `timeout_s` for the child `label` to exit: its exit code, or 128 + the
  /// signal that ended it; empty if it is still running (no failure is recorded).
  std::optional<int> wait_exit(const std::string& label, double timeout_s);
  /// wait_exit(), failing the test (and returning -1) if the child has not exited in time.
  int exit_status(const std::string& label, double timeout_s);
  /// Sends `signal`, then waits as exit_status() does.
  int stop(const std::string& label, int signal = 2 /* SIGINT */, double timeout_s = 10.0);
  /// Sends `signal` to every child still running, all at once, then waits for each as
  /// exit_status() does.
  void stop_all(int signal = 2 /* SIGINT */, double timeout_s = 10.0);
  /// start(), then exit_status().
  int run(const std::string& label, const std::vector<std::string>& argv, double timeout_s);
  /// A lock-step `kestrel-replay LOG --expect a,b --record OUT [extra]` as the child "replay",
  /// waited for: its exit status.
  int replay(const std::filesystem::path& log, const std::string& expect, const std::filesystem::path& record,
             const std::vector<std::string>& extra = {}, double timeout_s = 120.0);

  /// Stops listening once every message already delivered to the socket has been handled,
  /// and closes the recording. Called by the destructor; messages stay readable.
  void finish();

  /// A copy of the messages received on `channel` so far (all channels if empty).
  std::vector<ReceivedMessage> messages(const std::string& channel = "") const;
  /// How many messages have been received so far (all channels): an index for wait_for's `from`.
  size_t received() const;

  /// The first message on `channel` (from the `from`-th message received on any channel on)
  /// that decodes as Msg and satisfies `accept`; waits for it at most `timeout_s`. On timeout
  /// the test fails, saying `what`, and the result is empty.
  template <class Msg>
  std::optional<Msg> wait_for(const std::string& channel, const std::function<bool(const Msg&)>& accept,
                              double timeout_s, const std::string& what, size_t from = 0) {
    std::optional<Msg> found;
    wait_raw(channel, [&](const ReceivedMessage& m) {
      Msg msg = transport::decode_message<Msg>(m.data.data(), m.data.size(), channel);
      if (!accept(msg)) return false;
      found = std::move(msg);
      return true;
    }, timeout_s, what, from);
    return found;
  }

  /// A heartbeat of process `name` (the name it announces) in `state`; its pid is the
  /// process's. `from` as for wait_for.
  std::optional<kestrel::process_status_t> wait_for_state(const std::string& name, int8_t state, double timeout_s,
                                                          size_t from = 0);
  /// wait_for_state(name, RUNNING): the process's pid, 0 after a failure.
  pid_t wait_running(const std::string& name, double timeout_s = 20.0, size_t from = 0);
  /// A heartbeat of process `name` in any state: the process's pid, 0 after a failure.
  pid_t wait_heartbeat(const std::string& name, double timeout_s = 20.0, size_t from = 0);

 private:
  struct Child {
    pid_t pid = 0;
    std::optional<int> status;  // set once reaped
  };
  void listen();
  void on_message(const std::string& channel, const void* data, size_t size);
  bool wait_raw(const std::string& channel, const std::function<bool(const ReceivedMessage&)>& match,
                double timeout_s, const std::string& what, size_t from);
  Child& child(const std::string& label);
  static std::optional<int> reap(pid_t pid, bool block);
  void reap_everything();

  std::filesystem::path dir_;
  Options options_;
  std::map<std::string, Child> children_;
  std::vector<std::string> order_;  // labels, in start order

  struct Listener;  // the LCM instance, the recording and the thread
  std::unique_ptr<Listener> listener_;
  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<ReceivedMessage> messages_;
};

}  // namespace kestrel::test
