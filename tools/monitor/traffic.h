#pragma once
// Per-channel traffic statistics of the monitor: how many messages, how many bytes, how
// fast, and how many could not be decoded as their channel's type. Knows nothing of LCM:
// the caller feeds it each message with its own clock.
//
// Invariants: a channel's type is fixed by the table given at construction, or else by the
// fingerprint of its first message (or "raw" when that matches no kestrel type); a message
// that does not decode as that type is counted as a failure on its channel, never dropped
// silently.

#include <cstddef>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "tools/monitor/message_types.h"

namespace kestrel::monitor {

struct ChannelStats {
  const MessageType* type = nullptr;  ///< nullptr: raw bytes, not checked
  bool from_table = false;            ///< type named by the table (not guessed)
  int64_t count = 0;
  int64_t bytes = 0;
  int64_t failures = 0;
  std::string last_failure;  ///< the most recent decode error, naming the channel
  double first_s = 0.0;
  double last_s = 0.0;
  int64_t window_count = 0;  ///< since the last table()
  int64_t window_bytes = 0;
};

class TrafficMonitor {
 public:
  explicit TrafficMonitor(std::map<std::string, const MessageType*> channel_types);

  /// Counts and checks one message; returns the decode error ("" if it decoded).
  std::string on_message(const std::string& channel, const void* data, size_t size, double now_s);

  const std::map<std::string, ChannelStats>& channels() const { return channels_; }
  int64_t total() const { return total_; }
  int64_t failures() const { return failures_; }

  /// A table of every channel with its rate and bandwidth since the previous call (or the
  /// start, at `started_s`), and starts a new window.
  std::string table(double now_s);
  /// Whole-run figures per channel, `elapsed_s` being the monitoring time.
  nlohmann::json summary(double elapsed_s) const;

 private:
  std::map<std::string, const MessageType*> channel_types_;
  std::map<std::string, ChannelStats> channels_;
  int64_t total_ = 0;
  int64_t failures_ = 0;
  double window_start_s_ = -1.0;
};

}  // namespace kestrel::monitor
