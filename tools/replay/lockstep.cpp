// Lock-step replay: the LCM side of replayer.h. The accounting lives in AckLedger, the
// discovered processes in ProcessTable; this file moves messages and keeps time.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <random>
#include <set>

#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "common/transport/message.h"
#include "kestrel/replay_ack_t.hpp"
#include "kestrel/replay_control_t.hpp"
#include "tools/replay/ack_ledger.h"
#include "tools/replay/output_recorder.h"
#include "tools/replay/replayer.h"

namespace kestrel::replay {
namespace {

using kestrel::process_status_t;
using kestrel::replay_control_t;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

int64_t random_session() {
  std::random_device rd;
  std::mt19937_64 gen((uint64_t{rd()} << 32) ^ rd());
  std::uniform_int_distribution<int64_t> dist(1, INT64_MAX);
  return dist(gen);
}

std::string event_label(int64_t index, const transport::LogEvent& e) {
  return "event #" + std::to_string(index) + " (" + e.channel + " at " +
         fmt::format("{:.6f}", 1e-6 * static_cast<double>(e.timestamp)) + " s)";
}

class Session {
 public:
  Session(const LockstepOptions& options, const std::atomic<bool>& interrupted)
      : o_(options), interrupted_(interrupted), lcm_(transport::resolve_lcm_url(options.lcm_url)),
        session_(random_session()),
        table_(std::max(kConflictPersistence_s, 5 * options.begin_period_s)) {
    if (!lcm_.good())
      throw NetworkUnavailable("cannot start LCM on '" + transport::resolve_lcm_url(o_.lcm_url) + "'");
    // Recording needs every channel; otherwise the protocol's three are enough, which spares
    // receiving our own (possibly large) input messages back.
    const std::vector<std::string> patterns =
        o_.record_path.empty()
            ? std::vector<std::string>{channel::kReplayAck, channel::kProcessStatus, channel::kReplayControl}
            : std::vector<std::string>{".*"};
    for (const auto& p : patterns)
      lcm_.subscribeFunction(p, &Session::on_message, this)->setQueueCapacity(0);
  }

  ~Session() {
    if (begun_) {
      // END is idempotent; twice makes a lost datagram harmless.
      send_control(replay_control_t::COMMAND_END);
      send_control(replay_control_t::COMMAND_END);
    }
  }

  bool discover() {
    const double start = now_s();
    double next_begin = start;
    last_change_s_ = start;
    while (true) {
      if (interrupted_) return false;
      const double t = now_s();
      if (t >= next_begin) {
        send_control(replay_control_t::COMMAND_BEGIN);
        begun_ = true;
        next_begin += o_.begin_period_s;
      }
      pump(0.02);
      check_names(t);
      const auto missing = table_.missing(o_.expect);
      const bool quiet = t - last_change_s_ >= o_.settle_s && t - start >= o_.settle_s;
      if (missing.empty() && quiet) break;
      if (t - start > o_.discovery_timeout_s) {
        if (!missing.empty()) {
          std::vector<std::string> heard;
          for (const auto& [name, p] : table_.processes()) heard.push_back(name);
          throw PeerError(fmt::format(
              "no heartbeat within {:.1f} s from: {} (heard from: {}); is it running on this "
              "LCM URL and network namespace?",
              o_.discovery_timeout_s, fmt::join(missing, ", "),
              heard.empty() ? "nobody" : fmt::format("{}", fmt::join(heard, ", "))));
        }
        spdlog::warn("the set of processes kept changing for {:.1f} s; going ahead with it",
                     o_.discovery_timeout_s);
        break;
      }
    }
    if (const auto conflicts = table_.conflicts(now_s()); !conflicts.empty()) refuse(conflicts);
    discovering_ = false;
    if (table_.processes().empty())
      spdlog::warn("no kestrel process answered; replaying into nothing");
    for (const auto& line : describe(table_)) spdlog::info("process {}", line);
    return true;
  }

  // Live processes answer every BEGIN, so while discovering a pid not heard for a second is
  // gone; two pids under one name for longer than that are two processes, not a restart.
  static constexpr double kConflictPersistence_s = 1.0;

  void check_names(double t) {
    const auto conflicts = table_.conflicts(t);
    if (conflicts.empty()) {
      conflict_since_s_.reset();
      return;
    }
    if (!conflict_since_s_) conflict_since_s_ = t;
    if (t - *conflict_since_s_ >= kConflictPersistence_s) refuse(conflicts);
  }

  [[noreturn]] static void refuse(const std::vector<std::string>& conflicts) {
    throw PeerError(fmt::format(
        "several processes share a name, which lock-step cannot tell apart: {}; give each a "
        "unique name",
        fmt::join(conflicts, ", ")));
  }

  bool reset_processes() {
    const double sent = now_s();
    send_control(replay_control_t::COMMAND_RESET);
    // Each process heartbeats after its reset; wait for a heartbeat from all of them.
    while (true) {
      if (interrupted_) return false;
      std::vector<std::string> silent;
      for (const auto& [name, p] : table_.processes())
        if (p.last_heard_s < sent) silent.push_back(name);
      if (silent.empty()) return true;
      if (now_s() - sent > o_.ack_timeout_s)
        throw PeerError(fmt::format("no answer to RESET within {:.1f} s from: {}",
                                    o_.ack_timeout_s, fmt::join(silent, ", ")));
      pump(0.05);
    }
  }

  ReplayReport run(transport::LogReader& log) {
    ReplayReport report;
    report.log_path = log.path();
    report.mode = "lock-step";
    report.processes = describe(table_);
    if (!o_.record_path.empty()) {
      recorder_.emplace(o_.record_path);
      report.record_path = o_.record_path;
    }
    ledger_.emplace(table_.consumers(), [this](const std::string& c) { return is_recorded(c); });
    EventFilter filter(o_.selection, [this](const std::string& c) { return table_.publishers(c); });
    const double wall_start = now_s();
    std::optional<int64_t> first_ts, previous_ts;
    int64_t index = -1;
    while (auto event = log.next()) {
      ++index;
      if (interrupted_) {
        report.interrupted = true;
        break;
      }
      if (!filter.accept(*event)) continue;
      if (previous_ts && event->timestamp < *previous_ts) ++report.out_of_order;
      previous_ts = event->timestamp;
      if (!first_ts) first_ts = event->timestamp;
      report.data_s = 1e-6 * static_cast<double>(event->timestamp - *first_ts);

      inputs_.insert(event->channel);
      ledger_->publish(event->channel);
      if (lcm_.publish(event->channel, event->data.data(),
                       static_cast<unsigned>(event->data.size())) != 0)
        throw PeerError("cannot publish " + event_label(index, *event) + " on LCM");
      if (!wait_settled(index, *event)) {
        report.interrupted = true;
        break;
      }
      report.unannounced += ledger_->finish_event();
      if (recorder_) recorder_->flush_event(event->timestamp, depths(event->channel));
      ++report.events_replayed;
      ++report.replayed[event->channel];
    }
    report.wall_s = now_s() - wall_start;
    report.skipped = filter.skipped_channels();
    report.outside_window = filter.outside_window();
    report.damage = log.damage_report();
    if (recorder_) {
      recorder_->close();
      report.recorded = recorder_->recorded();
    }
    return report;
  }

 private:
  static void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Session* self) {
    self->handle(channel, *rbuf);
  }

  void handle(const std::string& channel, const lcm::ReceiveBuffer& rbuf) {
    try {
      if (channel == channel::kReplayAck) {
        on_ack(transport::decode_message<kestrel::replay_ack_t>(rbuf.data, rbuf.data_size, channel));
      } else if (channel == channel::kProcessStatus) {
        on_status(transport::decode_message<process_status_t>(rbuf.data, rbuf.data_size, channel));
      } else if (channel == channel::kReplayControl) {
        const auto c = transport::decode_message<replay_control_t>(rbuf.data, rbuf.data_size, channel);
        if (c.session != session_ && !protocol_error_)
          protocol_error_ = "another replay (session " + std::to_string(c.session) +
                            ") is running on this LCM network; two replays would steal each "
                            "other's processes";
      } else if (ledger_ && is_recorded(channel)) {
        ledger_->receive(channel);
        recorder_->add(channel, static_cast<const uint8_t*>(rbuf.data), rbuf.data_size);
        last_progress_s_ = now_s();
      }
    } catch (const InputError& e) {
      spdlog::warn("ignoring a malformed message: {}", e.what());
    }
  }

  void on_ack(const kestrel::replay_ack_t& ack) {
    if (ack.session != session_ || !ledger_) return;  // another session's, or before any event
    ledger_->acknowledge(ack.process, ack.channel, ack.output_channels);
    last_progress_s_ = now_s();
  }

  void on_status(const process_status_t& s) {
    if (discovering_) {
      if (table_.update(s, now_s())) last_change_s_ = now_s();
      return;
    }
    if (!table_.contains(s.name)) {
      if (latecomers_.insert(s.name).second)
        spdlog::warn("process {} appeared after discovery: it is not part of this replay", s.name);
      return;
    }
    table_.update(s, now_s());
    if (s.state == process_status_t::STATE_STOPPING || s.state == process_status_t::STATE_FAILED)
      stopped_.insert(s.name);
  }

  bool is_recorded(const std::string& channel) const {
    return recorder_.has_value() && !is_protocol_channel(channel) && inputs_.count(channel) == 0;
  }

  const std::map<std::string, int>& depths(const std::string& input) {
    auto it = depths_.find(input);
    if (it == depths_.end()) it = depths_.emplace(input, channel_depths(input, table_)).first;
    return it->second;
  }

  bool wait_settled(int64_t index, const transport::LogEvent& event) {
    last_progress_s_ = now_s();
    while (!ledger_->settled()) {
      if (interrupted_) return false;
      for (const auto& name : stopped_)
        if (ledger_->owes(name))
          throw PeerError(name + " stopped during the replay, at " + event_label(index, event));
      if (now_s() - last_progress_s_ > o_.ack_timeout_s) {
        std::string why;
        for (const auto& owed : ledger_->outstanding()) why += (why.empty() ? "" : "; ") + explain(owed);
        throw PeerError(fmt::format("{}: no progress for {:.1f} s: {} (is it still running? "
                                    "raise --ack-timeout if it is only slow)",
                                    event_label(index, event), o_.ack_timeout_s, why));
      }
      pump(0.1);
    }
    return true;
  }

  // Handles what arrives within `timeout_s`. Errors found in a handler are thrown from
  // here, not from the handler: they must not unwind through LCM's C code.
  void pump(double timeout_s) {
    lcm_.handleTimeout(std::max(1, static_cast<int>(std::lround(timeout_s * 1000.0))));
    if (protocol_error_) throw PeerError(*protocol_error_);
  }

  void send_control(int8_t command) {
    replay_control_t c{};
    c.session = session_;
    c.command = command;
    lcm_.publish(channel::kReplayControl, &c);
  }

  const LockstepOptions& o_;
  const std::atomic<bool>& interrupted_;
  lcm::LCM lcm_;
  const int64_t session_;
  bool begun_ = false;
  bool discovering_ = true;
  double last_change_s_ = 0.0;
  double last_progress_s_ = 0.0;
  ProcessTable table_;
  std::optional<AckLedger> ledger_;
  std::optional<OutputRecorder> recorder_;
  std::set<std::string> inputs_;  // channels the replay publishes: never recorded
  std::set<std::string> stopped_, latecomers_;
  std::map<std::string, std::map<std::string, int>> depths_;
  std::optional<std::string> protocol_error_;
  std::optional<double> conflict_since_s_;
};

}  // namespace

ReplayReport replay_lockstep(transport::LogReader& log, const LockstepOptions& options,
                             const std::atomic<bool>& interrupted) {
  Session session(options, interrupted);
  auto interrupted_report = [&] {
    ReplayReport r;
    r.log_path = log.path();
    r.mode = "lock-step";
    r.interrupted = true;
    return r;
  };
  if (!session.discover()) return interrupted_report();
  if (options.reset && !session.reset_processes()) return interrupted_report();
  return session.run(log);
}

}  // namespace kestrel::replay
