#include "tools/replay/event_filter.h"

#include "tools/replay/process_table.h"

namespace kestrel::replay {

EventFilter::EventFilter(const SelectionOptions& options,
                         std::function<std::vector<std::string>(const std::string&)> live_publishers,
                         std::optional<int64_t> log_start)
    : options_(options), live_publishers_(std::move(live_publishers)), first_timestamp_(log_start) {
  if (!options.channels_regex.empty()) regex_.emplace(options.channels_regex);
}

std::optional<std::string> EventFilter::channel_verdict(const std::string& channel) {
  const auto cached = verdicts_.find(channel);
  if (cached != verdicts_.end()) return cached->second;
  std::optional<std::string> reason;
  if (is_protocol_channel(channel)) {
    reason = "heartbeats and replay protocol are never replayed";
  } else if (regex_) {
    if (!std::regex_match(channel, *regex_)) reason = "not selected by --channels";
  } else if (live_publishers_) {
    std::string names;
    for (const auto& p : live_publishers_(channel)) names += (names.empty() ? "" : ", ") + p;
    if (!names.empty()) reason = "published by live process " + names;
  }
  verdicts_.emplace(channel, reason);
  return reason;
}

bool EventFilter::accept(const transport::LogEvent& event) {
  if (!first_timestamp_) first_timestamp_ = event.timestamp;
  if (auto reason = channel_verdict(event.channel)) {
    SkippedChannel& s = skipped_[event.channel];
    ++s.events;
    s.reason = *reason;
    return false;
  }
  const double t_s = 1e-6 * static_cast<double>(event.timestamp - *first_timestamp_);
  // Without --start nothing is before the window: an event stamped earlier than the first is
  // out of time order (the replay says so), not outside a window nobody asked for.
  const bool before = options_.start_s > 0.0 && t_s < options_.start_s;
  const bool after = options_.duration_s > 0.0 && t_s > options_.start_s + options_.duration_s;
  if (before || after) {
    ++outside_window_;
    return false;
  }
  return true;
}

std::string check_channel_regex(const std::string& regex) {
  try {
    std::regex r(regex);
    return {};
  } catch (const std::regex_error& e) {
    return "not a valid regular expression: " + std::string(e.what());
  }
}

}  // namespace kestrel::replay
