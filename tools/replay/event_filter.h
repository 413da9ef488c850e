#pragma once
// Which events of a log a replay publishes, and why the others are left out: a channel
// regex (--channels), a time window relative to the log's first event (--start,
// --duration), the replay protocol's own channels, and (lock-step, unless --channels is
// given) channels that a live process publishes itself. Knows nothing of LCM.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "common/transport/log_file.h"

namespace kestrel::replay {

struct SelectionOptions {
  std::string channels_regex;  ///< ECMAScript, must match the whole channel name; "" = all
  double start_s = 0.0;        ///< skip events earlier than first event + start_s
  double duration_s = 0.0;     ///< then replay this many seconds of log time; 0 = to the end
};

struct SkippedChannel {
  int64_t events = 0;
  std::string reason;
};

class EventFilter {
 public:
  /// `live_publishers(channel)` names the running processes that publish `channel` (null in
  /// timed mode); their channels are skipped unless a regex selects channels explicitly.
  /// Throws std::regex_error for a bad regex (check_channel_regex() tells beforehand).
  /// `log_start`: the timestamp of the log's first event, which the window counts from, for a
  /// filter that starts reading in the middle of the log (a seek); without it, the first
  /// event the filter sees.
  EventFilter(const SelectionOptions& options,
              std::function<std::vector<std::string>(const std::string&)> live_publishers,
              std::optional<int64_t> log_start = std::nullopt);

  /// True if `event` is to be replayed; otherwise counts why not.
  bool accept(const transport::LogEvent& event);

  const std::map<std::string, SkippedChannel>& skipped_channels() const { return skipped_; }
  int64_t outside_window() const { return outside_window_; }

 private:
  std::optional<std::string> channel_verdict(const std::string& channel);

  SelectionOptions options_;
  std::optional<std::regex> regex_;
  std::function<std::vector<std::string>(const std::string&)> live_publishers_;
  std::map<std::string, std::optional<std::string>> verdicts_;  // channel -> skip reason
  std::map<std::string, SkippedChannel> skipped_;
  std::optional<int64_t> first_timestamp_;
  int64_t outside_window_ = 0;
};

/// Checks a --channels value; returns an error text, empty if it is a valid regex.
std::string check_channel_regex(const std::string& regex);

}  // namespace kestrel::replay
