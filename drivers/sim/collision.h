#pragma once
// Exact geometric queries against a world's obstacles: free-standing rectangles (walls,
// floors, ceilings, panels) and solid boxes (furniture, thick walls).
//
// CollisionIndex buckets the obstacles in a uniform 2D grid over x, y (1 m cells) so that a
// query only looks at nearby obstacles; very large ones (floors, ceilings) are always checked.
// All queries are const and thread-safe. Distances are Euclidean, metres; a point inside a box
// is at distance 0.

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "drivers/sim/surface.h"

namespace kestrel::sim {

/// Distance from p to the rectangle of s.
double distance_to_rectangle(const Eigen::Vector3d& p, const Surface& s);
/// Distance from p to the solid box (0 inside).
double distance_to_box(const Eigen::Vector3d& p, const Box& box);
/// Distance between the segment [a, b] and the rectangle / box (exact up to 1e-9 m).
double segment_distance_to_rectangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Surface& s);
double segment_distance_to_box(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Box& box);

/// Axis-aligned bounds of the rectangle of s / of the solid box (its eight corners).
Eigen::AlignedBox3d bounds_of(const Surface& s);
Eigen::AlignedBox3d bounds_of(const Box& box);
/// Entry distance along the unit direction `d` into the box of half extents `half_extent`
/// centred at the origin, for a ray from `o` (both in the box's frame), and the axis of the
/// entry face; infinity (axis untouched) if it misses or starts inside.
double ray_box_local(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& half_extent,
                     int* axis);
/// The same for a ray in world coordinates, with the face it enters by (0..5 as Box::faces).
double ray_box(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Box& box, int* face);
/// Distance along the unit direction to the rectangle of s, or infinity if the ray misses it.
double ray_rectangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Surface& s);

struct RayHit {
  double distance = 0.0;  ///< along the unit direction, metres
  int surface = -1;       ///< the surface hit
};

class CollisionIndex {
 public:
  CollisionIndex() = default;
  /// Indexes every surface that is not a box face, and every box.
  CollisionIndex(const std::vector<Surface>& surfaces, const std::vector<Box>& boxes);

  /// Distance from p to the nearest obstacle, or `cap` if none is nearer than `cap`.
  double clearance(const Eigen::Vector3d& p, double cap) const;
  /// Minimum distance between the segment and any obstacle, or `cap` if none is nearer.
  double segment_clearance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double cap) const;
  /// First surface hit by the ray from `origin` along the unit `direction`, within max_distance.
  /// Rectangles are hit from either side; box faces only from outside.
  std::optional<RayHit> raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                double max_distance) const;

 private:
  struct Item {
    bool is_box;
    int index;
  };
  std::vector<Item> candidates(double x0, double y0, double x1, double y1) const;

  std::vector<Surface> rectangles_;
  std::vector<Box> boxes_;
  std::vector<std::vector<Item>> cells_;
  std::vector<Item> global_;
  double origin_x_ = 0.0, origin_y_ = 0.0, cell_ = 1.0;
  int nx_ = 0, ny_ = 0;
};

}  // namespace kestrel::sim
