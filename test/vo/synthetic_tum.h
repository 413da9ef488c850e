#pragma once
// The synthetic room (synthetic_scene.h) seen along one straight line, for the tests of the
// offline runs: the camera's pose at each frame, its ground truth as a motion-capture system
// samples it, and a TUM RGB-D folder of the rendered frames for the tools' --tum runs
// (kestrel-vo's and kestrel-slam's). One motion for all of them, so that what one test finds
// of a folder the others can count on.

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>

#include "common/trajectory.h"

namespace kestrel::vo::test {

/// T_world_camera at frame k (world = frame 0's camera): 1.1 cm a frame along one direction,
/// no rotation. k may lie between frames, for the ground truth between them.
Eigen::Isometry3d line_pose(double k);

/// line_pose() every 10 ms, from 50 ms before the first of `frames` frames (at t0, t0 +
/// period_us, ...) to 50 ms after the last: every frame lies within the ground truth.
Trajectory line_ground_truth(int64_t t0, int64_t period_us, int frames);

/// The folder's frame times: frame k's RGB image at kTumT0 + k * kTumPeriod (a TUM-like epoch).
inline constexpr int64_t kTumT0 = 1305031229528748;
inline constexpr int64_t kTumPeriod = 33333;

struct TumFolderSpec {
  int frames = 4;
  int blank_depth_from = 1 << 30;  ///< frames from here on have no depth reading at all
  int64_t depth_shift_us = 1000;   ///< depth time - RGB time
  bool extra_rgb = false;          ///< one more RGB image, a second after the others, no depth
};

/// Writes parent/rgbd_dataset_synthetic and returns it: frame k rendered from line_pose(k)
/// with the ROS default intrinsics (the name names no freiburg camera, so a run takes the
/// default profile, the built-in defaults fitted on synthetic frames), rgb.txt, depth.txt and
/// groundtruth.txt (line_ground_truth). Throws std::runtime_error if a file cannot be written.
std::filesystem::path write_tum_folder(const std::filesystem::path& parent, const TumFolderSpec& spec = {});

}  // namespace kestrel::vo::test
