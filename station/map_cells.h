#pragma once
// The map as the page draws it: the occupied cells of a MAP_OCTOMAP, each a cube with its
// centre and edge, and the difference between two such maps (what crosses the socket).
//
// Invariants: a CellSet's ids are sorted and unique, `cells[i]` is the cube of `ids[i]`; an id
// is the cell's OctoMap key (x | y << 16 | z << 32) at the map's resolution, so two maps of
// one resolution name a cell alike. diff_cells(a, b) applied to a gives b exactly: it removes
// the cells of a not in b and adds those of b not in a; between resolutions it is a reset
// (everything removed, everything added).

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "kestrel/octomap_t.hpp"
#include "mapper/voxel_map.h"

namespace kestrel::station {

/// One occupied cell, world frame: its centre and its edge, metres (float: what the page uses).
struct Cell {
  float x = 0, y = 0, z = 0;
  float size = 0;
  bool operator==(const Cell& o) const { return x == o.x && y == o.y && z == o.z && size == o.size; }
};

struct CellSet {
  double resolution_m = 0.0;
  int64_t revision = -1;      ///< the MAP_OCTOMAP's
  std::vector<uint64_t> ids;  ///< sorted
  std::vector<Cell> cells;    ///< parallel to ids
  /// The known space (free or occupied cells), world frame; empty before any known cell.
  Eigen::AlignedBox3d known_bounds;

  size_t size() const { return ids.size(); }
  /// Whether the cell holding the world point `p_in_world` is occupied.
  bool occupied_at(const Eigen::Vector3d& p_in_world) const;
  /// Whether an occupied cell's cube is within `radius_m` of `p_in_world`.
  bool occupied_within(const Eigen::Vector3d& p_in_world, double radius_m) const;
};

/// The occupied cells of `map` (those its occupancy() calls occupied) and its known bounds.
CellSet occupied_cells(const mapper::VoxelMap& map, int64_t revision);

/// Decodes a MAP_OCTOMAP with the mapper's checked reader (mapper/octree_io.h); throws
/// InputError naming `channel` for a message the planner would refuse too.
CellSet cells_of_message(const kestrel::octomap_t& msg, const char* channel);

struct CellDiff {
  bool reset = false;  ///< the page drops every cell first (a new resolution or a first map)
  std::vector<Cell> added;
  std::vector<Cell> removed;
  bool empty() const { return !reset && added.empty() && removed.empty(); }
};

/// What turns `before` into `after`. A `before` of another resolution (or none: resolution 0)
/// gives a reset with every cell of `after` added.
CellDiff diff_cells(const CellSet& before, const CellSet& after);

}  // namespace kestrel::station
