#pragma once
// Closed routes through a world's free space, for the spline flights (`loop`, `survey`).
//
// The free space at flight height is sampled on a grid (cells whose centre has at least
// `clearance_m` to every obstacle), restricted to the region connected to the start. A tour
// then visits `stops` places chosen by farthest-point sampling of the geodesic (grid)
// distance, in the cheapest order, along shortest grid paths, and comes back to the start:
// corridors walked twice and the return to the start give the revisits loop closure needs.
// Deterministic; no randomness.

#include <Eigen/Core>
#include <vector>

#include "drivers/sim/world.h"

namespace kestrel::sim {

struct RouteOptions {
  double height_m = 1.2;      ///< flight height above the world's floor (bounds min z)
  double cell_m = 0.2;        ///< grid resolution
  double clearance_m = 0.7;   ///< required distance to every obstacle at grid cells
  int stops = 4;              ///< places visited besides the start
  double spacing_m = 0.5;     ///< distance between consecutive returned points
};

/// A closed polyline (the last point connects back to the first) starting at `start`, with
/// points about `spacing_m` apart. Throws std::runtime_error (naming the world) if the start
/// is not in free space or nothing can be reached from it.
std::vector<Eigen::Vector3d> plan_tour(const World& world, const Eigen::Vector2d& start, const RouteOptions& options);

}  // namespace kestrel::sim
