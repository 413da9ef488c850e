#include "tools/soak/soak_route.h"

#include <cmath>
#include <stdexcept>

#include "common/numbers.h"
#include "drivers/sim/flights.h"

namespace kestrel::soak {

Route loop_route(const sim::World& world, double spacing_m) {
  if (!(spacing_m > 0.0)) throw std::invalid_argument("loop_route: the spacing must be positive");
  const auto flight = sim::make_flight("loop", world);
  // The path (without the take-off ramp) sampled finely; the lap ends where the path comes back
  // to its start, heading as it began, after having been away from it.
  constexpr double kStep = 0.005;  // s of path time: < 4 mm at the flights' 0.6 m/s
  const sim::PathPoint first = flight->path(0.0);
  Route r;
  r.start << first.p, wrap_angle(first.yaw);
  r.lap.push_back(r.start);
  Eigen::Vector3d previous = first.p;
  double length = 0.0, since_waypoint = 0.0, farthest = 0.0, last_distance = 0.0;
  for (double tau = kStep; tau < 3600.0; tau += kStep) {
    const sim::PathPoint p = flight->path(tau);
    const double step = (p.p - previous).norm();
    const double distance = (p.p - first.p).norm();
    const double turned = std::abs(wrap_angle(p.yaw - first.yaw));
    // Closed: back within 2 cm of the start (the nearest sample: farther at the next), same heading.
    if (farthest > 1.0 && last_distance < 0.02 && distance > last_distance && turned < 0.05) {
      r.lap_length_m = length;
      // A last waypoint too near the start would be a step back on the next lap.
      if (r.lap.size() > 1 && (r.lap.back().head<3>() - first.p).norm() < 0.5 * spacing_m) r.lap.pop_back();
      return r;
    }
    length += step;
    since_waypoint += step;
    farthest = std::max(farthest, distance);
    last_distance = distance;
    previous = p.p;
    if (since_waypoint >= spacing_m) {
      Eigen::Vector4d w;
      w << p.p, wrap_angle(p.yaw);
      r.lap.push_back(w);
      since_waypoint = 0.0;
    }
  }
  throw std::runtime_error("the loop flight of world '" + world.name() + "' does not close within an hour");
}

std::vector<Eigen::Vector4d> laps(const Route& route, double distance_m) {
  if (route.lap.empty() || !(route.lap_length_m > 0.0)) throw std::invalid_argument("laps: an empty route");
  const auto n = static_cast<size_t>(std::max(1.0, std::ceil(distance_m / route.lap_length_m)));
  std::vector<Eigen::Vector4d> out;
  out.reserve(n * route.lap.size() + 1);
  for (size_t i = 0; i < n; ++i) out.insert(out.end(), route.lap.begin(), route.lap.end());
  out.push_back(route.start);
  return out;
}

}  // namespace kestrel::soak
