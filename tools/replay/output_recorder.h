#pragma once
// Writes what the processes published during a lock-step replay to an LCM log, in an
// order that does not depend on thread or network timing, so that two replays of the same
// log through the same processes give byte-identical files.
//
// Canonical order of the outputs of one input event: by the channel's causal depth (its
// shortest distance from the input channel through the processes' subscriptions and
// publications; channels not reachable come last), then by channel name, then in arrival
// order within a channel. Arrival order within a channel is deterministic when the channel
// has a single publisher that handles its inputs in order, which is kestrel's convention.
// Every output is stamped with the input event's timestamp.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/transport/log_file.h"
#include "tools/replay/process_table.h"

namespace kestrel::replay {

/// channel -> causal depth from `input_channel` (the input itself is 0).
std::map<std::string, int> channel_depths(const std::string& input_channel,
                                          const ProcessTable& table);

class OutputRecorder {
 public:
  /// Creates `path` (InputError if it cannot).
  explicit OutputRecorder(const std::string& path);

  /// Buffers one output of the current input event.
  void add(const std::string& channel, const uint8_t* data, size_t size);
  /// Writes the buffered outputs in canonical order, stamped `timestamp`.
  void flush_event(int64_t timestamp, const std::map<std::string, int>& depths);
  /// Flushes the file; InputError on a write error.
  void close();

  const std::map<std::string, int64_t>& recorded() const { return recorded_; }
  int64_t total() const;

 private:
  struct Output {
    std::string channel;
    std::vector<uint8_t> data;
  };
  transport::LogWriter writer_;
  std::vector<Output> pending_;
  std::map<std::string, int64_t> recorded_;
};

}  // namespace kestrel::replay
