// The LCM side of lock-step driving (lockstep_driver.h). The accounting lives in AckLedger,
// the discovered processes in ProcessTable; this file moves messages and keeps time.

#include "tools/replay/lockstep_driver.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/message.h"
#include "kestrel/replay_control_t.hpp"

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

// Live processes answer every BEGIN, so while discovering a pid not heard for a second is
// gone; two pids under one name for longer than that are two processes, not a restart.
constexpr double kConflictPersistence_s = 1.0;

[[noreturn]] void refuse(const std::vector<std::string>& conflicts) {
  throw PeerError(fmt::format(
      "several processes share a name, which lock-step cannot tell apart: {}; give each a "
      "unique name",
      fmt::join(conflicts, ", ")));
}

}  // namespace

LockstepDriver::LockstepDriver(lcm::LCM& lcm, Pump pump, DriverOptions options, Interrupted interrupted)
    : lcm_(lcm), pump_(std::move(pump)), o_(std::move(options)), interrupted_(std::move(interrupted)),
      session_(random_session()), table_(std::max(kConflictPersistence_s, 5 * o_.begin_period_s)) {
  if (!o_.record_path.empty()) recorder_.emplace(o_.record_path);
  // Recording needs every channel; otherwise the protocol's three are enough, which spares
  // receiving our own (possibly large) input messages back.
  const std::vector<std::string> patterns =
      recorder_ ? std::vector<std::string>{".*"}
                : std::vector<std::string>{channel::kReplayAck, channel::kProcessStatus, channel::kReplayControl};
  for (const auto& p : patterns) {
    lcm::Subscription* s = lcm_.subscribeFunction(p, &LockstepDriver::on_message, this);
    s->setQueueCapacity(0);
    subscriptions_.push_back(s);
  }
}

LockstepDriver::~LockstepDriver() {
  if (begun_) {
    // END is idempotent; twice makes a lost datagram harmless.
    send_control(replay_control_t::COMMAND_END);
    send_control(replay_control_t::COMMAND_END);
  }
  for (lcm::Subscription* s : subscriptions_) lcm_.unsubscribe(s);
}

bool LockstepDriver::begin() {
  if (!discover()) return false;
  if (o_.reset && !reset_processes()) return false;
  rebuild_ledger();
  return true;
}

void LockstepDriver::rebuild_ledger() {
  ledger_.emplace(table_.consumers(), [this](const std::string& c) { return is_recorded(c); });
  ledger_members_.clear();
  for (const auto& [name, p] : table_.processes()) ledger_members_.insert(name);
  depths_.clear();
  membership_changed_ = false;
}

bool LockstepDriver::discover() {
  const double start = now_s();
  double next_begin = start;
  last_change_s_ = start;
  while (true) {
    if (interrupted_()) return false;
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
      spdlog::warn("the set of processes kept changing for {:.1f} s; going ahead with it", o_.discovery_timeout_s);
      break;
    }
  }
  if (const auto conflicts = table_.conflicts(now_s()); !conflicts.empty()) refuse(conflicts);
  discovering_ = false;
  if (table_.processes().empty()) spdlog::warn("no kestrel process answered; publishing into nothing");
  for (const auto& line : describe(table_)) spdlog::info("process {}", line);
  return true;
}

void LockstepDriver::check_names(double now) {
  const auto conflicts = table_.conflicts(now);
  if (conflicts.empty()) {
    conflict_since_s_.reset();
    return;
  }
  if (!conflict_since_s_) conflict_since_s_ = now;
  if (now - *conflict_since_s_ >= kConflictPersistence_s) refuse(conflicts);
}

bool LockstepDriver::reset_processes() {
  const double sent = now_s();
  send_control(replay_control_t::COMMAND_RESET);
  // Each process heartbeats after its reset; wait for a heartbeat from all of them.
  while (true) {
    if (interrupted_()) return false;
    std::vector<std::string> silent;
    for (const auto& [name, p] : table_.processes())
      if (p.last_heard_s < sent) silent.push_back(name);
    if (silent.empty()) return true;
    if (now_s() - sent > o_.ack_timeout_s)
      throw PeerError(fmt::format("no answer to RESET within {:.1f} s from: {}", o_.ack_timeout_s,
                                  fmt::join(silent, ", ")));
    pump(0.05);
  }
}

bool LockstepDriver::publish(const std::string& channel, const uint8_t* data, size_t size, int64_t timestamp,
                             const std::string& label) {
  if (!ledger_) throw std::logic_error("LockstepDriver::publish before begin()");
  if (interrupted_()) return false;
  if (o_.dynamic_membership) {
    const std::set<std::string> stopped = stopped_;  // drop() edits stopped_
    for (const auto& name : stopped) drop(name, "stopped");
  }
  if (membership_changed_) {
    // A process that joined during the last event may still be acknowledging inputs it was not
    // expected to handle; taken as a member now, those would count against it. Let them land
    // first (they are rare: a restart), then count it in.
    for (int i = 0; i < 5; ++i) pump(0.02);
    rebuild_ledger();
  }
  inputs_.insert(channel);
  if (recorder_ && o_.record_inputs.count(channel)) recorder_->add(channel, data, size);
  ledger_->publish(channel);
  latency_.begin_event(channel, now_s());
  if (lcm_.publish(channel, data, static_cast<unsigned>(size)) != 0)
    throw PeerError("cannot publish " + label + " on LCM");
  if (!wait_settled(label)) return false;
  latency_.end_event();
  unannounced_ += ledger_->finish_event();
  if (recorder_) recorder_->flush_event(timestamp, depths(channel));
  return true;
}

void LockstepDriver::close() {
  if (recorder_) recorder_->close();
}

std::map<std::string, int64_t> LockstepDriver::recorded() const {
  return recorder_ ? recorder_->recorded() : std::map<std::string, int64_t>{};
}

void LockstepDriver::on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel, LockstepDriver* self) {
  self->handle(channel, *rbuf);
}

void LockstepDriver::handle(const std::string& channel, const lcm::ReceiveBuffer& rbuf) {
  try {
    if (channel == channel::kReplayAck) {
      on_ack(transport::decode_message<kestrel::replay_ack_t>(rbuf.data, rbuf.data_size, channel));
    } else if (channel == channel::kProcessStatus) {
      on_status(transport::decode_message<process_status_t>(rbuf.data, rbuf.data_size, channel));
    } else if (channel == channel::kReplayControl) {
      const auto c = transport::decode_message<replay_control_t>(rbuf.data, rbuf.data_size, channel);
      if (c.session != session_ && !protocol_error_)
        protocol_error_ = "another lock-step driver (session " + std::to_string(c.session) +
                          ") is running on this LCM network; two would steal each other's processes";
    } else if (ledger_ && is_recorded(channel)) {
      ledger_->receive(channel);
      recorder_->add(channel, static_cast<const uint8_t*>(rbuf.data), rbuf.data_size);
      last_progress_s_ = now_s();
    }
  } catch (const InputError& e) {
    spdlog::warn("ignoring a malformed message: {}", e.what());
  }
}

void LockstepDriver::on_ack(const kestrel::replay_ack_t& ack) {
  if (ack.session != session_ || !ledger_) return;  // another session's, or before any event
  if (ack.channel == channel::kReplayControl) {  // "I have joined": the answer to BEGIN
    const auto c = candidates_.find(ack.process);
    if (c == candidates_.end()) return;
    table_.update(c->second, now_s());
    candidates_.erase(c);
    membership_changed_ = true;
    ++joined_;
    spdlog::info("process {} joined the lock-step session; it takes part from the next event", ack.process);
    return;
  }
  if (o_.dynamic_membership && ledger_members_.count(ack.process) == 0) {
    ledger_->announce(ack.output_channels);  // joined during this event: it owed nothing
  } else {
    ledger_->acknowledge(ack.process, ack.channel, ack.output_channels);
    latency_.acknowledge(ack.process, ack.channel, now_s());
  }
  last_progress_s_ = now_s();
}

void LockstepDriver::drop(const std::string& name, const std::string& why) {
  if (ledger_) ledger_->forget(name);
  ledger_members_.erase(name);
  table_.remove(name);
  stopped_.erase(name);
  membership_changed_ = true;
  ++dropped_;
  spdlog::warn("process {} left the lock-step session ({}); going on without it", name, why);
}

void LockstepDriver::invite(const process_status_t& status) {
  candidates_[status.name] = status;
  const double t = now_s();
  if (t - last_invite_s_ < o_.begin_period_s) return;
  last_invite_s_ = t;
  send_control(replay_control_t::COMMAND_BEGIN);  // members answer it again, harmlessly
}

void LockstepDriver::on_status(const process_status_t& s) {
  if (discovering_) {
    if (table_.update(s, now_s())) last_change_s_ = now_s();
    return;
  }
  if (o_.dynamic_membership) {
    const auto it = table_.processes().find(s.name);
    if (it != table_.processes().end() && it->second.pid != s.pid) drop(s.name, "restarted as pid " + std::to_string(s.pid));
    if (!table_.contains(s.name)) {
      if (s.state != process_status_t::STATE_STOPPING && s.state != process_status_t::STATE_FAILED) invite(s);
      return;
    }
  } else if (!table_.contains(s.name)) {
    if (latecomers_.insert(s.name).second)
      spdlog::warn("process {} appeared after discovery: it is not part of this lock-step session", s.name);
    return;
  }
  table_.update(s, now_s());
  if (s.state == process_status_t::STATE_STOPPING || s.state == process_status_t::STATE_FAILED) stopped_.insert(s.name);
}

bool LockstepDriver::is_recorded(const std::string& channel) const {
  return recorder_.has_value() && !is_protocol_channel(channel) && inputs_.count(channel) == 0 &&
         (!o_.record_filter || o_.record_filter(channel));
}

const std::map<std::string, int>& LockstepDriver::depths(const std::string& input) {
  auto it = depths_.find(input);
  if (it == depths_.end()) it = depths_.emplace(input, channel_depths(input, table_)).first;
  return it->second;
}

bool LockstepDriver::wait_settled(const std::string& label) {
  last_progress_s_ = now_s();
  while (!ledger_->settled()) {
    if (interrupted_()) return false;
    const std::set<std::string> stopped = stopped_;  // drop() edits stopped_
    for (const auto& name : stopped) {
      if (!ledger_->owes(name)) continue;
      if (!o_.dynamic_membership) throw PeerError(name + " stopped during the session, at " + label);
      drop(name, "stopped at " + label);
    }
    if (now_s() - last_progress_s_ > o_.ack_timeout_s) {
      std::string why;
      for (const auto& owed : ledger_->outstanding()) why += (why.empty() ? "" : "; ") + explain(owed);
      if (!o_.dynamic_membership)
        throw PeerError(fmt::format("{}: no progress for {:.1f} s: {} (is it still running? raise "
                                    "--ack-timeout if it is only slow)",
                                    label, o_.ack_timeout_s, why));
      // A process killed in flight never answers: drop whoever still owes, and end the event.
      std::set<std::string> silent;
      for (const auto& owed : ledger_->outstanding())
        if (!owed.process.empty() && owed.count > 0) silent.insert(owed.process);
      for (const auto& name : silent) drop(name, fmt::format("silent for {:.1f} s at {}", o_.ack_timeout_s, label));
      spdlog::warn("{}: ended without {}", label, why);
      return true;
    }
    pump(0.1);
  }
  return true;
}

// Handles what arrives within `timeout_s`. Errors found in a handler are thrown from here,
// not from the handler: they must not unwind through LCM's C code.
void LockstepDriver::pump(double timeout_s) {
  pump_(std::max(1, static_cast<int>(std::lround(timeout_s * 1000.0))));
  if (protocol_error_) throw PeerError(*protocol_error_);
}

void LockstepDriver::send_control(int8_t command) {
  replay_control_t c{};
  c.session = session_;
  c.command = command;
  lcm_.publish(channel::kReplayControl, &c);
}

}  // namespace kestrel::replay
