#include "mapper/journal_records.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

#include "common/crc32.h"
#include "common/error.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"

namespace kestrel::mapper::journal {

void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

uint32_t get_u32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}

JournalBytes::JournalBytes(const std::string& path) : fd_(::open(path.c_str(), O_RDONLY | O_CLOEXEC)) {
  if (fd_ < 0) throw InputError(path + ": cannot read the mapper journal: " + std::strerror(errno));
  const off_t end = ::lseek(fd_, 0, SEEK_END);
  if (end < 0) {
    const int error = errno;
    ::close(fd_);
    throw InputError(path + ": cannot read the mapper journal: " + std::strerror(error));
  }
  size_ = static_cast<uint64_t>(end);
}

JournalBytes::~JournalBytes() { ::close(fd_); }

bool JournalBytes::read(uint64_t offset, void* out, size_t n) const {
  auto* p = static_cast<char*>(out);
  while (n > 0) {
    const ssize_t got = ::pread(fd_, p, n, static_cast<off_t>(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    p += got;
    offset += static_cast<uint64_t>(got);
    n -= static_cast<size_t>(got);
  }
  return true;
}

namespace {

JournalRecord decode_record(char kind, const std::vector<uint8_t>& payload, const std::string& what) {
  JournalRecord r;
  if (kind == kGraph || kind == kReleased) {
    r.kind = kind == kGraph ? JournalRecord::Kind::kGraph : JournalRecord::Kind::kReleased;
    r.graph = transport::decode_message<kestrel::slam_graph_t>(payload.data(), payload.size(), what);
    return r;
  }
  if (kind == kPinned) {
    r.kind = JournalRecord::Kind::kPinned;
    const auto frame = transport::decode_message<kestrel::rgbd_frame_t>(payload.data(), payload.size(), what);
    r.frame = transport::decode_rgbd(frame, what.c_str());
    return r;
  }
  if (kind != kKeyframe) throw InputError(what + ": unknown record kind " + std::to_string(kind));
  if (payload.size() < 4) throw InputError(what + ": keyframe record too short");
  const uint32_t size = get_u32(payload.data());
  if (size > payload.size() - 4) throw InputError(what + ": keyframe size beyond the record");
  r.kind = JournalRecord::Kind::kKeyframe;
  r.keyframe = transport::decode_message<kestrel::slam_keyframe_t>(payload.data() + 4, size, what);
  const auto frame = transport::decode_message<kestrel::rgbd_frame_t>(payload.data() + 4 + size,
                                                                      payload.size() - 4 - size, what);
  r.frame = transport::decode_rgbd(frame, what.c_str());
  return r;
}

}  // namespace

uint64_t record_at(const JournalBytes& file, uint64_t at, const std::string& what,
                   std::vector<JournalRecord>& records, std::string& why) {
  uint8_t head[kRecordHead];
  if (!file.read(at, head, kRecordHead)) {
    why = "is cut short";
    return 0;
  }
  const uint32_t size = get_u32(head + 1);
  if (size > kMaxPayload) {
    why = "claims " + std::to_string(size) + " bytes";
    return 0;
  }
  const uint64_t end = at + kRecordHead + size + kRecordTail;
  if (end > file.size()) {
    why = "is cut short";
    return 0;
  }
  std::vector<uint8_t> payload(size);
  uint8_t crc_bytes[kRecordTail];
  if (!file.read(at + kRecordHead, payload.data(), size) ||
      !file.read(at + kRecordHead + size, crc_bytes, kRecordTail)) {
    why = "cannot be read";
    return 0;
  }
  if (crc32(payload.data(), size, crc32(head, kRecordHead)) != get_u32(crc_bytes)) {
    why = "fails its CRC";
    return 0;
  }
  try {
    records.push_back(decode_record(static_cast<char>(head[0]), payload, what));
  } catch (const InputError& e) {
    why = std::string("does not decode: ") + e.what();
    return 0;
  }
  return end;
}

// Where the first intact record at or after `from` starts, if one does. A candidate must have a
// known kind, a size that fits the file and, at the start of its payload, the hash of the LCM
// type that kind holds, before its CRC is computed; and the CRC must then match (a chance of
// 2^-32 for random bytes) and the record decode. The bytes CRC'd are capped, so a file crafted
// to be all candidates takes linear time, not quadratic.
std::optional<uint64_t> next_record(const JournalBytes& file, uint64_t from, const std::string& path) {
  static const std::vector<uint8_t> graph_hash = [] {
    const std::vector<uint8_t> m = transport::encode_message(kestrel::slam_graph_t{});
    return std::vector<uint8_t>(m.begin(), m.begin() + kFingerprint);
  }();
  static const std::vector<uint8_t> keyframe_hash = [] {
    const std::vector<uint8_t> m = transport::encode_message(kestrel::slam_keyframe_t{});
    return std::vector<uint8_t>(m.begin(), m.begin() + kFingerprint);
  }();
  static const std::vector<uint8_t> frame_hash = [] {
    const std::vector<uint8_t> m = transport::encode_message(kestrel::rgbd_frame_t{});
    return std::vector<uint8_t>(m.begin(), m.begin() + kFingerprint);
  }();
  // Windows overlap by what a candidate needs to be looked at: its head and the fingerprint
  // (after a keyframe's u32).
  constexpr size_t kLook = kRecordHead + 4 + kFingerprint;
  constexpr size_t kWindow = 1u << 20;
  uint64_t crc_budget = 4 * file.size() + kMaxPayload;
  std::vector<uint8_t> window(kWindow + kLook);
  std::vector<JournalRecord> scratch;
  for (uint64_t base = from; base < file.size(); base += kWindow) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(window.size(), file.size() - base));
    if (!file.read(base, window.data(), n)) return std::nullopt;
    for (size_t i = 0; i < std::min(n, kWindow); ++i) {
      const uint8_t* p = window.data() + i;
      const size_t left = n - i;
      if (left < kRecordHead + kFingerprint + kRecordTail) break;  // no record is smaller
      if (p[0] != kKeyframe && p[0] != kGraph && p[0] != kPinned && p[0] != kReleased) continue;
      const uint32_t size = get_u32(p + 1);
      if (size > kMaxPayload || base + i + kRecordHead + size + kRecordTail > file.size()) continue;
      const bool keyframe = p[0] == kKeyframe;  // the only kind with a u32 before its message
      const size_t hash_at = kRecordHead + (keyframe ? 4 : 0);
      if (size < hash_at - kRecordHead + kFingerprint || left < hash_at + kFingerprint) continue;
      const std::vector<uint8_t>& hash = keyframe ? keyframe_hash : p[0] == kPinned ? frame_hash : graph_hash;
      if (!std::equal(hash.begin(), hash.end(), p + hash_at)) continue;
      if (size > crc_budget) return std::nullopt;
      crc_budget -= size;
      std::string why;
      const uint64_t at = base + i;
      scratch.clear();
      if (record_at(file, at, path + ": record at byte " + std::to_string(at), scratch, why) != 0) return at;
    }
  }
  return std::nullopt;
}

}  // namespace kestrel::mapper::journal
