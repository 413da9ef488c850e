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
//  * PROCESS_STATUS is published about once per heartbeat period with the counters, the
//    subscribed and advertised channels, and the health set by set_health().
//  * Lock-step: between REPLAY_CONTROL BEGIN and END of a session, after every input handled
//    (accepted or rejected) the node publishes REPLAY_ACK listing the channels it published
//    on meanwhile; RESET calls the reset handler. See tools/replay/README.md.
//  * SIGINT and SIGTERM make spin() return after the current handler.

#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/transport/message.h"
#include "kestrel/process_status_t.hpp"
#include "kestrel/replay_control_t.hpp"

namespace kestrel::transport {

struct NodeCounters {
  int64_t messages_in = 0;
  int64_t messages_out = 0;
  int64_t messages_rejected = 0;
  int64_t last_input_utime = 0;
};

class Node {
 public:
  /// Connects to `lcm_url` (resolved by resolve_lcm_url); throws UnavailableError naming
  /// the URL if LCM cannot start (cli::App::run turns it into exit code 4).
  Node(std::string name, const std::string& lcm_url, double heartbeat_period_s = 1.0);
  ~Node();
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  /// Calls handler(const Msg&) for each valid message on `channel` (an exact name).
  /// At most `queue_capacity` messages wait; older ones are dropped by LCM when the process
  /// falls behind (30 suits sensors; 0 means unbounded).
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
  /// Health reported in heartbeats (process_status_t::STATE_*), with a reason.
  void set_health(int8_t state, const std::string& message);

  /// Handles messages until stop() or SIGINT/SIGTERM; returns kExitOk.
  int spin();
  /// Waits up to `timeout_ms` for one message and handles it; false once stopping.
  bool spin_once(int timeout_ms);
  void stop() { stopping_ = true; }
  bool stopping() const;

  const NodeCounters& counters() const { return counters_; }
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
  static void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                         Subscription* subscription);
  void add_subscription(const std::string& channel, Dispatch dispatch, int queue_capacity,
                        bool is_control = false);
  void handle(Subscription& s, const lcm::ReceiveBuffer& rbuf);
  void on_control(const kestrel::replay_control_t& control);
  void reject(const std::string& channel, const std::string& why);
  void maybe_heartbeat();
  void publish_heartbeat();

  std::string name_;
  std::string url_;
  lcm::LCM lcm_;
  std::chrono::steady_clock::duration heartbeat_period_;
  std::chrono::steady_clock::time_point next_heartbeat_{};
  std::deque<Subscription> subscriptions_;
  std::vector<std::string> advertised_;
  std::function<void()> reset_;
  int8_t health_ = kestrel::process_status_t::STATE_STARTING;
  std::string health_message_;
  NodeCounters counters_;
  std::map<std::string, int64_t> rejections_per_channel_;
  bool stopping_ = false;

  // Lock-step state: the active replay session, and what was published while handling the
  // current input.
  int64_t lockstep_session_ = 0;
  bool in_handler_ = false;
  std::vector<std::string> outputs_;
};

}  // namespace kestrel::transport
