#pragma once
// The camera's motion around a frame's time, as the timing corrections use it.

#include <Eigen/Core>

namespace kestrel::vo {

/// The camera's motion around a frame's time, for the timing corrections.
struct FrameMotion {
  bool known = false;
  Eigen::Matrix<double, 6, 1> twist_per_s = Eigen::Matrix<double, 6, 1>::Zero();  ///< [rho; phi]: pose(t + s) = pose(t) exp(s twist)
  double depth_offset_s = 0.0;  ///< depth time minus RGB time
  double readout_s = 0.0;       ///< rolling shutter: time from the first to the last image row
};

}  // namespace kestrel::vo
