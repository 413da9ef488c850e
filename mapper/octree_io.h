#pragma once
// The map as an OctoMap OcTree: for MAP_OCTOMAP messages, .bt / .ot files that octovis and
// every OctoMap user open, and back.
//
// to_octree() builds the tree OctoMap itself would hold after inserting the same scans: the
// same leaf log-odds, inner nodes at the maximum of their children, and fully pruned (OctoMap
// prunes after every update, so its trees are fully pruned too); the tests compare the
// streams byte for byte.
//
// Formats: kBinary is OcTree::writeBinary (.bt): free / occupied per leaf only, small;
// kFull is AbstractOcTree::write (.ot): every log-odds value, exact. Reading a .bt gives
// occupied cells at the clamping maximum and free ones at the minimum (OctoMap's readBinary).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "mapper/voxel_map.h"

namespace kestrel::mapper {

enum class OctreeFormat : int8_t { kBinary = 0, kFull = 1 };

/// The OcTree of `map` (the sensor-model parameters carried over).
std::unique_ptr<octomap::OcTree> to_octree(const VoxelMap& map);
/// A map holding the leaves of `tree`; its resolution is the tree's, the rest of `options`.
/// Throws InputError for a tree that would expand to more than 2^27 cells.
VoxelMap from_octree(const octomap::OcTree& tree, MapOptions options = {});

/// The map as an OctoMap stream in `format`.
std::vector<uint8_t> encode_octree(const VoxelMap& map, OctreeFormat format);
/// The OcTree in an OctoMap stream of `format` (encode_octree's, OctoMap's own, a
/// MAP_OCTOMAP message's). The stream's structure is checked first (octree_stream_check.h:
/// OctoMap's readers recurse without bound on a corrupt one); throws InputError naming `what`
/// when it is not a readable OcTree of that format or its resolution is unusable.
std::unique_ptr<octomap::OcTree> read_octree(const uint8_t* data, size_t size, OctreeFormat format,
                                             const std::string& what);
/// Reads a stream written by encode_octree (or by OctoMap) into a map: read_octree, then
/// from_octree.
VoxelMap decode_octree(const uint8_t* data, size_t size, OctreeFormat format, const char* what,
                       MapOptions options = {});

/// Writes `path`, a .bt (binary) or .ot (full) file by its extension, atomically
/// (common/atomic_file.h); throws InputError if the extension is neither or the file cannot be
/// written.
void write_map_file(const VoxelMap& map, const std::string& path);
/// Reads a .bt or .ot file; throws InputError naming the file if it is missing or not a
/// readable OcTree.
VoxelMap read_map_file(const std::string& path, MapOptions options = {});

/// The format a file name asks for; throws InputError for another extension.
OctreeFormat format_of(const std::string& path);

}  // namespace kestrel::mapper
