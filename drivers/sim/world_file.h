#pragma once
// The world file format (documented in drivers/sim/README.md): one statement per line,
// '#' comments, metres and degrees. Parsing is strict: anything unexpected is an InputError
// naming the source and line ("room.world:12: ...").

#include <string>

#include "drivers/sim/world.h"

namespace kestrel::sim {

/// Parses world text; `source` names it in errors and becomes World::source().
World parse_world(const std::string& text, const std::string& source);

/// Reads and parses a world file; a missing file is an InputError naming it.
World load_world_file(const std::string& path);

}  // namespace kestrel::sim
