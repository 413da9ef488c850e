#pragma once
// A small synthetic world for the VO tests: a box room with textured walls, floor and a block,
// rendered into RGB-D frames by ray casting, with exact depth and known poses.
//
// Texture is value noise in the plane's own metric coordinates (two octaves, bilinear), so a
// surface looks the same from every view and images have no aliasing at the distances used.
// Invariants: depth_mm is the z (optical axis) distance, rounded to millimetres (0 where no
// surface is hit); the colour image is grey (R = G = B); frames are seen by `camera`
// (undistorted unless `distortion` is set on it, which then distorts the rendered pixels).

#include <Eigen/Geometry>
#include <vector>

#include "common/rgbd_frame.h"

namespace kestrel::vo::test {

class SyntheticScene {
 public:
  /// A room of `half_width` x `half_width` x `depth` metres in front of the origin, seeded.
  explicit SyntheticScene(unsigned seed = 1, double depth_m = 3.0);

  /// Renders the view of a camera at T_world_camera (optical frame: x right, y down, z forward).
  RgbdFrame render(const Eigen::Isometry3d& T_world_camera, const PinholeCamera& camera,
                   int64_t utime) const;

  /// Grey level (0..255) of the texture at a world point on plane `plane`.
  double intensity(int plane, const Eigen::Vector3d& p_world) const;

 private:
  struct Plane {
    Eigen::Vector3d origin, u, v, normal;  // u, v unit in-plane axes
    double width, height;
    unsigned seed;
  };
  double noise(unsigned seed, double s, double t, double cell) const;

  std::vector<Plane> planes_;
};

/// The fr1 calibrated intrinsics used across the tests (no distortion).
PinholeCamera test_camera();

}  // namespace kestrel::vo::test
