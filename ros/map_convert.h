#pragma once
// MAP_OCTOMAP (octomap_t) as ROS messages: sensor_msgs/PointCloud2 of cell centres and a
// visualization_msgs/MarkerArray of voxels, for rviz. The map is read by the mapper's own
// checked reader (mapper/octree_io.h), as the planner reads it.
//
// Invariants:
//  * cells are the map's resolution: a pruned leaf (OctoMap merges eight equal children into
//    their parent) stands for every cell it covers, so a point is the centre of one cell of
//    `resolution`, whatever the tree's pruning;
//  * occupied / free is OctoMap's isNodeOccupied (log-odds above the occupancy threshold);
//  * points are in the map's frame (the world: the mapper inserts keyframes at SLAM's poses),
//    in the tree's leaf order, so the same map gives the same messages;
//  * a map whose cells of one kind would exceed kMaxCells is an InputError naming the map
//    (free space of a large map at a fine resolution: ask for fewer, e.g. without free cells).

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include <ros/time.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include "kestrel/octomap_t.hpp"

namespace kestrel::ros1 {

struct MapCells {
  double resolution_m = 0.0;
  std::vector<Eigen::Vector3f> occupied;  ///< cell centres, metres, world frame
  std::vector<Eigen::Vector3f> free;      ///< only when asked for
};

/// Most cells of one kind a map may give (4 M: 48 MB of points).
inline constexpr size_t kMaxCells = size_t{1} << 22;

/// The centres of the map's occupied cells (and free ones with `with_free`). Throws InputError
/// naming `what` for a message that is not a readable OctoMap stream of its format.
MapCells map_cells(const kestrel::octomap_t& map, bool with_free, const std::string& what);

/// The points as a PointCloud2 of float32 x, y, z (unorganised: height 1, dense).
sensor_msgs::PointCloud2 point_cloud(const std::vector<Eigen::Vector3f>& points, const std::string& frame,
                                     const ros::Time& stamp);

/// The occupied cells as one CUBE_LIST marker (namespace "occupied", id 0) of cubes of the
/// map's resolution, coloured by height for depth in rviz; a map with no occupied cell gives a
/// DELETEALL marker, which clears the cubes of the last map.
visualization_msgs::MarkerArray voxel_markers(const MapCells& cells, const std::string& frame, const ros::Time& stamp);

}  // namespace kestrel::ros1
