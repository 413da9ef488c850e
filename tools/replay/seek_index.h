#pragma once
// Where a seek in a log starts reading. A timed replay under control (--control) answers a
// seek by publishing, for each channel, the last event before the target (the map, the graph,
// the plan and the image of that moment), which it finds by reading the log in file order until
// the first event at or after the target. Read from the start, that costs the whole log before
// the target at every seek: gigabytes for a long flight with its images.
//
// The index keeps checkpoints taken while the log is read once in file order (the replay's
// first pass, which finds the log's time window), every `spacing_us` of the replayed events'
// log time: the byte offset of the next event, for each channel the offset of its last replayed
// event before it, and the latest timestamp of the replayed events before it. The read from the
// start stops at the first replayed event at or after the target (the others are skipped
// whatever their stamps), so a seek may start from the last checkpoint before which every
// replayed event is older than the target: it reads what the read from the start would have
// read from there on, and finds the same events (timestamps out of order included). The events
// the checkpoint names are read back from their offsets.
//
// Invariants: checkpoints are in file order, the first is the log's start; their latest
// timestamps never decrease; an event not after the last one added adds nothing.

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace kestrel::replay {

struct Checkpoint {
  int64_t offset = 0;  ///< of the first event not read before it
  /// The largest timestamp of the replayed events before it (none: the lowest value).
  int64_t latest_timestamp = std::numeric_limits<int64_t>::min();
  std::map<std::string, int64_t> last_offset_of;  ///< channel -> offset of its last replayed event before it
};

class SeekIndex {
 public:
  /// Throws std::invalid_argument for a spacing that is not positive.
  explicit SeekIndex(int64_t spacing_us = 1'000'000);

  /// Each event of the log as it is read, in file order from the start; `replayed`: the
  /// replay publishes it (the selection takes it), so it may be its channel's last event.
  void add_event(int64_t offset, int64_t timestamp, const std::string& channel, bool replayed);
  /// Where a seek to `target` starts reading.
  const Checkpoint& start_for(int64_t target) const;
  /// The timestamp of the log's first event, once it has been read.
  std::optional<int64_t> first_timestamp() const { return first_timestamp_; }
  size_t size() const { return checkpoints_.size(); }

 private:
  int64_t spacing_us_;
  std::vector<Checkpoint> checkpoints_;
  Checkpoint current_;  ///< the state before the next event
  std::optional<int64_t> first_timestamp_, first_replayed_timestamp_;
  int64_t last_offset_ = -1;  ///< of the last event added
};

}  // namespace kestrel::replay
