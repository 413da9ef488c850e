#pragma once
// The adapter every kestrel process is built on: typed LCM subscriptions with checked
// decoding, heartbeats, lock-step replay and clean shutdown. A process main creates a Node,
// subscribes handlers that call its library, and spins.
//
// Guarantees:
//  * Handlers run one at a time, in arrival order, on the thread that calls spin().
//  * A message that cannot be decoded as the subscribed type, or whose handler throws
//    InputError, is dropped, counted in the heartbeat and logged as one line naming the
//    channel (rate-limited); the process carries on.
//  * Every rejection is counted by channel and reason class (rejection_reason_class: the
//    reason with its numbers replaced by '#', at most kMaxReasonsPerChannel classes a channel,
//    the rest counted together); once anything was rejected, PROCESS_REJECTIONS
//    (rejection_counts_t) goes out with every heartbeat with all the counts so far.
//  * PROCESS_STATUS is published about once per heartbeat period with the counters, the
//    subscribed and advertised channels, and the health set by set_health() - except while
//    input is being rejected: then the state is DEGRADED and the message names the last
//    rejection ("rejecting CHANNEL: why"), so that a process blinded by bad input never shows
//    RUNNING (issue 38). The state set by set_health() is kept apart and reported again once
//    input is accepted; STOPPING and FAILED are always reported as set.
//  * A channel is being rejected from a rejection on it until both a message on it has been
//    accepted since and one heartbeat period has passed without another rejection on it.
//    One period, because the launcher sees one heartbeat per period: even a single bad
//    message shows in a heartbeat (one is sent at once when the state changes). Per channel
//    and until an acceptance, because a busy good channel (IMU at 200 Hz) must not hide a
//    slower one that is rejected (VO at 30 Hz), nor a channel whose last message was bad
//    before its sender went quiet.
//  * Lock-step: between REPLAY_CONTROL BEGIN and END of a session, after every input handled
//    (accepted or rejected) the node publishes REPLAY_ACK listing the channels it published
//    on meanwhile; RESET calls the reset handler. Each BEGIN is answered by a heartbeat and by
//    a REPLAY_ACK whose channel is REPLAY_CONTROL ("joined"). See tools/replay/README.md.
//  * SIGINT and SIGTERM make spin() return after the current handler.
//  * Time: the rejection windows and the heartbeat period are measured on the Node's clock,
//    the steady clock unless the constructor is given another (tests advance one by hand);
//    the time stamp in PROCESS_STATUS is always wall-clock time, for the operator.
//  * A channel is subscribed to by its exact name (see subscribe()); a name LCM would take as
//    a pattern, or cannot take at all, is a configuration error, not a crash.

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/transport/message.h"
#include "kestrel/process_status_t.hpp"
#include "kestrel/rejection_counts_t.hpp"
#include "kestrel/replay_control_t.hpp"

namespace kestrel::transport {

struct NodeCounters {
  int64_t messages_in = 0;
  int64_t messages_out = 0;
  int64_t messages_rejected = 0;
  int64_t last_input_utime = 0;
};

/// A rejection's reason as a kind of fault: every number in it (integer, decimal, exponent,
/// with its sign) becomes '#', so that "accelerometer 512.3 m/s^2" and "accelerometer 600
/// m/s^2" count as one reason.
std::string rejection_reason_class(const std::string& reason);

/// Microseconds on the steady (monotonic) clock: the clock a Node measures time on by default.
int64_t steady_microseconds();

/// Why `channel` cannot be subscribed to as an exact name ("" = it can): LCM allows 63
/// characters, and compiles the name as a regular expression, so a pattern character would
/// either subscribe to other channels too ("IMU.*") or to none ("CAM[", which LCM's C++ API
/// then crashes on). Bytes outside printable ASCII are refused for the same reason (the
/// pattern must be valid UTF-8) and because a name is shown on terminals.
std::string channel_name_problem(const std::string& channel);

class Node {
 public:
  /// A monotonic time in microseconds (any origin); only differences are used.
  using Clock = std::function<int64_t()>;

  /// Connects to `lcm_url` (resolved by resolve_lcm_url); throws UnavailableError naming
  /// the URL if LCM cannot start (cli::App::run turns it into exit code 4). `clock` measures
  /// the heartbeat period and the rejection windows; an empty one is std::invalid_argument.
  Node(std::string name, const std::string& lcm_url, double heartbeat_period_s = 1.0,
       Clock clock = steady_microseconds);
  ~Node();
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  /// Calls handler(const Msg&) for each valid message on `channel` (an exact name).
  /// At most `queue_capacity` messages wait; older ones are dropped by LCM when the process
  /// falls behind (30 suits sensors; 0 means unbounded). A channel name that is not one
  /// (channel_name_problem) throws CLI::ValidationError naming it and why, which
  /// cli::App::run turns into exit code 2; the node is then as it was.
  template <class Msg, class Handler>
  void subscribe(const std::string& channel, Handler handler, int queue_capacity = 30) {
    add_subscription(
        channel,
        [channel, handler](const void* data, size_t size) -> int64_t {
          const Msg msg = decode_message<Msg>(data, size, channel);
          handler(msg);
          return message_utime(msg);
        },
        queue_capacity);
  }

  /// Declares a channel this process publishes on (heartbeats list it).
  void advertise(const std::string& channel);

  template <class Msg>
  void publish(const std::string& channel, const Msg& msg) {
    publish_bytes(channel, encode_message(msg));
  }
  void publish_bytes(const std::string& channel, const std::vector<uint8_t>& bytes);

  /// Called on REPLAY_CONTROL RESET: drop all algorithm state.
  void on_reset(std::function<void()> reset) { reset_ = std::move(reset); }
  /// The process's own health (process_status_t::STATE_*), with a reason; heartbeats report
  /// it unless input is being rejected (see above).
  void set_health(int8_t state, const std::string& message);

  struct Health {
    int8_t state = kestrel::process_status_t::STATE_STARTING;
    std::string message;
  };
  /// What the next heartbeat reports: the own health, or DEGRADED while input is rejected.
  Health health() const;

  /// Handles messages until stop() or SIGINT/SIGTERM; returns kExitOk.
  int spin();
  /// Waits up to `timeout_ms` for one message and handles it; false once stopping.
  bool spin_once(int timeout_ms);
  void stop() { stopping_ = true; }
  bool stopping() const;

  const NodeCounters& counters() const { return counters_; }
  /// Reason classes counted per channel; beyond this many on one channel, the rest are counted
  /// as one ("other reasons"), so a stream of varied garbage cannot grow the message unbounded.
  static constexpr size_t kMaxReasonsPerChannel = 16;
  /// The counts PROCESS_REJECTIONS carries, sorted by channel then reason.
  std::vector<kestrel::rejection_reason_t> rejection_counts() const;
  const std::string& name() const { return name_; }
  lcm::LCM& lcm() { return lcm_; }

 private:
  using Dispatch = std::function<int64_t(const void*, size_t)>;
  struct Subscription {
    Node* node;
    std::string channel;
    Dispatch dispatch;
    bool is_control;  // REPLAY_CONTROL: not an input, never acknowledged
  };
  // Per channel with a rejection: when the last one was, and whether a message was accepted
  // after it. Entries leave once the channel is no longer being rejected.
  // `order` ranks rejections by arrival: two within one tick of the clock are still told
  // apart, so the newer one is the one named.
  struct Rejection {
    int64_t at_us = 0;
    int64_t order = 0;
    std::string why;  // printable, without the channel's name
    bool accepted_since = false;
  };
  static void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                         Subscription* subscription);
  void add_subscription(const std::string& channel, Dispatch dispatch, int queue_capacity,
                        bool is_control = false);
  void handle(Subscription& s, const lcm::ReceiveBuffer& rbuf);
  void on_control(const kestrel::replay_control_t& control);
  void reject(const std::string& channel, const std::string& why);
  void accepted(const std::string& channel);
  bool still_rejecting(const Rejection& r, int64_t now_us) const;
  void publish_heartbeat_if_state_changed();
  void maybe_heartbeat();
  void publish_heartbeat();

  std::string name_;
  std::string url_;
  lcm::LCM lcm_;
  Clock clock_;
  int64_t heartbeat_period_us_;
  int64_t next_heartbeat_us_ = std::numeric_limits<int64_t>::min();  // due at once
  std::deque<Subscription> subscriptions_;
  std::vector<std::string> advertised_;
  std::function<void()> reset_;
  Health own_health_;  // as set_health() left it, whatever the input does
  int8_t reported_state_ = kestrel::process_status_t::STATE_STARTING;  // in the last heartbeat
  NodeCounters counters_;
  std::map<std::string, int64_t> rejections_per_channel_;
  struct ReasonCount {
    int64_t count = 0;
    std::string last;
  };
  std::map<std::string, std::map<std::string, ReasonCount>> reasons_;  // channel -> class -> count
  std::map<std::string, Rejection> rejecting_;  // channels being rejected
  bool stopping_ = false;

  // Lock-step state: the active replay session, and what was published while handling the
  // current input.
  int64_t lockstep_session_ = 0;
  bool in_handler_ = false;
  std::vector<std::string> outputs_;
};

}  // namespace kestrel::transport
