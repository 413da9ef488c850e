// The seek index (tools/replay/seek_index.h): a seek that starts from its checkpoint finds what
// a read of the whole log from its start finds, whatever the timestamps' order.

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tools/replay/seek_index.h"

namespace kestrel::replay {
namespace {

struct Event {
  int64_t offset = 0;
  int64_t timestamp = 0;
  std::string channel;
  bool replayed = true;
};

// What a seek to `target` publishes: the last replayed event of each channel before the first
// replayed event at or after it (offsets), and that event (or none: the end).
struct Moment {
  std::map<std::string, int64_t> last_of;
  std::optional<int64_t> next;
  bool operator==(const Moment& o) const { return last_of == o.last_of && next == o.next; }
};
Moment scan(const std::vector<Event>& log, size_t from, std::map<std::string, int64_t> last_of, int64_t target) {
  Moment m{std::move(last_of), std::nullopt};
  for (size_t i = from; i < log.size(); ++i) {
    if (!log[i].replayed) continue;
    if (log[i].timestamp >= target) {
      m.next = log[i].offset;
      break;
    }
    m.last_of[log[i].channel] = log[i].offset;
  }
  return m;
}
Moment seek(const SeekIndex& index, const std::vector<Event>& log, int64_t target) {
  const Checkpoint& c = index.start_for(target);
  size_t from = 0;
  while (from < log.size() && log[from].offset < c.offset) ++from;
  EXPECT_TRUE(from == log.size() || log[from].offset == c.offset) << "a checkpoint at an event's offset";
  return scan(log, from, c.last_offset_of, target);
}
SeekIndex indexed(const std::vector<Event>& log, int64_t spacing_us) {
  SeekIndex index(spacing_us);
  for (const Event& e : log) index.add_event(e.offset, e.timestamp, e.channel, e.replayed);
  return index;
}

TEST(SeekIndex, ACheckpointEverySpacingOfLogTimeNamesEachChannelsLastEvent) {
  // Two channels at 10 Hz, one second apart checkpoints, event i at byte 100 i.
  std::vector<Event> log;
  for (int i = 0; i < 40; ++i) log.push_back({100 * i, 1'000'000 + 100'000 * i, i % 2 ? "B" : "A", true});
  const SeekIndex index = indexed(log, 1'000'000);
  EXPECT_EQ(index.first_timestamp(), 1'000'000);
  // The start, then a checkpoint once the log's time has gone on by a second: before the
  // events after 2.0, 3.0 and 4.0 s (events 11, 21 and 31, at bytes 1100, 2100 and 3100).
  ASSERT_EQ(index.size(), 4u);
  // A seek to 3.55 s starts before event 21: every event before it is older (the latest is
  // 3.0 s), and A's last was event 20, B's event 19.
  const Checkpoint& c = index.start_for(3'550'000);
  EXPECT_EQ(c.offset, 2100);
  EXPECT_EQ(c.latest_timestamp, 3'000'000);
  EXPECT_EQ(c.last_offset_of, (std::map<std::string, int64_t>{{"A", 2000}, {"B", 1900}}));
  // Before the first checkpoint after the start, and exactly at a checkpoint's latest event:
  // the one before it (the read from the start stops at that event).
  EXPECT_EQ(index.start_for(1'500'000).offset, 0);
  EXPECT_EQ(index.start_for(3'000'000).offset, 1100);
  EXPECT_EQ(index.start_for(3'000'001).offset, 2100);
}

TEST(SeekIndex, ASeekFromItsCheckpointFindsWhatAReadFromTheStartFinds) {
  // Logs with out-of-order stamps, jumps back, skipped channels and repeated stamps; every
  // target, against the read from the start.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    std::uniform_int_distribution<int> channel(0, 3), step(-300'000, 700'000), length(0, 60);
    std::bernoulli_distribution replayed(0.8), jump(0.03);
    std::vector<Event> log;
    int64_t t = 5'000'000, offset = 0;
    const int n = length(rng);
    for (int i = 0; i < n; ++i) {
      t += jump(rng) ? -4'000'000 : step(rng);
      log.push_back({offset, t, std::string(1, static_cast<char>('A' + channel(rng))), replayed(rng)});
      offset += 30 + channel(rng) * 7;  // the first event at the file's start, as in an LCM log
    }
    for (const int64_t spacing : {1, 250'000, 1'000'000, 10'000'000}) {
      const SeekIndex index = indexed(log, spacing);
      std::vector<int64_t> targets = {INT64_MIN, INT64_MAX, 0};
      for (const Event& e : log) targets.insert(targets.end(), {e.timestamp - 1, e.timestamp, e.timestamp + 1});
      for (const int64_t target : targets)
        ASSERT_TRUE(seek(index, log, target) == scan(log, 0, {}, target))
            << "trial " << trial << ", spacing " << spacing << " us, target " << target;
    }
  }
}

TEST(SeekIndex, AnEventAddedAgainAndOnesNotReplayedMakeNoCheckpoint) {
  SeekIndex index(1'000'000);
  index.add_event(0, 0, "A", true);
  index.add_event(100, 1'500'000, "A", true);
  index.add_event(200, 2'000'000, "A", true);  // a checkpoint before it: 1.5 s since the first
  ASSERT_EQ(index.size(), 2u);
  // Read again (a seek in a pass that is not the first), then skipped channels far in time.
  index.add_event(100, 9'000'000, "B", true);
  index.add_event(300, 90'000'000, "SKIPPED", false);
  index.add_event(400, 2'100'000, "A", true);
  EXPECT_EQ(index.size(), 2u);
  EXPECT_EQ(index.start_for(2'000'001).offset, 200);
  EXPECT_EQ(index.start_for(2'000'001).last_offset_of, (std::map<std::string, int64_t>{{"A", 100}}));
}

TEST(SeekIndex, AnEmptyLogSeeksToItsStartAndASpacingMustBePositive) {
  const SeekIndex index(1'000'000);
  EXPECT_EQ(index.size(), 1u);
  EXPECT_EQ(index.start_for(123).offset, 0);
  EXPECT_TRUE(index.start_for(123).last_offset_of.empty());
  EXPECT_FALSE(index.first_timestamp().has_value());
  EXPECT_THROW(SeekIndex(0), std::invalid_argument);
  EXPECT_THROW(SeekIndex(-5), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::replay
