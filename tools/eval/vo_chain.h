#pragma once
// Chains visual-odometry results (frame-to-reference motions) into a camera trajectory.
//
// Rules, applied to frames in increasing time:
//  * the chain starts at the identity: the first frame with status "no reference" (the VO's
//    first frame) has the pose I; a reference frame looked up before anything is known is I;
//  * a frame whose motion is valid gets T_world_current = T_world_reference * T_ref_current,
//    where T_world_reference is the pose recorded for the frame at reference_utime;
//  * if that reference has no pose (the VO failed on it, or it is not in the log), the chain
//    continues from the last known pose: the motion is applied to the pose of the most recent
//    frame that has one, and the frame is counted (unknown_reference);
//  * any other frame (a failure, or a restart after a reset) has no estimate; it is still
//    listed among the frames, so that it counts as a failure.

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "common/trajectory.h"

namespace kestrel::eval {

struct VoStep {
  int64_t utime = 0;
  int64_t reference_utime = 0;
  bool valid = false;         ///< the VO produced T_reference_current for this frame
  bool no_reference = false;  ///< the VO's first frame (or first after a reset)
  Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
};

class VoChain {
 public:
  /// Adds the next frame; std::invalid_argument unless its utime is after the last one's.
  void add(const VoStep& step);

  const Trajectory& trajectory() const { return trajectory_; }  ///< T_world_camera
  const std::vector<int64_t>& frame_utimes() const { return frame_utimes_; }
  size_t without_estimate() const { return without_estimate_; }
  size_t unknown_reference() const { return unknown_reference_; }

 private:
  Trajectory trajectory_;
  std::vector<int64_t> frame_utimes_;
  size_t without_estimate_ = 0;
  size_t unknown_reference_ = 0;
};

}  // namespace kestrel::eval
