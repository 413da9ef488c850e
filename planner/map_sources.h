#pragma once
// Turning maps from elsewhere into the planner's grid: a ROS map_server map (read by the sim
// driver's strict reader, which names the file in every error) and an OctoMap (the mapper's
// MAP_OCTOMAP) projected onto the floor plan over the vehicle's height band.
//
// ROS maps: image row 0 is the map's top, so grid row r is image row (height - 1 - r); the
// YAML's origin (including its yaw) places the grid. OctoMap: a column is occupied if any
// occupied leaf overlaps [z_min, z_max], free if free leaves overlap it and none is occupied,
// unknown otherwise; the grid's cells are the tree's leaves at its resolution.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "planner/grid_environment.h"

namespace octomap {
class OcTree;
}

namespace kestrel::planner {

/// Reads `yaml_path` and its image. Throws InputError naming the file for bad input.
OccupancyGrid read_ros_map(const std::string& yaml_path);

/// Projects the tree's leaves in [z_min, z_max] onto a grid. Throws InputError (naming
/// `source`) for an empty tree.
OccupancyGrid project_octomap(const octomap::OcTree& tree, double z_min, double z_max, const std::string& source);


}  // namespace kestrel::planner
