#pragma once
// A SLAM map on disk (slam_map.h): `kestrel-slam --save-map DIR` writes DIR/slam.map, `--map
// DIR` reads it. One binary file, versioned and checksummed:
//
//   "KESTREL-SLAM-MAP" (16 bytes), format version (u32), then sections, each
//   tag (4 bytes) | payload size (u64) | payload | CRC-32 of tag, size and payload (u32):
//     HEAD  text, "key: value" lines: what made the map, when, its counts (for people; it
//           is returned as read, nothing in it is relied on)
//     VOCB  the vocabulary (slam/place/vocabulary.h's format; empty: none trained)
//     KEYF  the keyframes: poses, session, link, sensor, camera, features
//     GRPH  the pose graph's vertices and edges, the loop gate's model per edge, the revision
//     END.  nothing: the file is whole
// Numbers are little-endian (the reader refuses a big-endian host rather than misread).
//
// Errors: a missing file, another format, a newer version, a cut or damaged file (a CRC that
// fails), impossible sizes or values, or a map that breaks slam_map.h's invariants throw
// InputError naming the file and what is wrong (the tools exit 3). Every count is checked
// against the bytes left before anything is sized (a keyframe in memory is about 3x its bytes). The writer goes through AtomicFile: an existing map is never
// left half-replaced.

#include <string>

#include "slam/backend/slam_map.h"

namespace kestrel::slam {

constexpr unsigned kMapFormatVersion = 1;

/// The file of the map in folder `dir`.
std::string map_file_in(const std::string& dir);

/// What the HEAD section says besides the counts.
struct MapProvenance {
  std::string made_by;  ///< e.g. "kestrel-slam --tum rgbd_dataset_freiburg1_xyz"
  std::string created;  ///< e.g. an ISO 8601 UTC time; the library takes no clock
};

/// Writes `map` (checked first) to map_file_in(dir), creating `dir` if needed. Throws
/// InputError naming the folder when it cannot be written.
void write_map(const std::string& dir, const SlamMap& map, const MapProvenance& provenance);

/// Reads the map in folder `dir`; what its HEAD says in `head` when given.
SlamMap read_map(const std::string& dir, std::string* head = nullptr);

}  // namespace kestrel::slam
