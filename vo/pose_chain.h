#pragma once
// Chains the odometry's relative motions into camera poses T_world_camera, the trajectory a
// user (or an evaluation) sees. The world frame is the camera of the first frame.
//
// Invariants: a frame gets a pose exactly when its status is ok (or it is the first frame);
// a motion is chained onto the pose of the frame it is relative to (the keyframe or, after a
// fall-back, the previous frame), both of which the chain keeps; after a restart the new
// reference takes the last known pose (the motion across the gap is unknown, taken as none).

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>

#include "vo/odometry.h"

namespace kestrel::vo {

class PoseChain {
 public:
  /// Adds the next result of the stream; returns this frame's T_world_camera if it has one.
  std::optional<Eigen::Isometry3d> add(const VoResult& result);
  void reset() { *this = PoseChain(); }

 private:
  struct Stamped {
    int64_t utime = -1;
    Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  };
  Stamped keyframe_, previous_;
  Eigen::Isometry3d last_ = Eigen::Isometry3d::Identity();
};

}  // namespace kestrel::vo
