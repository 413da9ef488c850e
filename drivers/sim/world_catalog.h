#pragma once
// Finding a world by name: the worlds shipped in drivers/sim/worlds/ (embedded in the library
// at build time, so the tools work wherever they are installed), `stata` (extruded from a ROS
// occupancy map given by path), a world file, or any occupancy map YAML.

#include <optional>
#include <string>
#include <vector>

#include "drivers/sim/world.h"

namespace kestrel::sim {

/// Names of the embedded worlds (room, floor, office).
std::vector<std::string> builtin_world_names();
/// Text of an embedded world, or empty if there is none of that name.
std::optional<std::string> builtin_world_text(const std::string& name);

/// Empty when `what` has the form of a world load_world() takes: an embedded world's name,
/// "stata" (when `with_stata`: the tool takes the map it is built from), or a path ending in
/// .world, .yaml or .yml (whether that file is there and sound is input, for load_world() to
/// say). Otherwise the message for a world there is not, naming `what` and the worlds there
/// are. Which world is a question of the command line (the tools exit 2 on it), what a file
/// holds a question of input (exit 3).
std::string unknown_world_error(const std::string& what, bool with_stata = true);

/// Empty when (`world`, `map_yaml`) names a world load_world() can try: unknown_world_error()
/// and "stata" without its map. The check a tool with --world and --map makes of its command
/// line before it reads any input.
std::string world_choice_error(const std::string& world, const std::string& map_yaml);

/// `what` is an embedded world's name, "stata" (built from `map_yaml`), a path to a world file
/// (*.world) or a path to an occupancy map (*.yaml). `map_seed` sets the appearance of worlds
/// built from maps. Throws InputError for an unknown name or bad file (naming it).
World load_world(const std::string& what, const std::string& map_yaml = "", uint64_t map_seed = 1);

}  // namespace kestrel::sim
