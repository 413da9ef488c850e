#pragma once
// A synthetic world for the SLAM tests: the inside of a box-shaped room whose walls, floor and
// ceiling carry a random texture of grey cells at three scales, rendered into RGB-D frames by
// ray casting with exact depth; and camera paths through it with known poses.
//
// The texture is a function of the surface's own metric coordinates (hashed cells), so a place
// looks the same from every view, and two places differ. Cell edges give ORB its corners.
// Invariants: world z is up, the room spans [-half_x, half_x] x [-half_y, half_y] x [0, height];
// depth_mm is the optical-axis distance in millimetres (0 where nothing is hit, never inside
// the room); rgb is grey (R = G = B).

#include <Eigen/Geometry>
#include <vector>

#include "common/rgbd_frame.h"

namespace kestrel::slam::test {

class SyntheticRoom {
 public:
  SyntheticRoom(unsigned seed, double half_x_m, double half_y_m, double height_m);

  /// The view of a camera at T_world_camera (optical frame: x right, y down, z forward).
  RgbdFrame render(const Eigen::Isometry3d& T_world_camera, const PinholeCamera& camera,
                   int64_t utime) const;

 private:
  double texture(int face, double s, double t) const;

  unsigned seed_;
  Eigen::Vector3d lo_, hi_;
};

/// The optical frame of a camera at `position` looking horizontally along `yaw` (world z up).
Eigen::Isometry3d level_camera(const Eigen::Vector3d& position, double yaw_rad);

/// `n` poses on a circle of `radius_m` about (0, 0, 1 m), looking outward, going round
/// `turns` times (the last pose revisits the first when turns is a whole number).
std::vector<Eigen::Isometry3d> circle_path(int n, double radius_m, double turns);

/// `n` poses along x from -length/2 to +length/2 at y = 0, z = 1 m, looking along -y (at the
/// wall beside the path): every place is seen once.
std::vector<Eigen::Isometry3d> straight_path(int n, double length_m);

/// 320 x 240 camera (half the Kinect's) with 60 degrees of horizontal field of view, enough
/// for ORB and quick to render.
PinholeCamera test_camera();

}  // namespace kestrel::slam::test
