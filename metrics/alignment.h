#pragma once
// The rigid alignment used before the ATE: the T_gt_est (rotation and translation, no scale)
// that minimises sum_i |p_gt_i - T_gt_est * p_est_i|^2.
//
// common/geometry/align.h solves the general case (Horn / Umeyama). It refuses point sets that
// leave the rotation undetermined; the ATE is still defined there, because every minimiser
// gives the same residual, so this file completes those cases:
//  * all estimated positions coincide (a trajectory that never moves): translation only;
//  * they lie on a line: any rotation taking the line's direction d onto
//    v = sum_i s_i (p_gt_i - mean_gt), s_i = d . (p_est_i - mean_est), is a minimiser
//    (the cost is const - 2 (R d) . v); the smallest such rotation is used.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

#include "common/trajectory.h"

namespace kestrel::metrics {

enum class AlignmentKind {
  kNone,         ///< not aligned (disabled)
  kRigid,        ///< rotation and translation determined by the points
  kCollinear,    ///< estimated positions on a line: rotation about it is free
  kTranslation,  ///< estimated positions coincide: rotation is free
};

struct Alignment {
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();
  AlignmentKind kind = AlignmentKind::kNone;
};

/// Aligns corresponding columns of `p_est` onto `p_gt` (same size, at least one column;
/// std::invalid_argument otherwise).
Alignment align_positions(const Eigen::Matrix3Xd& p_est, const Eigen::Matrix3Xd& p_gt);

/// Aligns whole poses: the rotation is the chordal mean of R_gt R_est^T over the estimate's
/// poses that `gt` covers (within `max_gap_us`, Trajectory::at), the translation the mean of
/// p_gt - R p_est. For expressing one world in another once (a saved map's world in the
/// truth's: `kestrel eval --world-from`), where the positions alone may leave the rotation
/// loose (a camera turning on the spot). Throws std::invalid_argument when no pose is covered.
Alignment align_poses(const Trajectory& est, const Trajectory& gt, int64_t max_gap_us);

const char* to_string(AlignmentKind kind);

}  // namespace kestrel::metrics
