#pragma once
// The driving side of the lock-step protocol (README.md, "How lock-step works"), for any
// source of events: `kestrel replay` drives it from a log, the simulator's closed-loop vehicle
// (`kestrel sim --flight vehicle --lockstep`) from the events it renders.
//
//   LockstepDriver driver(lcm, pump, options, interrupted);
//   if (!driver.begin()) return;                 // discovery, then RESET
//   while (...) driver.publish(channel, bytes, utime, label);   // one event, settled
//   driver.close();                              // the recording; END goes out on destruction
//
// Guarantees: publish() returns only once every process the event reaches, and everything
// they published in turn, has been acknowledged (AckLedger), so each process sees the same
// inputs in the same order on any machine. It never waits forever: a process that makes no
// progress for `ack_timeout_s`, or stops while it owes an acknowledgement, is PeerError naming
// it. The driver may itself be a process of the set (the simulator is a Node that consumes
// VEHICLE_COMMAND): its own acknowledgements settle its own events like anyone's, provided
// `pump` also serves its Node.

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "kestrel/process_status_t.hpp"
#include "kestrel/replay_ack_t.hpp"
#include "tools/replay/ack_ledger.h"
#include "tools/replay/latency.h"
#include "tools/replay/output_recorder.h"
#include "tools/replay/process_table.h"

namespace kestrel::replay {

/// A process did not answer, stopped, or broke the protocol; what() names it.
class PeerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DriverOptions {
  std::vector<std::string> expect;     ///< process names that must take part
  double discovery_timeout_s = 10.0;   ///< give up finding `expect` after this
  double settle_s = 1.0;               ///< the process set must not change for this long
  double begin_period_s = 0.2;         ///< BEGIN is repeated this often while discovering
  bool reset = true;                   ///< RESET every process before the first event
  double ack_timeout_s = 10.0;         ///< longest wait without progress on one event
  std::string record_path;             ///< "" = do not record
  /// Channels the driver publishes that also go into the recording, ahead of the outputs
  /// they cause (the simulator's GROUND_TRUTH, for scoring a flight from its recording).
  std::set<std::string> record_inputs;
  /// Which output channels go into the recording (empty: all).
  std::function<bool(const std::string&)> record_filter;
  /// A set whose processes may leave and join (the simulator's live set, where `kestrel launch
  /// --restart` brings back what dies). A process that stops, or makes no progress for
  /// `ack_timeout_s`, is dropped with a warning and the event ends without it; a process
  /// heard later (a restart: a new pid) is invited with BEGIN and takes part from the first
  /// event after it acknowledged that. false (replay): either is PeerError, and a process
  /// heard later is ignored.
  bool dynamic_membership = false;
};

class LockstepDriver {
 public:
  /// Handles what arrives on the connection within `timeout_ms` (at least one call of
  /// `lcm.handleTimeout`); a caller with a Node on the same connection passes its spin_once.
  using Pump = std::function<void(int timeout_ms)>;

  /// True once the driver should stop (Ctrl-C): checked while waiting.
  using Interrupted = std::function<bool()>;

  /// Subscribes to the protocol's channels (every channel when recording) on `lcm`, which
  /// must outlive the driver. InputError if the recording cannot be created.
  LockstepDriver(lcm::LCM& lcm, Pump pump, DriverOptions options, Interrupted interrupted);
  ~LockstepDriver();
  LockstepDriver(const LockstepDriver&) = delete;
  LockstepDriver& operator=(const LockstepDriver&) = delete;

  /// Finds the processes (BEGIN until the set is stable and every `expect` is there) and
  /// resets them when asked. false if interrupted; PeerError on a missing or ambiguous process.
  bool begin();

  /// Publishes one event and waits until it has settled; `label` names it in errors.
  /// false if interrupted (the event may not have settled).
  bool publish(const std::string& channel, const uint8_t* data, size_t size, int64_t timestamp,
               const std::string& label);

  /// Flushes the recording (InputError on a write error).
  void close();

  /// "name (pid N): IN, IN -> OUT, OUT" for each process taking part.
  std::vector<std::string> processes() const { return describe(table_); }
  /// Names of the processes taking part that publish on `channel`.
  std::vector<std::string> publishers(const std::string& channel) const { return table_.publishers(channel); }
  /// Messages received on recorded channels that no acknowledgement announced.
  int64_t unannounced() const { return unannounced_; }
  /// channel -> messages recorded.
  std::map<std::string, int64_t> recorded() const;
  /// dynamic_membership: processes dropped (stopped or silent) and joined since begin().
  int64_t dropped() const { return dropped_; }
  int64_t joined() const { return joined_; }
  /// Per input channel and process: the time from publishing an event to its acknowledgement
  /// of each input (latency.h).
  std::vector<LatencyRow> latency() const { return latency_.rows(); }

 private:
  static void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel, LockstepDriver* self);
  void handle(const std::string& channel, const lcm::ReceiveBuffer& rbuf);
  void on_ack(const kestrel::replay_ack_t& ack);
  void on_status(const kestrel::process_status_t& status);
  bool discover();
  bool reset_processes();
  void check_names(double now);
  bool is_recorded(const std::string& channel) const;
  const std::map<std::string, int>& depths(const std::string& input);
  bool wait_settled(const std::string& label);
  void drop(const std::string& name, const std::string& why);
  void invite(const kestrel::process_status_t& status);
  void rebuild_ledger();
  void pump(double timeout_s);
  void send_control(int8_t command);

  lcm::LCM& lcm_;
  Pump pump_;
  DriverOptions o_;
  Interrupted interrupted_;
  const int64_t session_;
  std::vector<lcm::Subscription*> subscriptions_;
  bool begun_ = false;
  bool discovering_ = true;
  double last_change_s_ = 0.0;
  double last_progress_s_ = 0.0;
  ProcessTable table_;
  std::optional<AckLedger> ledger_;
  std::optional<OutputRecorder> recorder_;
  std::set<std::string> inputs_;  // channels the driver publishes: recorded only if asked
  std::set<std::string> stopped_, latecomers_;
  std::map<std::string, std::map<std::string, int>> depths_;
  std::optional<std::string> protocol_error_;
  std::optional<double> conflict_since_s_;
  int64_t unannounced_ = 0;
  // dynamic_membership: processes heard but not (yet) taking part, by name (their newest
  // heartbeat); those the current event's ledger counts on; whether that set must be rebuilt.
  std::map<std::string, kestrel::process_status_t> candidates_;
  std::set<std::string> ledger_members_;
  bool membership_changed_ = false;
  double last_invite_s_ = 0.0;
  int64_t dropped_ = 0, joined_ = 0;
  LatencyLedger latency_;
};

}  // namespace kestrel::replay
