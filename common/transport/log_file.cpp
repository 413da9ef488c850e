#include "common/transport/log_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "common/error.h"

namespace kestrel::transport {
namespace {

constexpr uint32_t kSync = 0xEDA1DA01u;
constexpr int kHeaderSize = 4 + 8 + 8 + 4 + 4;
// LCM itself limits channel names to 63 characters; anything longer is corruption.
constexpr uint32_t kMaxChannelLength = 255;

uint32_t get_u32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}
int64_t get_i64(const uint8_t* p) {
  return static_cast<int64_t>((uint64_t{get_u32(p)} << 32) | get_u32(p + 4));
}
void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (24 - 8 * i));
}
void put_i64(uint8_t* p, int64_t v) {
  put_u32(p, static_cast<uint32_t>(static_cast<uint64_t>(v) >> 32));
  put_u32(p + 4, static_cast<uint32_t>(v));
}

}  // namespace

LogReader::LogReader(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw InputError(path + ": cannot open LCM log: " + std::strerror(errno));
  std::fseek(file_, 0, SEEK_END);
  file_size_ = std::ftell(file_);
  std::fseek(file_, 0, SEEK_SET);
  if (file_size_ > 0) {
    uint8_t head[4];
    if (file_size_ < 4 || std::fread(head, 1, 4, file_) != 4 || get_u32(head) != kSync) {
      std::fclose(file_);
      file_ = nullptr;
      throw InputError(path + ": not an LCM log (no event header at its start)");
    }
    std::fseek(file_, 0, SEEK_SET);
  }
}

void LogReader::seek(int64_t offset) {
  if (offset < 0 || offset > file_size_) throw std::out_of_range(path_ + ": no event at byte " + std::to_string(offset));
  std::fseek(file_, offset, SEEK_SET);
}

LogReader::~LogReader() {
  if (file_) std::fclose(file_);
}

bool LogReader::resync() {
  // Scan byte by byte for the next sync word; the caller already consumed the bad one.
  const int64_t start = std::ftell(file_);
  uint32_t window = 0;
  int have = 0;
  int c;
  while ((c = std::fgetc(file_)) != EOF) {
    window = (window << 8) | static_cast<uint32_t>(c);
    if (++have >= 4 && window == kSync) {
      std::fseek(file_, -4, SEEK_CUR);
      skipped_bytes_ += std::ftell(file_) - start;
      return true;
    }
  }
  skipped_bytes_ += file_size_ - start;
  return false;
}

std::optional<LogEvent> LogReader::next() {
  while (file_) {
    const int64_t offset = std::ftell(file_);
    if (offset >= file_size_) return std::nullopt;
    uint8_t header[kHeaderSize];
    const size_t got = std::fread(header, 1, kHeaderSize, file_);
    auto damaged = [&](bool is_truncation) {
      // Read before (a rewind, a seek back): counted then.
      const bool counted = !damage_counted_.insert(offset).second;
      const int64_t skipped_before = skipped_bytes_;
      if (is_truncation) {
        if (!counted) {
          truncated_ = true;
          skipped_bytes_ += file_size_ - offset;
        }
        std::fseek(file_, 0, SEEK_END);
      } else {
        if (!counted) ++corrupt_regions_;
        std::fseek(file_, offset + 1, SEEK_SET);
        skipped_bytes_ += 1;  // the byte at `offset` that started the bad event
        resync();
        if (counted) skipped_bytes_ = skipped_before;
      }
    };
    if (got < 4) {
      damaged(true);
      return std::nullopt;
    }
    if (get_u32(header) != kSync) {
      damaged(false);
      continue;
    }
    if (got < static_cast<size_t>(kHeaderSize)) {
      damaged(true);
      return std::nullopt;
    }
    LogEvent event;
    event.offset = offset;
    event.event_number = get_i64(header + 4);
    event.timestamp = get_i64(header + 12);
    const uint32_t channel_length = get_u32(header + 20);
    const uint32_t data_length = get_u32(header + 24);
    const int64_t end = offset + kHeaderSize + int64_t{channel_length} + int64_t{data_length};
    if (channel_length == 0 || channel_length > kMaxChannelLength) {
      damaged(false);
      continue;
    }
    if (end > file_size_) {
      // Either the last event was cut off, or a corrupt length field: tell them apart by
      // looking for a later sync word.
      std::fseek(file_, offset + 1, SEEK_SET);
      const int64_t skipped_before = skipped_bytes_;
      if (resync()) {
        skipped_bytes_ = skipped_before;
        std::fseek(file_, offset, SEEK_SET);
        damaged(false);
        continue;
      }
      skipped_bytes_ = skipped_before;
      std::fseek(file_, offset, SEEK_SET);
      damaged(true);
      return std::nullopt;
    }
    event.channel.resize(channel_length);
    event.data.resize(data_length);
    if (std::fread(event.channel.data(), 1, channel_length, file_) != channel_length ||
        std::fread(event.data.data(), 1, data_length, file_) != data_length) {
      std::fseek(file_, offset, SEEK_SET);
      damaged(true);
      return std::nullopt;
    }
    return event;
  }
  return std::nullopt;
}

std::string LogReader::damage_report() const {
  if (corrupt_regions_ == 0 && !truncated_) return {};
  std::string s = path_ + ": damaged LCM log: ";
  if (corrupt_regions_ > 0)
    s += std::to_string(corrupt_regions_) + " corrupt region(s), ";
  if (truncated_) s += "truncated last event, ";
  s += std::to_string(skipped_bytes_) + " bytes skipped (first at byte " +
       std::to_string(*damage_counted_.begin()) + ")";
  return s;
}

LogWriter::LogWriter(const std::string& path) : path_(path) {
  // in-place: an LCM log, appended event by event as it is recorded; readers stop at a cut event
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw InputError(path + ": cannot write LCM log: " + std::strerror(errno));
}

LogWriter::~LogWriter() {
  if (file_) std::fclose(file_);
}

void LogWriter::write(const std::string& channel, int64_t timestamp,
                      const std::vector<uint8_t>& data) {
  if (!file_) throw std::logic_error("LogWriter::write after close");
  uint8_t header[kHeaderSize];
  put_u32(header, kSync);
  put_i64(header + 4, next_event_number_);
  put_i64(header + 12, timestamp);
  put_u32(header + 20, static_cast<uint32_t>(channel.size()));
  put_u32(header + 24, static_cast<uint32_t>(data.size()));
  if (std::fwrite(header, 1, kHeaderSize, file_) != kHeaderSize ||
      std::fwrite(channel.data(), 1, channel.size(), file_) != channel.size() ||
      std::fwrite(data.data(), 1, data.size(), file_) != data.size()) {
    throw InputError(path_ + ": write failed: " + std::strerror(errno));
  }
  ++next_event_number_;
}

void LogWriter::close() {
  if (!file_) return;
  const bool ok = std::fflush(file_) == 0;
  const int err = errno;
  std::fclose(file_);
  file_ = nullptr;
  if (!ok) throw InputError(path_ + ": write failed: " + std::strerror(err));
}

}  // namespace kestrel::transport
