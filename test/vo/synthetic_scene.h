#pragma once
// A small synthetic world for the VO tests: a box room with textured walls, floor, ceiling and
// a block, rendered into RGB-D frames by the simulator's renderer (drivers/sim/renderer.h),
// with exact depth and known poses. It is one of the simulator's worlds (a world file made
// here, drivers/sim/README.md), so the tests see the surfaces, texture and lighting that
// kestrel-sim flies in, not a renderer of their own.
//
// The scene's frame is the one the tests pose cameras in: x right, y down, z forward (a level
// camera at the origin looks at the back wall, depth_m ahead); the room spans x in [-2, 2],
// y in [-1.5, 1.5] and z in [-1, depth_m]. Invariants: depth_mm is the exact z (optical axis)
// distance of the surface seen, rounded to millimetres (0 where none); the colour has no
// sensor noise or vignetting; the same seed, pose and camera always give the same bytes.
// `camera` is used as a pinhole (its distortion, if any, is not applied to the pixels).

#include <Eigen/Geometry>
#include <memory>
#include <optional>

#include "common/rgbd_frame.h"

namespace kestrel::sim {
class World;
class Renderer;
}  // namespace kestrel::sim

namespace kestrel::vo::test {

class SyntheticScene {
 public:
  /// The room, `depth_m` deep in front of the origin; `seed` keys the surfaces' appearance.
  explicit SyntheticScene(unsigned seed = 1, double depth_m = 3.0);
  ~SyntheticScene();
  SyntheticScene(const SyntheticScene&) = delete;
  SyntheticScene& operator=(const SyntheticScene&) = delete;

  /// Renders the view of a camera at T_world_camera (optical frame: x right, y down, z forward).
  /// Not thread-safe (the renderer keeps its buffers): one scene per thread.
  RgbdFrame render(const Eigen::Isometry3d& T_world_camera, const PinholeCamera& camera,
                   int64_t utime) const;

 private:
  unsigned seed_;
  std::unique_ptr<sim::World> world_;
  // Made for the camera of the last render; remade when another camera is asked for.
  mutable std::unique_ptr<sim::Renderer> renderer_;
  mutable std::optional<PinholeCamera> renderer_camera_;
};

/// The fr1 calibrated intrinsics used across the tests (no distortion).
PinholeCamera test_camera();

}  // namespace kestrel::vo::test
