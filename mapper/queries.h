#pragma once
// The questions the planner asks of the map: may a sphere of radius r travel along a segment
// without touching a blocked cell, and how far is a point from the nearest occupied cell.
//
// Cells are treated as the exact cubes they are (not their centres): a cell blocks a sphere
// when the Euclidean distance from the segment to the cube is at most r. A cell is blocked
// when it is occupied, and also when it is unknown unless `unknown_is_free` (the planner's
// safe default is to treat the unexplored as an obstacle). Queries only read the map.

#include <Eigen/Core>
#include <limits>

#include "mapper/voxel_map.h"

namespace kestrel::mapper {

struct QueryOptions {
  bool unknown_is_free = false;  ///< false: unknown cells block like occupied ones
};

class MapQueries {
 public:
  MapQueries(const VoxelMap& map, const QueryOptions& options = {});

  /// True if no blocked cell lies within `radius_m` of the segment [a, b] (a point if a == b).
  /// Points outside the map's key range are blocked. radius_m >= 0.
  bool segment_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius_m) const;
  bool sphere_free(const Eigen::Vector3d& centre, double radius_m) const {
    return segment_free(centre, centre, radius_m);
  }

  /// Distance from `p` to the nearest occupied cell's cube (0 inside one), searched up to
  /// `max_distance_m`; +infinity when there is none that close. Unknown cells do not count.
  double distance_to_occupied(const Eigen::Vector3d& p, double max_distance_m) const;

 private:
  bool blocked(const Key& key) const;
  /// Distance from the segment to the cube of `key` (exact up to 1e-9 m).
  double segment_to_cell(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Key& key) const;
  double point_to_cell(const Eigen::Vector3d& p, const Key& key) const;

  const VoxelMap& map_;
  QueryOptions options_;
};

}  // namespace kestrel::mapper
