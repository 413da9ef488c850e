#pragma once
// The mapper journal's record format (keyframe_journal.h describes the file) and the two reads
// a damaged journal needs: one record at a given offset, checked whole (size within the file,
// CRC, decode), and the next offset at which an intact record starts. Internal to the journal
// (keyframe_journal.cpp); everything else goes through read_journal() and JournalWriter.
//
// Invariants: nothing here writes; a read never allocates more than kMaxPayload for a record,
// and next_record() computes CRCs over at most 4x the file's size, so damaged or hostile files
// cost linear time.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/crc32.h"
#include "mapper/keyframe_journal.h"

namespace kestrel::mapper::journal {

// Version 2 added the pinned-frame and released-pins records; a version 1 journal (no such
// records) reads as before.
constexpr char kHeader[] = "kestrel mapper journal 2\n";
constexpr char kHeaderVersion1[] = "kestrel mapper journal 1\n";
constexpr size_t kHeaderSize = sizeof(kHeader) - 1;
static_assert(sizeof(kHeaderVersion1) == sizeof(kHeader), "the versions' headers are as long");
constexpr char kKeyframe = 'K';
constexpr char kGraph = 'G';
constexpr char kPinned = 'P';
constexpr char kReleased = 'R';
constexpr size_t kRecordHead = 5;  // kind + size
constexpr size_t kRecordTail = 4;  // CRC
// Far above any record (a 640x480 frame stored undecimated is under 2 MB): a larger size
// field is damage, not a record to allocate for.
constexpr uint32_t kMaxPayload = 64u << 20;
constexpr size_t kFingerprint = 8;  // an LCM message starts with its type's hash

using kestrel::crc32;  // common/crc32.h
void put_u32(std::vector<uint8_t>& out, uint32_t v);  ///< little-endian
uint32_t get_u32(const uint8_t* p);                   ///< little-endian

/// A journal file's bytes, read where asked (a damaged journal is read out of order).
class JournalBytes {
 public:
  /// Throws InputError naming `path` if it cannot be opened.
  explicit JournalBytes(const std::string& path);
  ~JournalBytes();
  JournalBytes(const JournalBytes&) = delete;
  JournalBytes& operator=(const JournalBytes&) = delete;

  uint64_t size() const { return size_; }
  /// Exactly `n` bytes at `offset`, or false.
  bool read(uint64_t offset, void* out, size_t n) const;

 private:
  int fd_ = -1;
  uint64_t size_ = 0;
};

/// The record at `at`, appended to `records` if it is whole, passes its CRC and decodes: its
/// end offset. Else 0, and `why` says what is wrong as "record N <why>" reads ("is cut short",
/// "fails its CRC", ...). `what` names the record in decode errors.
uint64_t record_at(const JournalBytes& file, uint64_t at, const std::string& what,
                   std::vector<JournalRecord>& records, std::string& why);

/// Where the first intact record at or after `from` starts, if one does (see the .cpp).
std::optional<uint64_t> next_record(const JournalBytes& file, uint64_t from, const std::string& path);

}  // namespace kestrel::mapper::journal
