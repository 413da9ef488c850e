#include "tools/replay/seek_index.h"

#include <algorithm>
#include <stdexcept>

namespace kestrel::replay {
namespace {
constexpr int64_t kNone = std::numeric_limits<int64_t>::min();
}  // namespace

SeekIndex::SeekIndex(int64_t spacing_us) : spacing_us_(spacing_us) {
  if (!(spacing_us > 0)) throw std::invalid_argument("seek index: the checkpoint spacing must be positive");
  checkpoints_.push_back(current_);
}

void SeekIndex::add_event(int64_t offset, int64_t timestamp, const std::string& channel, bool replayed) {
  if (offset <= last_offset_) return;  // read again
  last_offset_ = offset;
  if (!first_timestamp_) first_timestamp_ = timestamp;
  if (!replayed) return;
  if (!first_replayed_timestamp_) first_replayed_timestamp_ = timestamp;
  // A checkpoint before this event once the replayed events' time has gone on by the spacing
  // since the last one (since the first replayed event, for the first). Unsigned: two stamps
  // may lie further apart than an int64 holds.
  if (current_.latest_timestamp != kNone) {
    const int64_t since = checkpoints_.size() == 1 ? *first_replayed_timestamp_ : checkpoints_.back().latest_timestamp;
    if (static_cast<uint64_t>(current_.latest_timestamp) - static_cast<uint64_t>(since) >=
        static_cast<uint64_t>(spacing_us_)) {
      current_.offset = offset;
      checkpoints_.push_back(current_);
    }
  }
  current_.latest_timestamp = std::max(current_.latest_timestamp, timestamp);
  current_.last_offset_of[channel] = offset;
}

const Checkpoint& SeekIndex::start_for(int64_t target) const {
  // The last checkpoint whose replayed events before are all older than the target: the read
  // from the start would have gone past it.
  const auto after = std::partition_point(checkpoints_.begin(), checkpoints_.end(),
                                          [&](const Checkpoint& c) { return c.latest_timestamp < target; });
  return after == checkpoints_.begin() ? checkpoints_.front() : *std::prev(after);
}

}  // namespace kestrel::replay
