#include "common/transport/node.h"

#include <CLI/Error.hpp>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <iterator>
#include <stdexcept>
#include <string_view>

#include "common/error.h"
#include "common/text.h"
#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "kestrel/replay_ack_t.hpp"

namespace kestrel::transport {
namespace {

std::atomic<bool> g_signalled{false};

void on_signal(int) { g_signalled = true; }

void install_signal_handlers() {
  static const bool installed = [] {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    return true;
  }();
  (void)installed;
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Log the first few rejections on a channel, then one in a hundred, so that a stream of bad
// messages cannot flood the terminal while the count stays exact.
bool should_log(int64_t nth) { return nth <= 5 || nth % 100 == 0; }

// `why` usually starts with the channel already (decode errors); avoid saying it twice.
std::string without_channel(const std::string& channel, const std::string& why) {
  const bool named = why.compare(0, channel.size(), channel) == 0 && why.size() > channel.size() &&
                     why[channel.size()] == ':';
  return named ? why.substr(std::min(why.size(), channel.size() + 2)) : why;
}

// A heartbeat's reason is shown on an operator's terminal: bytes from a damaged message must
// not reach it raw (escape_bytes), and one reason must not fill the screen.
std::string printable_reason(const std::string& text) {
  constexpr size_t kMaxChars = 200;
  std::string out = escape_bytes(text);
  if (out.size() > kMaxChars) {
    // Cut before a character, not inside one (a UTF-8 sequence or an escape).
    size_t cut = kMaxChars;
    while (cut > 0 && (static_cast<unsigned char>(out[cut]) & 0xC0) == 0x80) --cut;
    const size_t escape = out.rfind('\\', cut);
    if (escape != std::string::npos && cut - escape < 4) cut = escape;
    out = out.substr(0, cut) + "...";
  }
  return out;
}

// LCM subscribes to "^CHANNEL$" compiled as a GLib regular expression: these characters
// would make a name a pattern.
constexpr std::string_view kPatternCharacters = "\\^$.|?*+()[]{}";
constexpr size_t kMaxChannelChars = LCM_MAX_CHANNEL_NAME_LENGTH;  // LCM refuses longer names

}  // namespace

int64_t steady_microseconds() {
  const auto since_origin = std::chrono::steady_clock::now().time_since_epoch();
  return std::chrono::duration_cast<std::chrono::microseconds>(since_origin).count();
}

std::string rejection_reason_class(const std::string& reason) {
  std::string out;
  out.reserve(reason.size());
  size_t i = 0;
  while (i < reason.size()) {
    const char c = reason[i];
    // A number starts with a digit, or a sign or point before one, not inside a word ("x2").
    const bool word_before = i > 0 && (std::isalnum(static_cast<unsigned char>(reason[i - 1])) || reason[i - 1] == '_');
    size_t j = i;
    if ((c == '-' || c == '+') && j + 1 < reason.size()) ++j;
    if (reason[j] == '.' && j + 1 < reason.size()) ++j;
    if (word_before || !is_digit(reason[j])) {
      out += c;
      ++i;
      continue;
    }
    j = i + ((c == '-' || c == '+') ? 1 : 0);
    while (j < reason.size() &&
           (is_digit(reason[j]) || (reason[j] == '.' && j + 1 < reason.size() && is_digit(reason[j + 1]))))
      ++j;
    // An exponent: e or E, an optional sign, digits.
    if (j + 1 < reason.size() && (reason[j] == 'e' || reason[j] == 'E')) {
      size_t k = j + 1;
      if (reason[k] == '-' || reason[k] == '+') ++k;
      if (k < reason.size() && is_digit(reason[k])) {
        while (k < reason.size() && is_digit(reason[k])) ++k;
        j = k;
      }
    }
    out += '#';
    i = j;
  }
  return out;
}

std::string channel_name_problem(const std::string& channel) {
  if (channel.empty()) return "is empty";
  if (channel.size() > kMaxChannelChars) {
    return "has " + std::to_string(channel.size()) + " characters; LCM takes at most " +
           std::to_string(kMaxChannelChars);
  }
  for (const char c : channel) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte == ' ') return "contains a space; a channel name is one word";
    if (byte < 0x20 || byte >= 0x7f)
      return "contains the byte " + escape_bytes(std::string(1, c)) + "; a channel name is printable ASCII";
    if (kPatternCharacters.find(c) != std::string_view::npos) {
      return std::string("contains '") + c +
             "', which LCM would take as part of a pattern; a channel is subscribed to by its exact name";
    }
  }
  return "";
}

Node::Node(std::string name, const std::string& lcm_url, double heartbeat_period_s, Clock clock)
    : name_(std::move(name)),
      url_(resolve_lcm_url(lcm_url)),
      lcm_(url_),
      clock_(std::move(clock)),
      heartbeat_period_us_(static_cast<int64_t>(std::llround(heartbeat_period_s * 1e6))) {
  if (!clock_) throw std::invalid_argument("Node '" + name_ + "': the clock is empty");
  if (!lcm_.good()) throw UnavailableError("cannot start LCM on '" + url_ + "'");
  install_signal_handlers();
  add_subscription(
      channel::kReplayControl,
      [this](const void* data, size_t size) -> int64_t {
        on_control(decode_message<kestrel::replay_control_t>(data, size, channel::kReplayControl));
        return 0;
      },
      0, /*is_control=*/true);
  advertise(channel::kProcessStatus);
}

Node::~Node() {
  own_health_.state = kestrel::process_status_t::STATE_STOPPING;
  publish_heartbeat();
}

void Node::add_subscription(const std::string& channel, Dispatch dispatch, int queue_capacity,
                            bool is_control) {
  // Checked before anything changes, so a caller that handles the error keeps a working node.
  if (const std::string problem = channel_name_problem(channel); !problem.empty())
    throw CLI::ValidationError("channel '" + escape_bytes(channel) + "'", problem);
  subscriptions_.push_back({this, channel, std::move(dispatch), is_control});
  lcm::Subscription* sub = lcm_.subscribeFunction(channel, &Node::on_message, &subscriptions_.back());
  if (!sub) throw std::runtime_error("cannot subscribe to " + channel);
  sub->setQueueCapacity(queue_capacity);
}

void Node::advertise(const std::string& channel) {
  for (const auto& c : advertised_)
    if (c == channel) return;
  advertised_.push_back(channel);
}

void Node::on_message(const lcm::ReceiveBuffer* rbuf, const std::string&, Subscription* s) {
  s->node->handle(*s, *rbuf);
}

void Node::handle(Subscription& s, const lcm::ReceiveBuffer& rbuf) {
  if (s.is_control) {
    try {
      s.dispatch(rbuf.data, rbuf.data_size);
      accepted(s.channel);
    } catch (const std::exception& e) {
      reject(s.channel, e.what());
    }
    return;
  }
  ++counters_.messages_in;
  in_handler_ = true;
  outputs_.clear();
  int64_t utime = 0;
  try {
    utime = s.dispatch(rbuf.data, rbuf.data_size);
    if (utime > counters_.last_input_utime) counters_.last_input_utime = utime;
    accepted(s.channel);
  } catch (const InputError& e) {
    reject(s.channel, e.what());
  } catch (const std::exception& e) {
    // A library failing on an input it accepted is a bug, but the process must keep serving
    // the other inputs: report it loudly, count it, carry on.
    reject(s.channel, std::string("handler failed: ") + e.what());
  }
  in_handler_ = false;
  if (lockstep_session_ != 0) {
    kestrel::replay_ack_t ack;
    ack.session = lockstep_session_;
    ack.process = name_;
    ack.channel = s.channel;
    ack.input_utime = utime;
    ack.output_channels = outputs_;
    ack.num_outputs = static_cast<int32_t>(outputs_.size());
    lcm_.publish(channel::kReplayAck, &ack);
  }
}

void Node::reject(const std::string& channel, const std::string& why) {
  ++counters_.messages_rejected;
  const int64_t nth = ++rejections_per_channel_[channel];
  // Printable in the log as in the heartbeat: a damaged message's bytes may be terminal codes.
  const std::string reason = printable_reason(without_channel(channel, why));
  if (should_log(nth)) spdlog::warn("rejected message #{} on {}: {}", nth, channel, reason);
  rejecting_[channel] = Rejection{clock_(), counters_.messages_rejected, reason, false};
  auto& classes = reasons_[channel];
  std::string kind = rejection_reason_class(reason);
  if (!classes.count(kind) && classes.size() >= kMaxReasonsPerChannel) kind = "other reasons";
  ReasonCount& c = classes[kind];
  ++c.count;
  c.last = reason;
  publish_heartbeat_if_state_changed();
}

void Node::accepted(const std::string& channel) {
  const auto it = rejecting_.find(channel);
  if (it == rejecting_.end()) return;
  it->second.accepted_since = true;
  publish_heartbeat_if_state_changed();
}

bool Node::still_rejecting(const Rejection& r, int64_t now_us) const {
  return !r.accepted_since || now_us - r.at_us < heartbeat_period_us_;
}

Node::Health Node::health() const {
  const int8_t own = own_health_.state;
  if (own == kestrel::process_status_t::STATE_STOPPING || own == kestrel::process_status_t::STATE_FAILED)
    return own_health_;
  const int64_t now = clock_();
  const std::pair<const std::string, Rejection>* last = nullptr;
  std::vector<std::string> others;
  for (const auto& entry : rejecting_) {
    if (!still_rejecting(entry.second, now)) continue;
    if (last && entry.second.order < last->second.order) {
      others.push_back(entry.first);
      continue;
    }
    if (last) others.push_back(last->first);
    last = &entry;
  }
  if (!last) return own_health_;
  Health h;
  h.state = kestrel::process_status_t::STATE_DEGRADED;
  h.message = "rejecting " + last->first + ": " + last->second.why;
  if (!others.empty()) {
    h.message += " (also rejecting";
    for (const auto& c : others) h.message += " " + c;
    h.message += ")";
  }
  if (!own_health_.message.empty()) h.message += "; " + own_health_.message;
  return h;
}

void Node::publish_heartbeat_if_state_changed() {
  const int64_t now = clock_();
  for (auto it = rejecting_.begin(); it != rejecting_.end();)
    it = still_rejecting(it->second, now) ? std::next(it) : rejecting_.erase(it);
  if (health().state != reported_state_) publish_heartbeat();
}

void Node::on_control(const kestrel::replay_control_t& control) {
  switch (control.command) {
    case kestrel::replay_control_t::COMMAND_BEGIN:
      if (lockstep_session_ != control.session) spdlog::info("lock-step replay session {} begins", control.session);
      lockstep_session_ = control.session;
      publish_heartbeat();  // the replay learns our subscriptions from this
      {
        // "I have joined": a driver whose set may change takes a process in from this answer
        // on (tools/replay/lockstep_driver.h); the channel is the control channel itself.
        kestrel::replay_ack_t joined;
        joined.session = lockstep_session_;
        joined.process = name_;
        joined.channel = channel::kReplayControl;
        joined.input_utime = 0;
        joined.num_outputs = 0;
        lcm_.publish(channel::kReplayAck, &joined);
      }
      break;
    case kestrel::replay_control_t::COMMAND_RESET:
      spdlog::info("reset requested by replay session {}", control.session);
      if (reset_) reset_();
      publish_heartbeat();
      break;
    case kestrel::replay_control_t::COMMAND_END:
      if (lockstep_session_ == control.session) {
        spdlog::info("lock-step replay session {} ends", control.session);
        lockstep_session_ = 0;
      }
      break;
    default:
      throw InputError(std::string(channel::kReplayControl) + ": unknown command " +
                       std::to_string(control.command));
  }
}

void Node::publish_bytes(const std::string& channel, const std::vector<uint8_t>& bytes) {
  if (lcm_.publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size())) != 0) {
    spdlog::warn("publishing {} bytes on {} failed", bytes.size(), channel);
  }
  ++counters_.messages_out;
  if (in_handler_) outputs_.push_back(channel);
  advertise(channel);
}

void Node::set_health(int8_t state, const std::string& message) {
  const bool changed = state != own_health_.state || message != own_health_.message;
  own_health_.state = state;
  own_health_.message = message;
  if (changed) publish_heartbeat();
}

bool Node::stopping() const { return stopping_ || g_signalled; }

bool Node::spin_once(int timeout_ms) {
  if (stopping()) return false;
  maybe_heartbeat();
  const int rc = lcm_.handleTimeout(timeout_ms);
  if (rc < 0 && !stopping()) {
    // select() interrupted by a signal other than ours, or LCM failed: retry on the next call.
    spdlog::debug("LCM handle returned {}", rc);
  }
  maybe_heartbeat();
  return !stopping();
}

int Node::spin() {
  if (own_health_.state == kestrel::process_status_t::STATE_STARTING)
    set_health(kestrel::process_status_t::STATE_RUNNING, "");
  while (spin_once(100)) {
  }
  return kExitOk;
}

void Node::maybe_heartbeat() {
  // A rejected channel recovers without an event: its period ends while the process waits.
  publish_heartbeat_if_state_changed();
  const int64_t now = clock_();
  if (now < next_heartbeat_us_) return;
  next_heartbeat_us_ = now + heartbeat_period_us_;
  publish_heartbeat();
}

std::vector<kestrel::rejection_reason_t> Node::rejection_counts() const {
  std::vector<kestrel::rejection_reason_t> out;
  for (const auto& [channel, classes] : reasons_) {
    for (const auto& [kind, c] : classes) {
      kestrel::rejection_reason_t r;
      r.channel = channel;
      r.reason = kind;
      r.count = c.count;
      r.last = c.last;
      out.push_back(std::move(r));
    }
  }
  return out;
}

void Node::publish_heartbeat() {
  kestrel::process_status_t s;
  s.utime = wall_utime();
  s.name = name_;
  s.pid = static_cast<int32_t>(::getpid());
  const Health reported = health();
  s.state = reported.state;
  s.message = reported.message;
  reported_state_ = reported.state;
  for (const Subscription& sub : subscriptions_)
    if (!sub.is_control) s.subscriptions.push_back(sub.channel);
  s.num_subscriptions = static_cast<int32_t>(s.subscriptions.size());
  s.publications = advertised_;
  s.num_publications = static_cast<int32_t>(s.publications.size());
  s.messages_in = counters_.messages_in;
  s.messages_out = counters_.messages_out;
  s.messages_rejected = counters_.messages_rejected;
  s.last_input_utime = counters_.last_input_utime;
  lcm_.publish(channel::kProcessStatus, &s);
  if (reasons_.empty()) return;
  kestrel::rejection_counts_t r;
  r.utime = s.utime;
  r.name = name_;
  r.pid = s.pid;
  r.rejected = counters_.messages_rejected;
  r.reasons = rejection_counts();
  r.num_reasons = static_cast<int32_t>(r.reasons.size());
  lcm_.publish(channel::kProcessRejections, &r);
}

}  // namespace kestrel::transport
