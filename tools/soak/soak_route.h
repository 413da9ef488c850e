#pragma once
// The route a soak flies: the simulator's `loop` flight of a world (an ellipse facing the walls,
// or a closed tour through the free space that revisits places: drivers/sim/flights.h) as
// waypoints for kestrel-follow, one lap after another. Flown again and again, SLAM sees the
// same places over and over, which is what a map or a pose graph that keeps everything grows on.

#include <Eigen/Core>

#include <vector>

#include "drivers/sim/world.h"

namespace kestrel::soak {

struct Route {
  Eigen::Vector4d start = Eigen::Vector4d::Zero();  ///< x, y, z, yaw: where the lap begins and ends
  std::vector<Eigen::Vector4d> lap;                 ///< waypoints of one lap, `start` first, not repeated at its end
  double lap_length_m = 0.0;
};

/// One lap of `world`'s loop flight, a waypoint about every `spacing_m` along it. Throws
/// std::runtime_error when the flight does not fit the world or does not close within an hour.
Route loop_route(const sim::World& world, double spacing_m = 0.25);

/// Whole laps, one after the other, at least `distance_m` long, ending at the start.
std::vector<Eigen::Vector4d> laps(const Route& route, double distance_m);

}  // namespace kestrel::soak
