// How each event changes the filter state: a keyframe clone, a VO update (against its clone,
// directly or through an anchor), a SLAM correction; and the noise of a VO update.

#include <cmath>

#include "common/geometry/so3.h"
#include "estimator/estimator.h"
#include "estimator/measurements.h"

namespace kestrel::estimator {
namespace {

// The error of A^-1 z from those of an anchor A = T_ref_anchor and z = T_ref_cur: the
// anchor's part (common to every update through that anchor) and the update's own part,
// treated as independent (conservative: A and z are both measured from the same old frame,
// whose error partly cancels in A^-1 z).
struct AnchoredNoise {
  Matrix6d from_anchor;
  Matrix6d from_update;
};
AnchoredNoise anchored_noise(const Eigen::Isometry3d& A, const Matrix6d& cov_A,
                             const Eigen::Isometry3d& z, const Matrix6d& cov_z) {
  const Eigen::Isometry3d rel = A.inverse() * z;
  const Eigen::Matrix3d Rt = A.linear().transpose();
  Matrix6d Jz = Matrix6d::Zero();
  Jz.topLeftCorner<3, 3>() = Rt;
  Jz.bottomRightCorner<3, 3>().setIdentity();
  Matrix6d JA = Matrix6d::Zero();
  JA.topLeftCorner<3, 3>() = -Rt;
  JA.topRightCorner<3, 3>() = so3::hat(rel.translation());
  JA.bottomRightCorner<3, 3>() = -rel.linear().transpose();
  return {JA * cov_A * JA.transpose(), Jz * cov_z * Jz.transpose()};
}

}  // namespace

void Estimator::apply(Event& e, FilterState& s) {
  switch (e.kind) {
    case EventKind::kClone:
      add_clone(s);
      e.outcome = Outcome::kApplied;
      return;
    case EventKind::kVo: {
      const auto spec = clone_specs_.find(e.vo.reference_utime);
      const int clone = spec == clone_specs_.end() ? -1 : s.mean.find_clone(spec->second.clone_utime);
      if (clone < 0) {
        e.outcome = Outcome::kUnreferenced;
        return;
      }
      // The update's noise is its keyframe's error, common to every update against that
      // keyframe, plus its own. The common part is added once, to the clone, so that a
      // keyframe held for many frames is not believed once per frame (docs/estimator.md §4).
      const double share = options_.vo_noise.keyframe_share;
      Eigen::Isometry3d z = e.vo.T_refcam_curcam;
      const Matrix6d Q = vo_noise(options_.vo_noise, e.vo);
      Matrix6d Q_common = share * Q, Q_own = (1.0 - share) * Q;
      if (spec->second.anchored) {
        // Every update through an anchor shares the anchor's error too.
        const AnchoredNoise a =
            anchored_noise(spec->second.anchor, spec->second.anchor_covariance, z, Q);
        Q_common = a.from_anchor + share * a.from_update;
        Q_own = (1.0 - share) * a.from_update;
        z = spec->second.anchor.inverse() * z;
      }
      const RelativePoseMeasurement m(clone, z, Q_own, e.vo.T_body_camera);
      Clone& reference = s.mean.clones[static_cast<size_t>(clone)];
      if (reference.keyframe_error_of != e.vo.reference_utime) {
        const int o = FilterMean::clone_offset(clone);
        s.P.block<6, 6>(o, o) += m.reference_covariance(s.mean, Q_common);
        reference.keyframe_error_of = e.vo.reference_utime;
      }
      const int max_in_row = options_.vo_max_gated_in_row;
      const bool force = max_in_row > 0 && s.vo_gated_in_row >= max_in_row;
      const UpdateResult r = filter_->update(s, m, force ? 0.0 : options_.vo_gate_chi2);
      e.outcome = r.applied ? (force ? Outcome::kForced : Outcome::kApplied) : Outcome::kGated;
      s.vo_gated_in_row = r.applied ? 0 : s.vo_gated_in_row + 1;
      return;
    }
    case EventKind::kCorrection: {
      if (e.outcome == Outcome::kAligned) return;
      const AbsolutePoseMeasurement m(e.correction.T_world_body, correction_noise(options_, e.correction));
      const UpdateResult r = filter_->update(s, m, options_.correction_gate_chi2);
      e.outcome = r.applied ? Outcome::kApplied : Outcome::kGated;
      return;
    }
  }
}

}  // namespace kestrel::estimator
