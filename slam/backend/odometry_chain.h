#pragma once
// Turns the visual odometry's relative motions (each frame against a reference frame that an
// earlier frame announced) into odometry poses T_odom_camera that SLAM takes (slam.h).
//
// "odom" is the body frame at the first frame: the first camera pose is T_body_camera. When the
// odometry restarts (no reference, or a reference this chain never saw), the new segment starts
// at the last known pose and the pose is flagged `broken`: it is not related to the earlier
// ones. Invariants: utimes increase; at most kMaxReferences references are remembered.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>

namespace kestrel::slam {

/// The part of a VO result the chain needs (vo_update_t without the diagnostics).
struct VoMotion {
  int64_t utime = 0;
  int64_t reference_utime = 0;
  bool ok = false;                  ///< T_reference_current is valid
  bool new_reference = false;       ///< this frame is the reference of the next ones
  Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
};

struct OdometryPose {
  Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();
  bool broken = false;              ///< the odometry restarted since the previous pose
};

class OdometryChain {
 public:
  static constexpr size_t kMaxReferences = 64;

  /// The pose of this frame, or nothing when the odometry gave none. Throws InputError for a
  /// utime that does not increase or a motion that is not a finite rigid transform.
  std::optional<OdometryPose> add(const VoMotion& motion);
  void reset();

 private:
  std::map<int64_t, Eigen::Isometry3d> references_;  ///< utime -> T_odom_camera
  std::optional<Eigen::Isometry3d> last_;            ///< last pose given out
  int64_t last_utime_ = 0;
  bool pending_break_ = false;  ///< a restart was seen; flag the next pose
};

}  // namespace kestrel::slam
