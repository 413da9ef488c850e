#pragma once
// The worlds of the paper's planning experiments, loaded through the simulator's world
// library (drivers/sim): the shipped `floor` world (13 x 23 m, the size of the paper's Stata
// ground floor, as rooms and corridors), the shipped `atrium` (the same size, open, as the
// paper describes its floor) and `stata`, extruded from the real Stata basement map when it is present.
// Each comes with its five start/goal pairs (>= 8.53 m apart, as in the paper), checked to be
// free for the vehicle when the world is loaded.

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "drivers/sim/world.h"
#include "planner/types.h"
#include "planner/world_environment.h"

namespace kestrel::planner {

struct ExperimentWorld {
  std::string name;
  std::unique_ptr<sim::World> world;
  std::unique_ptr<WorldEnvironment> env;  ///< features placed
  std::vector<std::pair<Config, Config>> pairs;
};

/// Any sim world with its features placed and these start/goal pairs. Throws
/// std::runtime_error if a pair is not free for `radius_m`.
ExperimentWorld make_experiment_world(const std::string& name, sim::World world, const WorldFeatureOptions& features,
                                      std::vector<std::pair<Config, Config>> pairs, double radius_m);

/// The shipped `floor` world. Throws std::runtime_error if a pair is not free for `radius_m`.
ExperimentWorld floor_experiment_world(const WorldFeatureOptions& features, double radius_m);

/// The shipped `atrium` world (13 x 23 m, the paper's open kind of floor). Throws
/// std::runtime_error if a pair is not free for `radius_m`.
ExperimentWorld atrium_experiment_world(const WorldFeatureOptions& features, double radius_m);

/// `stata` from `map_yaml`, or nullopt when that file does not exist. Bad map files throw
/// InputError naming the file.
std::optional<ExperimentWorld> stata_experiment_world(const std::string& map_yaml,
                                                      const WorldFeatureOptions& features, double radius_m);

}  // namespace kestrel::planner
