#pragma once
// The camera's motion around a frame's time, as the timing corrections use it.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/geometry/se3.h"

namespace kestrel::sensors {

/// The camera's motion around a frame's time, for the timing corrections.
struct FrameMotion {
  bool known = false;
  Eigen::Matrix<double, 6, 1> twist_per_s = Eigen::Matrix<double, 6, 1>::Zero();  ///< [rho; phi]: pose(t + s) = pose(t) exp(s twist)
  double depth_offset_s = 0.0;  ///< depth time minus RGB time
  double readout_s = 0.0;       ///< rolling shutter: time from the first to the last image row

  /// The camera at the depth image's time in the colour camera's frame, exp(depth offset *
  /// twist); identity when the motion is unknown.
  Eigen::Isometry3d T_rgb_depth() const {
    return known ? se3::exp(depth_offset_s * twist_per_s) : Eigen::Isometry3d::Identity();
  }
};

}  // namespace kestrel::sensors
