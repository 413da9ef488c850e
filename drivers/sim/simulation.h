#pragma once
// The synthetic sensor suite in one object: a world, a flight, the Kinect-like camera
// (renderer.h) and the IMU (imu.h), stepped in time order. This is the header other
// components use:
//
//   const World world = load_world("room");                       // world_catalog.h
//   const auto flight = make_flight("figure8", world);            // flights.h
//   Simulation sim(world, *flight, SimulationOptions{});
//   for (;;) {
//     const SimEvent e = sim.next();      // IMU samples at 200 Hz, frames at 30 Hz, in order
//     if (e.kind == SimEvent::kFrame) use(e.frame, e.truth);      // RgbdFrame + exact pose
//     else use(e.imu, e.truth);                                   // ImuSample + exact state
//   }
//
// Or directly: sim.render(k) renders frame k; flight->state(t) is the exact motion.
// Time stamps: utime = start_utime + round(t * 1e6) with t = seq / rate (IMU) and
// k / camera rate (frames); the truth is evaluated at exactly the stamped time. When an IMU
// sample and a frame share a time stamp the IMU sample comes first. A fixed seed gives the
// same bytes on every run and machine.

#include <algorithm>
#include <cstdint>

#include "common/rgbd_frame.h"
#include "drivers/sim/camera_options.h"
#include "drivers/sim/flight.h"
#include "drivers/sim/imu.h"
#include "drivers/sim/renderer.h"
#include "drivers/sim/world.h"

namespace kestrel::sim {

struct SimulationOptions {
  CameraOptions camera;
  ImuOptions imu;
  uint64_t seed = 1;                               ///< sensor noise (camera and IMU)
  int64_t start_utime = 1'000'000'000'000'000;     ///< utime of t = 0 (10^9 s, as a sensor clock)
};

struct SimEvent {
  enum Kind { kImu, kFrame };
  Kind kind = kImu;
  int64_t utime = 0;
  MotionState truth;                 ///< exact body state at utime
  Eigen::Isometry3d T_world_camera;  ///< exact optical-frame pose at utime
  ImuSample imu;                     ///< kImu: the sample (with the true biases)
  RgbdFrame frame;                   ///< kFrame: the rendered frame
};

class Simulation {
 public:
  /// `world` and `flight` must outlive the simulation.
  Simulation(const World& world, const Flight& flight, const SimulationOptions& options);

  /// The next event in time order (never ends; the caller decides the duration).
  SimEvent next();
  /// Time stamp of the event next() returns next (a closed-loop driver commits the vehicle's
  /// motion up to it first).
  int64_t next_utime() const { return std::min(frame_utime(next_frame_), imu_utime(next_imu_)); }
  /// Starts again at t = 0; the same events follow.
  void reset();

  /// Frame k rendered at its time stamp (independent of next()).
  RgbdFrame render(int64_t k);
  int64_t frame_utime(int64_t k) const;
  int64_t imu_utime(int64_t seq) const;
  double seconds(int64_t utime) const { return 1e-6 * static_cast<double>(utime - options_.start_utime); }
  Eigen::Isometry3d T_world_camera(double t) const;

  const SimulationOptions& options() const { return options_; }
  const World& world() const { return world_; }
  const Flight& flight() const { return flight_; }

 private:
  const World& world_;
  const Flight& flight_;
  SimulationOptions options_;
  Renderer renderer_;
  ImuSimulator imu_;
  int64_t next_frame_ = 0;
  int64_t next_imu_ = 0;
};

}  // namespace kestrel::sim
