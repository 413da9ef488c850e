#pragma once
// The Kinect's accelerometer (a Kionix KXSD9 in the motor unit) and its axes.
//
// libfreenect reports raw counts, 819 per g (FREENECT_COUNTS_PER_G), and converts them with
// g = 9.80665 m/s^2 (freenect_get_mks_accel). TUM's accelerometer.txt holds the same
// readings in m/s^2: every value there is a whole number of counts times 9.80665 / 819.
//
// Axes: the accelerometer reads specific force (+g upwards at rest) on axes x left, y up,
// z forward as seen from the Kinect, i.e. the RGB camera's optical frame (x right, y down,
// z forward) turned 180 degrees about z: a_camera = (-a_x, -a_y, a_z). This was measured on
// TUM fr1_xyz and fr1_rpy: a least-squares fit of the readings against the specific force
// that the motion-capture attitude predicts, R_world_camera^T * (0, 0, +9.81), gives
// diag(-0.95, -0.78, 1.29) and diag(-1.01, -0.96, 1.04) with off-diagonal terms below 0.35
// (README.md, "Accelerometer axes"; the residual is the hand-held motion itself).

#include <Eigen/Core>
#include <cstdint>

namespace kestrel::kinect {

inline constexpr double kStandardGravity = 9.80665;  ///< libfreenect's g, m/s^2
inline constexpr double kCountsPerG = 819.0;         ///< FREENECT_COUNTS_PER_G

/// Specific force on the accelerometer's axes -> the RGB camera's optical frame.
inline Eigen::Vector3d accel_to_camera(const Eigen::Vector3d& a_accel) {
  return {-a_accel.x(), -a_accel.y(), a_accel.z()};
}

/// Raw counts -> m/s^2, as freenect_get_mks_accel computes it.
inline double counts_to_mps2(int16_t counts) { return counts / kCountsPerG * kStandardGravity; }

/// m/s^2 -> raw counts, rounded to nearest and saturated to int16 (NaN gives 0).
int16_t mps2_to_counts(double a);

}  // namespace kestrel::kinect
