#include "drivers/sim/simulation.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace kestrel::sim {

Simulation::Simulation(const World& world, const Flight& flight, const SimulationOptions& options)
    : world_(world),
      flight_(flight),
      options_(options),
      renderer_(world, options.camera, options.seed),
      imu_(flight, options.imu, options.seed) {
  if (!(options_.camera.rate_hz > 0)) throw std::invalid_argument("camera rate must be > 0");
}

void Simulation::reset() {
  imu_.reset();
  next_frame_ = 0;
  next_imu_ = 0;
}

int64_t Simulation::frame_utime(int64_t k) const {
  return options_.start_utime + std::llround(static_cast<double>(k) * 1e6 / options_.camera.rate_hz);
}

int64_t Simulation::imu_utime(int64_t seq) const {
  return options_.start_utime + std::llround(static_cast<double>(seq) * 1e6 / options_.imu.rate_hz);
}

Eigen::Isometry3d Simulation::T_world_camera(double t) const {
  return flight_.state(t).T_world_body * options_.camera.T_body_camera;
}

RgbdFrame Simulation::render(int64_t k) {
  const int64_t utime = frame_utime(k);
  const double t = seconds(utime);
  const int n = options_.camera.rgb.motion_blur_samples;
  std::vector<Eigen::Isometry3d> exposure;
  if (n <= 1) {
    exposure.push_back(T_world_camera(t));
  } else {
    // Poses spread evenly over the exposure, centred on the time stamp.
    const double span = options_.camera.rgb.exposure_time_s;
    for (int i = 0; i < n; ++i) exposure.push_back(T_world_camera(t + span * (static_cast<double>(i) / (n - 1) - 0.5)));
  }
  return renderer_.render(exposure, utime, k);
}

SimEvent Simulation::next() {
  SimEvent e;
  const int64_t frame_at = frame_utime(next_frame_), imu_at = imu_utime(next_imu_);
  if (imu_at <= frame_at) {
    e.kind = SimEvent::kImu;
    e.utime = imu_at;
    e.imu = imu_.next();
    ++next_imu_;
  } else {
    e.kind = SimEvent::kFrame;
    e.utime = frame_at;
    e.frame = render(next_frame_);
    ++next_frame_;
  }
  e.truth = flight_.state(seconds(e.utime));
  e.T_world_camera = e.truth.T_world_body * options_.camera.T_body_camera;
  return e;
}

}  // namespace kestrel::sim
