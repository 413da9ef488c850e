#pragma once
// Turns the visual odometry's relative motions (each frame against a reference frame that an
// earlier frame announced) into odometry poses T_odom_camera that SLAM takes (slam.h).
//
// "odom" is the body frame at the first frame: the first camera pose is T_body_camera. When the
// odometry restarts (no reference, or a reference this chain never saw: its announcement lost
// on a link, or forgotten), the new segment starts at the last known pose and the pose is
// flagged `broken`: it is not related to the earlier ones. An unseen reference is remembered
// where that first motion puts it, so the later motions against it chain on. A motion from the
// previous frame, which no update announced (the VO falls back to it when its keyframe fails),
// chains on through that frame's pose: no break. Invariants: utimes increase; an OK motion's
// reference is an earlier frame; at most kMaxReferences references are remembered.
//
// Uncertainty: when the VO reports a covariance with each motion, the chain keeps it with each
// reference (relative to the reference it was measured from), so that relative_covariance()
// gives the covariance of the motion between two frames of one segment: the frames' own
// motions from their references plus the references' motions between them, carried to the
// later frame (first order; the terms are taken as independent). The part of each reported
// covariance that the VO calls per-frame pose noise (its floors: timing, misregistration) is
// taken out of every motion and counted once for the span: that noise belongs to each frame's
// pose, so along a chain it cancels between consecutive motions instead of adding up.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>

#include "common/geometry/se3.h"

namespace kestrel::slam {

/// The part of a VO result the chain needs (vo_update_t without the diagnostics).
struct VoMotion {
  int64_t utime = 0;
  int64_t reference_utime = 0;
  bool ok = false;                  ///< T_reference_current is valid
  bool new_reference = false;       ///< this frame is the reference of the next ones
  Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  /// Of T_reference_current, [dp; dtheta] as in vo_update_t (dp in the reference frame,
  /// dtheta in the current frame); all zero when the VO gave none.
  Matrix6d covariance = Matrix6d::Zero();
  /// Per-axis standard deviations of the per-frame pose noise included in `covariance` (the
  /// VO's floors, vo_update_t); 0 = none.
  double translation_floor_m = 0.0;
  double rotation_floor_rad = 0.0;
};

struct OdometryPose {
  Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();
  bool broken = false;              ///< the odometry restarted since the previous pose
  /// How the pose was chained, for relative_covariance(): the reference it was measured from
  /// (0: none, the start of a segment), the motion from it, and that motion's covariance as a
  /// right perturbation xi = [rho; phi] of T_reference_camera (T * Exp(xi)) without the
  /// per-frame pose noise, which is `floor`; has_covariance when the VO reported one.
  int64_t reference_utime = 0;
  Eigen::Isometry3d T_reference_camera = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();
  Matrix6d floor = Matrix6d::Zero();
  bool has_covariance = false;
  int64_t utime = 0;
};

class OdometryChain {
 public:
  static constexpr size_t kMaxReferences = 64;

  /// The pose of this frame, or nothing when the odometry gave none. Throws InputError for a
  /// utime that does not increase or a motion that is not a finite rigid transform.
  std::optional<OdometryPose> add(const VoMotion& motion);
  void reset();

  /// Covariance of T_a_b = T_odom_a^-1 T_odom_b as a right perturbation [rho; phi], for two
  /// poses this chain gave (a before b, one segment), when the VO reported covariances for
  /// every motion in between and the references joining them are still remembered.
  std::optional<Matrix6d> relative_covariance(const OdometryPose& a, const OdometryPose& b) const;

 private:
  struct Reference {
    Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();
    int64_t parent_utime = 0;  ///< the reference it was measured from (0: segment start)
    Matrix6d covariance = Matrix6d::Zero();  ///< right perturbation of T_parent_this
    bool has_covariance = false;
    /// Never announced: placed where the first motion against it put it, at a break, so not
    /// that frame's own pose in the chain.
    bool placed_at_break = false;
  };
  /// Keeps `reference` under `utime`, forgetting the oldest beyond kMaxReferences.
  void remember(int64_t utime, const Reference& reference);

  std::map<int64_t, Reference> references_;  ///< utime -> reference
  std::optional<OdometryPose> last_;  ///< the last pose given out
  int64_t last_utime_ = 0;
};

}  // namespace kestrel::slam
