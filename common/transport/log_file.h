#pragma once
// LCM log files (the format of lcm-logger / lcm-logplayer).
//
// LogReader is written here rather than taken from lcm::LogFile so that a damaged log gives a
// precise report instead of silently ending: it checks every event header against the file
// size, resynchronises on the next sync word after corruption, and counts what it skipped.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "common/transport/message.h"

namespace kestrel::transport {

struct LogEvent {
  int64_t offset = 0;  ///< where the event starts in its file (LogReader::seek goes back to it)
  int64_t event_number = 0;
  int64_t timestamp = 0;  ///< microseconds; kestrel writers use the message utime
  std::string channel;
  std::vector<uint8_t> data;
};

class LogReader {
 public:
  /// Opens `path`; throws InputError if it cannot be opened or is not an LCM log.
  explicit LogReader(const std::string& path);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  /// The next intact event, or empty at the end of the file.
  std::optional<LogEvent> next();
  /// Back to the first event (a replay seeking backwards reads the file again).
  void rewind() { seek(0); }
  /// On to the event at `offset` (a LogEvent's offset, or 0): the next next() reads it.
  /// Damage is counted once however often it is read.
  void seek(int64_t offset);

  /// Damage seen so far: bytes skipped to find the next event, and a truncated tail.
  int64_t corrupt_regions() const { return corrupt_regions_; }
  int64_t skipped_bytes() const { return skipped_bytes_; }
  bool truncated() const { return truncated_; }
  /// One line describing the damage ("" if none), naming the file.
  std::string damage_report() const;
  const std::string& path() const { return path_; }

 private:
  bool resync();
  std::string path_;
  std::set<int64_t> damage_counted_;  ///< where the damage read so far starts: counted once
  std::FILE* file_ = nullptr;
  int64_t file_size_ = 0;
  int64_t corrupt_regions_ = 0;
  int64_t skipped_bytes_ = 0;
  bool truncated_ = false;
};

class LogWriter {
 public:
  /// Creates (truncates) `path`; throws InputError if it cannot be written.
  explicit LogWriter(const std::string& path);
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  void write(const std::string& channel, int64_t timestamp, const std::vector<uint8_t>& data);
  template <class Msg>
  void write_message(const std::string& channel, int64_t timestamp, const Msg& msg) {
    write(channel, timestamp, encode_message(msg));
  }
  /// Flushes and closes; throws InputError on a write error (e.g. disk full).
  void close();
  int64_t events_written() const { return next_event_number_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  int64_t next_event_number_ = 0;
};

/// Every message on `channel` in the log at `path`, decoded as Msg, in log order; throws
/// InputError if the log cannot be read or a message does not decode.
template <class Msg>
std::vector<Msg> read_messages(const std::string& path, const std::string& channel) {
  std::vector<Msg> out;
  LogReader log(path);
  while (auto e = log.next())
    if (e->channel == channel) out.push_back(decode_message<Msg>(e->data.data(), e->data.size(), channel));
  return out;
}

}  // namespace kestrel::transport
