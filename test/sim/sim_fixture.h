#pragma once
// Shared set-up of the sim tests: small worlds built in code (whose geometry the tests know
// exactly), the built-in worlds loaded once per process, and camera poses.

#include <Eigen/Geometry>

#include "drivers/sim/camera_options.h"
#include "drivers/sim/flight.h"
#include "drivers/sim/imu.h"
#include "drivers/sim/world.h"

namespace kestrel::sim::test {

/// A 12 x 12 x 5 m open space with one plane wall x = 3 (facing -x) spanning y in [-4, 4],
/// z in [-1, 4], and, when `with_box`, a box (centre (2, 0.3, 1.4), half extent 0.25,
/// yawed 20 degrees) in front of it. Materials are light plaster, so depth returns are strong.
const World& plane_world(bool with_box);

/// A built-in world, loaded once per test process.
const World& builtin(const char* name);

/// Optical frame at `position` looking along world heading `yaw` (z up), pitched down by
/// `pitch` (radians).
Eigen::Isometry3d look(const Eigen::Vector3d& position, double yaw, double pitch = 0.0);

/// Camera options with every random effect off (depth still quantised).
CameraOptions exact_camera();

/// The state reached by integrating `imu`'s samples with RK4 (steps of two sample periods)
/// from the flight's true state at t = 0, after `seconds`.
struct Integrated {
  Eigen::Quaterniond q;
  Eigen::Vector3d v, p;
};
Integrated integrate(const Flight& flight, ImuSimulator& imu, double seconds);

}  // namespace kestrel::sim::test
