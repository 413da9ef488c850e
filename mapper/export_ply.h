#pragma once
// The registered frames as one coloured point cloud (binary little-endian PLY: float x, y, z
// in the world frame, uchar red, green, blue), which MeshLab, CloudCompare and Open3D open.
// Points come from the stored keyframes at their current poses, so after a loop closure the
// cloud is as consistent as the map. Frames without colour give grey points.

#include <string>

#include "mapper/keyframe_store.h"

namespace kestrel::mapper {

/// Writes every depth pixel of every stored keyframe (no reading beyond `max_range_m`); returns
/// the number of points. Atomic (common/atomic_file.h); throws InputError naming `path` if it
/// cannot be written.
size_t write_ply(const KeyframeStore& keyframes, const std::string& path, double max_range_m);

}  // namespace kestrel::mapper
