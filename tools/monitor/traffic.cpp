#include "tools/monitor/traffic.h"

#include <fmt/format.h>

#include "common/error.h"

namespace kestrel::monitor {
namespace {

std::string type_label(const ChannelStats& s) {
  if (!s.type) return "raw";
  return s.from_table ? s.type->name : s.type->name + " (by fingerprint)";
}

}  // namespace

TrafficMonitor::TrafficMonitor(std::map<std::string, const MessageType*> channel_types)
    : channel_types_(std::move(channel_types)) {}

std::string TrafficMonitor::on_message(const std::string& channel, const void* data, size_t size,
                                       double now_s) {
  if (window_start_s_ < 0.0) window_start_s_ = now_s;
  auto [it, first] = channels_.try_emplace(channel);
  ChannelStats& s = it->second;
  if (first) {
    s.first_s = now_s;
    const auto known = channel_types_.find(channel);
    s.from_table = known != channel_types_.end();
    s.type = s.from_table ? known->second : identify(data, size);
  }
  ++s.count;
  ++s.window_count;
  ++total_;
  s.bytes += static_cast<int64_t>(size);
  s.window_bytes += static_cast<int64_t>(size);
  s.last_s = now_s;
  if (!s.type) return {};
  try {
    s.type->check(data, size, channel);
    return {};
  } catch (const InputError& e) {
    ++s.failures;
    ++failures_;
    s.last_failure = e.what();
    return s.last_failure;
  }
}

std::string TrafficMonitor::table(double now_s) {
  const double dt = window_start_s_ < 0.0 ? 0.0 : now_s - window_start_s_;
  std::string out = fmt::format("{:<24} {:<36} {:>9} {:>9} {:>11} {:>8}\n", "channel", "type",
                                "count", "rate Hz", "kB/s", "bad");
  for (auto& [channel, s] : channels_) {
    const double rate = dt > 0.0 ? s.window_count / dt : 0.0;
    const double kbps = dt > 0.0 ? s.window_bytes / dt / 1000.0 : 0.0;
    out += fmt::format("{:<24} {:<36} {:>9} {:>9.1f} {:>11.1f} {:>8}\n", channel, type_label(s),
                       s.count, rate, kbps, s.failures);
    s.window_count = 0;
    s.window_bytes = 0;
  }
  window_start_s_ = now_s;
  return out;
}

nlohmann::json TrafficMonitor::summary(double elapsed_s) const {
  nlohmann::json channels = nlohmann::json::object();
  for (const auto& [channel, s] : channels_) {
    const double span = s.last_s - s.first_s;
    channels[channel] = {
        {"type", s.type ? s.type->name : "raw"},
        {"type_from", s.type ? (s.from_table ? "table" : "fingerprint") : "none"},
        {"count", s.count},
        {"bytes", s.bytes},
        {"decode_failures", s.failures},
        {"last_failure", s.last_failure},
        {"rate_hz", s.count > 1 && span > 0.0 ? (s.count - 1) / span : 0.0},
        {"bandwidth_Bps", elapsed_s > 0.0 ? s.bytes / elapsed_s : 0.0},
    };
  }
  return {{"elapsed_s", elapsed_s},
          {"messages", total_},
          {"decode_failures", failures_},
          {"channels", channels}};
}

}  // namespace kestrel::monitor
