#pragma once
// A 2D occupancy grid extruded in height: the planner's environment for ROS maps and for
// OctoMaps projected onto the floor plan.
//
// Cell (col, row) has its centre at T_world_grid * (col, row) (metres, rows along the grid's
// +y); a cell is free, occupied or unknown, and only free cells are flyable. Walls are full
// height: the vehicle's centre must stay within [z_min + r, z_max - r]. Clearance is the
// distance from a cell centre to the nearest non-free cell centre less half a cell, so
// collision checks are conservative by at most half a cell. Immutable after construction.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "planner/environment.h"
#include "planner/types.h"

namespace kestrel::planner {

struct OccupancyGrid {
  enum Cell : uint8_t { kFree = 0, kOccupied = 1, kUnknown = 2 };
  int width = 0;   ///< columns
  int height = 0;  ///< rows
  double resolution = 0.05;  ///< metres per cell
  Eigen::Affine2d T_world_grid = Eigen::Affine2d::Identity();  ///< (col, row) -> (x, y), includes the scale
  std::vector<uint8_t> cells;  ///< row-major, width * height
  uint8_t at(int col, int row) const { return cells[static_cast<size_t>(row) * width + col]; }
};

/// A grid of `width` x `height` cells of `resolution` m with its lower-left cell centre at
/// (x0, y0); all cells free.
OccupancyGrid make_grid(int width, int height, double resolution, double x0, double y0);

/// Fills the cells whose centres lie in the axis-aligned rectangle [x0, x1] x [y0, y1].
void fill_rect(OccupancyGrid& grid, double x0, double y0, double x1, double y1, uint8_t value);

class GridEnvironment : public Environment {
 public:
  /// Throws std::invalid_argument for an empty grid or z_max <= z_min.
  GridEnvironment(OccupancyGrid grid, double z_min, double z_max);

  Eigen::AlignedBox3d bounds() const override { return bounds_; }
  bool is_free(const Eigen::Vector3d& p, double radius) const override;
  bool segment_is_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const override;
  bool line_of_sight(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const override;

  const OccupancyGrid& grid() const { return grid_; }
  /// Distance (m) from p's cell to the nearest non-free cell, 0 outside the grid.
  double clearance(const Eigen::Vector3d& p) const;

  /// Places features on the faces of occupied cells that border free cells, `density_per_m2`
  /// on average, scaled per stretch of wall (`wall_piece_m` squares) by one of 0, 0.25, 1, 2.5
  /// drawn from `seed`: like the paper's walls of different texture. Heights uniform in z range.
  std::vector<Feature> wall_features(double density_per_m2, double wall_piece_m, uint64_t seed) const;

 private:
  bool cell_of(const Eigen::Vector2d& xy, int& col, int& row) const;

  OccupancyGrid grid_;
  Eigen::Affine2d T_grid_world_;
  std::vector<float> clearance_m_;
  double z_min_, z_max_;
  Eigen::AlignedBox3d bounds_;
};

}  // namespace kestrel::planner
