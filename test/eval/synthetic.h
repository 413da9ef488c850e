#pragma once
// Synthetic trajectories with answers known in closed form, for the evaluation tests.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <vector>

#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "common/trajectory.h"

namespace kestrel::eval::test {

constexpr int64_t kStart_us = 1305031104000000;  // a TUM-like epoch
constexpr int64_t kFrame_us = 33333;             // 30 Hz

/// Frame times kStart_us + i * step_us, i = 0 .. n-1.
inline std::vector<int64_t> frame_times(int n, int64_t step_us = kFrame_us) {
  std::vector<int64_t> t;
  for (int i = 0; i < n; ++i) t.push_back(kStart_us + i * step_us);
  return t;
}

/// A camera flying a rising circle (radius 1 m, 0.25 turn/s) while turning about two axes:
/// neither its positions nor its rotations are degenerate.
inline Eigen::Isometry3d helix_pose(int64_t utime) {
  const double t = 1e-6 * static_cast<double>(utime - kStart_us);
  const double a = 0.5 * kPi * t;
  const Eigen::Vector3d p(std::cos(a), std::sin(a), 0.2 * t);
  return se3::make(so3::exp(Eigen::Vector3d(0.1 * std::sin(t), 0.05 * t, a)), p);
}

inline Trajectory helix(const std::vector<int64_t>& utimes) {
  Trajectory t;
  for (int64_t u : utimes) t.push_back(u, helix_pose(u));
  return t;
}

/// Every pose of `t` with `f(utime, pose)` applied.
template <class F>
Trajectory map_poses(const Trajectory& t, F f) {
  Trajectory out;
  for (const StampedPose& p : t.poses()) out.push_back(p.utime, f(p.utime, p.T));
  return out;
}

}  // namespace kestrel::eval::test
