#pragma once
// The world file format (documented in drivers/sim/README.md): one statement per line,
// '#' comments, metres and degrees. Parsing is strict: anything unexpected is an InputError
// naming the source and line ("room.world:12: ...").
//
// Every coordinate and length is within +-kMaxWorldCoordinate_m, checked as it is read: the
// world's collision index has a cell per square metre of its extent, so a wall to x = 1e12
// would otherwise ask for more memory than any machine has.

#include <string>

#include "drivers/sim/world.h"

namespace kestrel::sim {

/// A world spans at most 1 km along each axis (a collision index of a million cells).
inline constexpr double kMaxWorldCoordinate_m = 500.0;

/// Parses world text; `source` names it in errors and becomes World::source(). `parts`:
/// what to build of it (world.h).
World parse_world(const std::string& text, const std::string& source, WorldParts parts = WorldParts::kAll);

/// Reads and parses a world file; a missing file is an InputError naming it.
World load_world_file(const std::string& path);

}  // namespace kestrel::sim
