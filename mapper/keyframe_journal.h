#pragma once
// The mapper's journal: an append-only file of the SLAM keyframes the mapper stored and of
// the graphs that moved them, so that a mapper restarted in flight (`kestrel launch
// --restart`) rebuilds the map it had instead of starting from nothing. Once a keyframe's
// frame has left the bus, the mapper's copy is the only one; the journal keeps it on disk.
//
// File: the header "kestrel mapper journal 2\n" (version 1, without pinned records, still
// reads), then records, each
//   kind (1 byte: 'K' keyframe, 'G' graph, 'P' pinned frame, 'R' released pins) | payload size (u32,
//   little-endian) | payload | CRC-32 of kind, size and payload (u32, little-endian).
// A keyframe's payload is the keyframe as SLAM_GRAPH gave it and the frame the mapper stored
// (decimated; raw colour and zstd depth, so lossless), both LCM-encoded, the first with its
// size (u32) in front. A graph's payload is a SLAM_GRAPH message holding only the stored
// keyframes that graph moved (their new poses; no edges), so the journal grows with what moved,
// not with the whole graph at each loop closure. A pinned frame's payload is a frame the mapper
// keeps for a keyframe SLAM has not placed in its saved map yet (Mapper::pin; LCM-encoded as a
// keyframe's); a released-pins payload is a SLAM_GRAPH message whose keyframes' utimes name the
// pinned frames the mapper let go (joined, or left out of SLAM's list). A mapper restarted
// before the placement pins again the frames pinned and neither released nor taken by a
// keyframe record of the same time after them.
// Records are written whole and flushed to the kernel at once, so a process killed at any
// point leaves every earlier record intact.
//
// A journal on disk is never cut, overwritten or lost (issue 38):
//  * Reading goes past damage. A record cut short, failing its CRC or not decoding (a kill or a
//    full disk at the end; a bad sector, a flipped bit or a zeroed block anywhere) is skipped
//    and reading goes on at the next byte where an intact record starts (known kind, a size
//    that fits, the LCM type's hash at the start of the payload, then its CRC and a decode), so
//    every intact record is kept, before and after the damage. That is sound because records
//    do not depend on the bytes around them: each keyframe record is a whole keyframe, and each
//    graph record only moves stored keyframes; a lost graph record leaves some keyframes at
//    their earlier poses until SLAM's next graph that holds them (each SLAM_GRAPH carries
//    every keyframe's current pose, and Mapper::apply_graph moves them there). Only the
//    keyframes in lost records are lost. A damaged header is damage too when intact records follow it; a file
//    with no intact record and no header is not a journal: InputError naming it, untouched.
//  * A damaged journal is kept whole as "<file>.damaged-<utime>" (keep_aside: a hard link, or a
//    copy), and "<file>" is replaced (atomically) by a valid journal of the records read,
//    copied byte for byte, which the writer then appends to.
//  * A version 1 journal is continued as version 2: replaced (atomically) by the same records,
//    byte for byte, under the new header before anything is appended.
//  * A reset (lock-step replay's RESET) keeps the journal it ends as "<file>.reset-<utime>" and
//    starts "<file>" again empty; a journal without records is simply kept.
//  * Compaction (JournalWriter::compact): the file is replaced, by one rename, with a journal
//    that restores the same store: one record per stored keyframe at its current pose, and a
//    graph record of the last revision, then a record per frame still pinned. The records it drops are of keyframes the store itself
//    has dropped (over its budget) and of poses since superseded, so a mapper restored from
//    either file holds the same keyframes at the same poses, bit for bit; until the rename
//    the old file is whole. So the journal stays within a bound of the store instead of
//    growing with the flight.
//  * The only deletion: so that repeated resets (or damage) cannot fill the disk, each time a
//    journal is set aside the oldest of that kind ("reset" or "damaged") beyond the `keep` most
//    recent are deleted, and each deletion is reported (JournalWriter::pruned()) for the
//    process to log. `keep` is at least 1 and the journal just set aside is always kept: what a
//    reset or the damage has just ended is never the one deleted. Other files are never touched.

#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "common/rgbd_frame.h"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/slam_keyframe_t.hpp"
#include "mapper/mapper.h"

namespace kestrel::mapper {

struct JournalRecord {
  enum class Kind { kKeyframe, kGraph, kPinned, kReleased };
  Kind kind = Kind::kKeyframe;
  kestrel::slam_keyframe_t keyframe;  ///< kKeyframe
  RgbdFrame frame;                    ///< kKeyframe: as the mapper stored it; kPinned: as it pinned it (decimated)
  kestrel::slam_graph_t graph;        ///< kGraph; kReleased: the released frames' utimes (keyframes' utime)
};

struct JournalContents {
  std::vector<JournalRecord> records;  ///< every intact record, in the order written
  /// Where those records lie in the file: [begin, end) byte offsets, adjacent ones merged.
  std::vector<std::pair<uint64_t, uint64_t>> spans;
  uint64_t intact_bytes = 0;   ///< the header (if intact) and those records
  uint64_t file_bytes = 0;     ///< the file's size when read (0: missing or empty)
  uint64_t skipped_bytes = 0;  ///< in damaged stretches
  int damaged_stretches = 0;
  std::string damage;          ///< the first damage and a summary ("" = the file is whole)
  int version = 0;             ///< of the header: 1 or 2 (0: no intact header)
};

/// What the journal at `path` holds; empty for a missing or empty file. Throws InputError
/// naming `path` if it cannot be read or is not a journal (no header, no intact record).
JournalContents read_journal(const std::string& path);

/// SLAM_GRAPH's keyframe as the mapper takes it; InputError naming `what` for a broken pose.
GraphKeyframe to_graph_keyframe(const kestrel::slam_keyframe_t& keyframe, const char* what);

struct Restored {
  int64_t keyframes = 0;      ///< keyframe records put into the store
  int64_t pinned = 0;         ///< frames pinned again (their keyframes had not joined)
  int64_t last_revision = -1; ///< of the last graph record (-1: none)
};

/// Replays `journal` into `mapper` (Mapper::restore_keyframe, restore_poses: the steps
/// apply_graph took, so the keyframes end at the same poses, bit for bit) and rebuilds its
/// map from them; pins again the pinned frames no later keyframe record took
/// (Mapper::restore_pinned). `what` names the journal in errors.
Restored restore_journal(const JournalContents& journal, Mapper& mapper, const std::string& what);

/// How many journals set aside of each kind a writer keeps unless told otherwise.
constexpr int kDefaultKeptJournals = 5;

/// The journals kept aside for `path` under `tag` ("reset", "damaged"): the regular files
/// beside it named as keep_aside() names them, "<path>.<tag>-<utime>" or "...-<utime>-<n>",
/// oldest first (by the time and number in the name, which say when each was set aside).
/// Throws InputError naming the folder if it cannot be listed.
std::vector<std::string> kept_journals(const std::string& path, const std::string& tag);

/// What pruning the journals kept aside did.
struct PrunedJournals {
  std::vector<std::string> removed;   ///< deleted, oldest first
  std::vector<std::string> failures;  ///< "<file or folder>: why" for what could not be deleted (it stays)
};

/// Deletes the oldest of kept_journals(path, tag) beyond the `keep` most recent, never
/// `just_kept` (the one set aside just now, kept whatever its name says: the wall clock can
/// step back). `keep` < 1 is std::invalid_argument: pruning never empties the set.
PrunedJournals prune_kept_journals(const std::string& path, const std::string& tag, int keep,
                                   const std::string& just_kept);

/// A stored keyframe, for compaction: its id and its stored frame.
struct LiveKeyframe {
  int64_t id = 0;
  const RgbdFrame* frame = nullptr;
};

class JournalWriter {
 public:
  /// Journals to `path`, whose read_journal() is `contents` (default: a missing or empty file,
  /// where a new journal starts): a whole journal is appended to; a damaged one is kept aside
  /// and replaced by a fresh journal of `contents`' records (see the top of this file). Throws
  /// InputError naming the file if it cannot be written, or if it is no longer what was read
  /// (its size differs), so a journal is never written over unread. Of the journals set aside
  /// `keep` of each kind are kept (see the top of this file); `keep` < 1 is
  /// std::invalid_argument.
  explicit JournalWriter(std::string path, const JournalContents& contents = {},
                         int keep = kDefaultKeptJournals);

  void keyframe(const kestrel::slam_keyframe_t& keyframe, const RgbdFrame& frame);
  void graph(const kestrel::slam_graph_t& graph);
  /// A frame the mapper pinned (Mapper::pin), as it keeps it.
  void pinned(const RgbdFrame& frame);
  /// The pinned frames at `utimes` were let go.
  void released(const std::vector<int64_t>& utimes);
  /// The map was reset: `path` starts again as an empty journal, the one it ends kept as
  /// "<path>.reset-<utime>" (if it holds a record). Throws InputError (nothing changed) if the
  /// old one cannot be kept.
  void restart();
  /// Replaces the journal by one of `keyframes` (in that order), each as its last record in
  /// this journal placed it (its keyframe record, or the last graph record that moved it: the
  /// pose exactly as SLAM sent it, so a restore is bit for bit), and, when `graph_revision`
  /// >= 0, a graph record of that revision that moves nothing (a restored mapper then still
  /// refuses older graphs), then the frames still `pinned`; see the top of this file. Atomic:
  /// on any failure (InputError naming the file; std::invalid_argument for a keyframe this
  /// journal never held) the old journal is still whole and still appended to.
  void compact(const std::vector<LiveKeyframe>& keyframes, int64_t graph_revision,
               const std::vector<const RgbdFrame*>& pinned = {});
  /// How many times compact() replaced the journal.
  int compactions() const { return compactions_; }

  const std::string& path() const { return path_; }
  uint64_t bytes() const { return bytes_; }
  /// Where the journal set aside by the constructor (damaged) or the last restart() is kept
  /// ("" = that one kept nothing).
  const std::string& kept_aside() const { return kept_aside_; }
  /// The older journals of the same kind that setting that one aside deleted (or could not).
  const PrunedJournals& pruned() const { return pruned_; }

 private:
  // `path_` replaced atomically by the header and `spans` of the file `source`.
  void start_fresh(const std::string& source, const std::vector<std::pair<uint64_t, uint64_t>>& spans);
  void open_for_append();
  void append(char kind, const std::vector<uint8_t>& payload);
  // Writes one record (kind, size, payload, CRC) to `out`; returns the bytes written. The one
  // place a record's layout is written, for appends and for compaction alike.
  static uint64_t write_record(std::ostream& out, char kind, const std::vector<uint8_t>& payload);
  static std::vector<uint8_t> keyframe_payload(const kestrel::slam_keyframe_t& keyframe, const RgbdFrame& frame);
  static std::vector<uint8_t> frame_payload(const RgbdFrame& frame);

  std::string path_;
  int keep_;
  // in-place: the journal, appended record by record (compaction is atomic)
  std::ofstream out_;
  uint64_t bytes_ = 0;
  std::string kept_aside_;
  PrunedJournals pruned_;
  int compactions_ = 0;
  // Each keyframe's last entry in the journal (its keyframe record's, or the last graph
  // record's that moved it): what compact() writes for it.
  std::map<int64_t, kestrel::slam_keyframe_t> placed_;
  void place(const kestrel::slam_keyframe_t& keyframe) { placed_[keyframe.id] = keyframe; }
};

}  // namespace kestrel::mapper
