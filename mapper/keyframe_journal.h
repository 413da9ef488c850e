#pragma once
// The mapper's journal: an append-only file of the SLAM keyframes the mapper stored and of
// the graphs that moved them, so that a mapper restarted in flight (`kestrel launch
// --restart`) rebuilds the map it had instead of starting from nothing. Once a keyframe's
// frame has left the bus, the mapper's copy is the only one; the journal keeps it on disk.
//
// File: the header "kestrel mapper journal 1\n", then records, each
//   kind (1 byte: 'K' keyframe, 'G' graph) | payload size (u32, little-endian) | payload |
//   CRC-32 of kind, size and payload (u32, little-endian).
// A keyframe's payload is the keyframe as SLAM_GRAPH gave it and the frame the mapper stored
// (decimated; raw colour and zstd depth, so lossless), both LCM-encoded, the first with its
// size (u32) in front. A graph's payload is a SLAM_GRAPH message holding only the stored
// keyframes that graph moved (their new poses; no edges), so the journal grows with what moved,
// not with the whole graph at each loop closure.
// Records are written whole and flushed to the kernel at once, so a process killed at any
// point leaves every earlier record intact.
//
// Reading stops at the first record that is cut short, fails its CRC or does not decode
// (what a kill or a full disk leaves at the end); the records before it are kept, the
// damage is reported, and the writer cuts the file there before appending. A file that does
// not start with the header is not a journal: InputError naming it, and nothing is touched.

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "common/rgbd_frame.h"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/slam_keyframe_t.hpp"
#include "mapper/mapper.h"

namespace kestrel::mapper {

struct JournalRecord {
  enum class Kind { kKeyframe, kGraph };
  Kind kind = Kind::kKeyframe;
  kestrel::slam_keyframe_t keyframe;  ///< kKeyframe
  RgbdFrame frame;                    ///< kKeyframe: as the mapper stored it (decimated)
  kestrel::slam_graph_t graph;        ///< kGraph
};

struct JournalContents {
  std::vector<JournalRecord> records;  ///< in the order written
  uint64_t intact_bytes = 0;           ///< the header and those records
  std::string damage;                  ///< why reading stopped early ("" = it did not)
};

/// What the journal at `path` holds; empty for a missing or empty file. Throws InputError
/// naming `path` if it cannot be read or is not a journal.
JournalContents read_journal(const std::string& path);

/// SLAM_GRAPH's keyframe as the mapper takes it; InputError naming `what` for a broken pose.
GraphKeyframe to_graph_keyframe(const kestrel::slam_keyframe_t& keyframe, const char* what);

struct Restored {
  int64_t keyframes = 0;      ///< keyframe records put into the store
  int64_t last_revision = -1; ///< of the last graph record (-1: none)
};

/// Replays `journal` into `mapper` (Mapper::restore_keyframe, restore_poses: the steps
/// apply_graph took, so the keyframes end at the same poses, bit for bit) and rebuilds its
/// map from them. `what` names the journal in errors.
Restored restore_journal(const JournalContents& journal, Mapper& mapper, const std::string& what);

class JournalWriter {
 public:
  /// Appends to `path` after its first `intact_bytes` (read_journal's figure; whatever follows
  /// is cut off), or starts a new journal when `intact_bytes` is 0. Throws InputError naming
  /// the file if it cannot be written.
  JournalWriter(std::string path, uint64_t intact_bytes);

  void keyframe(const kestrel::slam_keyframe_t& keyframe, const RgbdFrame& frame);
  void graph(const kestrel::slam_graph_t& graph);
  /// Empties the journal (the map was reset).
  void clear();

  const std::string& path() const { return path_; }
  uint64_t bytes() const { return bytes_; }

 private:
  void append(char kind, const std::vector<uint8_t>& payload);

  std::string path_;
  std::ofstream out_;
  uint64_t bytes_ = 0;
};

}  // namespace kestrel::mapper
