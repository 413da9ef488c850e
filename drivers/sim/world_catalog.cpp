#include "drivers/sim/world_catalog.h"

#include <utility>

#include "common/error.h"
#include "drivers/sim/map_world.h"
#include "drivers/sim/world_file.h"

namespace kestrel::sim {

// Defined in the generated builtin_worlds.cpp.
const std::vector<std::pair<std::string, std::string>>& builtin_world_table();

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

std::vector<std::string> builtin_world_names() {
  std::vector<std::string> names;
  for (const auto& [name, text] : builtin_world_table()) names.push_back(name);
  return names;
}

std::optional<std::string> builtin_world_text(const std::string& name) {
  for (const auto& [n, text] : builtin_world_table())
    if (n == name) return text;
  return std::nullopt;
}

std::string unknown_world_error(const std::string& what, bool with_stata) {
  if (builtin_world_text(what) || (with_stata && what == "stata")) return {};
  if (ends_with(what, ".world") || ends_with(what, ".yaml") || ends_with(what, ".yml")) return {};
  std::string known;
  for (const auto& n : builtin_world_names()) known += (known.empty() ? "" : ", ") + n;
  if (with_stata) known += ", stata";
  return "unknown world '" + what + "' (built in: " + known + "; or a .world file or an occupancy map .yaml)";
}

std::string world_choice_error(const std::string& world, const std::string& map_yaml) {
  if (world == "stata" && map_yaml.empty()) return "world 'stata' needs an occupancy map (--map FILE.yaml)";
  return unknown_world_error(world);
}

World load_world(const std::string& what, const std::string& map_yaml, uint64_t map_seed) {
  if (const auto text = builtin_world_text(what)) return parse_world(*text, "drivers/sim/worlds/" + what + ".world");
  MapWorldOptions options;
  options.seed = map_seed;
  if (what == "stata") {
    if (map_yaml.empty()) throw InputError("world 'stata' needs an occupancy map (--map FILE.yaml)");
    return world_from_map(read_occupancy_map(map_yaml), "stata", options);
  }
  if (ends_with(what, ".yaml") || ends_with(what, ".yml")) return world_from_map(read_occupancy_map(what), what, options);
  if (ends_with(what, ".world")) return load_world_file(what);
  throw InputError(unknown_world_error(what));
}

}  // namespace kestrel::sim
