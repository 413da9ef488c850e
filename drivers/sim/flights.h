#pragma once
// The flights kestrel-sim offers, each fitted to the world it flies in:
//
//   hover       position hold with a slow drift of a few centimetres and a little yaw
//   figure8     a horizontal figure eight at walking pace, yaw swinging +-25 degrees
//   aggressive  a wide figure eight at up to ~1.5 m/s with yaw swinging at up to ~120 deg/s
//   loop        an ellipse around the room facing the walls; in worlds where no ellipse fits
//               (corridors, building maps) a closed tour through the free space that
//               revisits places (route.h), for loop closure
//   survey      a tour visiting more places (six stops) at a slower pace
//
// Every flight starts at rest at the world's start pose, is collision-free (checked: the
// vehicle's sphere of `radius_m` stays clear of every obstacle, else the flight is shrunk
// or an error names the world), and repeats after its period, so any duration works.

#include <memory>
#include <string>
#include <vector>

#include "drivers/sim/bspline.h"
#include "drivers/sim/flight.h"
#include "drivers/sim/world.h"

namespace kestrel::sim {

struct FlightOptions {
  double radius_m = 0.35;   ///< vehicle radius for the collision check
  double ramp_s = 2.0;      ///< take-off ramp (see flight.h)
  double speed_scale = 1.0; ///< multiplies every flight's speed
};

/// Names accepted by make_flight.
std::vector<std::string> flight_names();

/// The flight `name` in `world`. Throws std::invalid_argument for an unknown name and
/// std::runtime_error when no collision-free version of it fits the world.
std::unique_ptr<Flight> make_flight(const std::string& name, const World& world, const FlightOptions& options = {});

/// Checks the flight over [0, duration_s] every 0.05 s; returns the first time at which the
/// vehicle's sphere is not free, or a negative value if there is none.
double first_collision(const Flight& flight, const World& world, double radius_m, double duration_s);

/// A flight along a closed periodic B-spline (position and unwrapped yaw), used by `loop`
/// and `survey` in worlds of corridors; public so that tests and tools can build their own.
class SplineFlight : public Flight {
 public:
  /// `points`: closed route (route.h), flown at about `speed` m/s, heading along the route.
  SplineFlight(std::string name, const std::vector<Eigen::Vector3d>& points, double speed, double ramp_s);
  std::string name() const override { return name_; }
  PathPoint path(double tau) const override;
  double period_s() const { return position_.period_s(); }

 private:
  std::string name_;
  PeriodicBSpline position_;
  PeriodicBSpline yaw_;   // x: yaw minus its mean drift over a period (periodic part)
  double yaw_turn_ = 0.0; // total heading change over one period (a multiple of 2 pi)
};

}  // namespace kestrel::sim
