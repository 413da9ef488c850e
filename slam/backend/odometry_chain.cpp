#include "slam/backend/odometry_chain.h"

#include <cmath>
#include <string>

#include "common/error.h"
#include "common/geometry/se3.h"

namespace kestrel::slam {

void OdometryChain::reset() {
  references_.clear();
  last_.reset();
  last_utime_ = 0;
}

void OdometryChain::remember(int64_t utime, const Reference& reference) {
  // The oldest go first, never the one remembered now.
  while (references_.size() >= kMaxReferences && references_.begin()->first != utime)
    references_.erase(references_.begin());
  references_[utime] = reference;
}

std::optional<OdometryPose> OdometryChain::add(const VoMotion& m) {
  if (last_utime_ != 0 && m.utime <= last_utime_) {
    throw InputError("VO update utime " + std::to_string(m.utime) + " does not follow " + std::to_string(last_utime_));
  }
  if (m.ok && !se3::is_valid(m.T_reference_current, 1e-6)) {
    throw InputError("VO update " + std::to_string(m.utime) + ": motion is not a finite rigid transform");
  }
  if (m.ok && (m.reference_utime <= 0 || m.reference_utime >= m.utime)) {
    throw InputError("VO update " + std::to_string(m.utime) + ": its reference " + std::to_string(m.reference_utime) +
                     " is not an earlier frame");
  }
  last_utime_ = m.utime;

  std::optional<Eigen::Isometry3d> T_odom_camera;
  OdometryPose out;
  out.utime = m.utime;
  bool broken = false;  // not related to the poses before
  if (m.ok) {
    auto ref = references_.find(m.reference_utime);
    if (ref == references_.end()) {
      if (last_ && last_->utime == m.reference_utime) {
        // Measured from the frame before, which no update announced: the VO's fall-back when
        // its keyframe fails. That frame's pose and how it was chained are known: go on
        // through it.
        remember(m.reference_utime,
                 Reference{last_->T_odom_camera, last_->reference_utime, last_->covariance, last_->has_covariance});
      } else {
        // A reference this chain never had: its announcement was lost (a lossy link) or is
        // older than the kMaxReferences remembered. A new segment starts at this frame, and
        // the reference is remembered where this motion puts it, so the motions after it
        // against the same reference chain on from here: one break, rather than no pose at
        // all until the VO takes its next reference (a hovering VO keeps one for minutes).
        broken = last_.has_value();
        const Eigen::Isometry3d T_odom_here = last_ ? last_->T_odom_camera : m.T_body_camera;
        remember(m.reference_utime,
                 Reference{T_odom_here * m.T_reference_current.inverse(), 0, Matrix6d::Zero(), false, true});
      }
      ref = references_.find(m.reference_utime);
    }
    T_odom_camera = ref->second.T_odom_camera * m.T_reference_current;
    out.reference_utime = m.reference_utime;
    out.T_reference_camera = m.T_reference_current;
    if (m.covariance.allFinite() && !m.covariance.isZero(0.0)) {
      // Per-axis floors: isotropic in each block, so the same in any frame. Floors the
      // covariance cannot contain (negative, not finite, above its diagonal) are not taken
      // out: the whole covariance then counts per motion.
      out.floor.diagonal() << Eigen::Vector3d::Constant(m.translation_floor_m * m.translation_floor_m),
          Eigen::Vector3d::Constant(m.rotation_floor_rad * m.rotation_floor_rad);
      const bool floors_ok = std::isfinite(m.translation_floor_m) && std::isfinite(m.rotation_floor_rad) &&
                             m.translation_floor_m >= 0.0 && m.rotation_floor_rad >= 0.0 &&
                             (m.covariance.diagonal() - out.floor.diagonal()).minCoeff() >= 0.0;
      if (!floors_ok) out.floor.setZero();
      // [dp; dtheta] with dp in the reference frame -> right perturbation: rho = R^T dp.
      Matrix6d J = Matrix6d::Identity();
      J.topLeftCorner<3, 3>() = m.T_reference_current.linear().transpose();
      out.covariance = J * (m.covariance - out.floor) * J.transpose();
      out.covariance = 0.5 * (out.covariance + out.covariance.transpose()).eval();
      out.has_covariance = true;
    }
  }
  if (!T_odom_camera) {
    if (!m.new_reference) return std::nullopt;  // a failed frame: no estimate
    // A new segment: a restart after earlier poses, or the very first frame.
    broken = last_.has_value();
    T_odom_camera = last_ ? last_->T_odom_camera : m.T_body_camera;
  }
  if (m.new_reference)
    remember(m.utime, Reference{*T_odom_camera, out.reference_utime, out.covariance, out.has_covariance});
  out.T_odom_camera = *T_odom_camera;
  out.broken = broken;
  last_ = out;
  return out;
}

std::optional<Matrix6d> OdometryChain::relative_covariance(const OdometryPose& a, const OdometryPose& b) const {
  if (!b.has_covariance || a.utime >= b.utime) return std::nullopt;
  // Walk from b's reference back to a (when a is itself a reference) or to a's reference,
  // accumulating the motion z from there to b's reference and its covariance.
  Eigen::Isometry3d z = Eigen::Isometry3d::Identity();
  Matrix6d cov_z = Matrix6d::Zero();
  int64_t node = b.reference_utime;
  bool from_a = false;  // the walk reached a itself: a's own motion is part of z's path
  for (size_t steps = 0;; ++steps) {
    if (node == a.utime) {
      // a itself, unless the chain placed a reference at a's time after a break (a reference
      // forgotten and met again): a's own pose is not that one.
      if (const auto it = references_.find(node); it != references_.end() && it->second.placed_at_break)
        return std::nullopt;
      from_a = true;
      break;
    }
    if (node == a.reference_utime && node != 0) break;
    const auto it = references_.find(node);
    if (it == references_.end() || !it->second.has_covariance || it->second.parent_utime == 0 ||
        steps > kMaxReferences) {
      return std::nullopt;
    }
    const Reference& r = it->second;
    const auto parent = references_.find(r.parent_utime);
    if (parent == references_.end()) return std::nullopt;
    // x = T_parent_node; the path parent -> b's reference is x * z.
    const Eigen::Isometry3d x = parent->second.T_odom_camera.inverse() * r.T_odom_camera;
    const Matrix6d A = se3::adjoint(z.inverse());
    cov_z = A * r.covariance * A.transpose() + cov_z;
    z = x * z;
    node = r.parent_utime;
  }
  // T_a_b = x_a^-1 z y with y = b's motion from its reference (x_a = identity when the walk
  // reached a itself).
  const Eigen::Isometry3d& y = b.T_reference_camera;
  const Matrix6d Ay = se3::adjoint(y.inverse());
  Matrix6d cov = Ay * cov_z * Ay.transpose() + b.covariance;
  if (!from_a) {
    if (!a.has_covariance) return std::nullopt;
    const Eigen::Isometry3d T_a_b = a.T_reference_camera.inverse() * z * y;
    const Matrix6d Aa = se3::adjoint(T_a_b.inverse());
    cov += Aa * a.covariance * Aa.transpose();
  }
  // The per-frame pose noise of the span's two ends, as much as one motion carries.
  cov += b.floor;
  return Matrix6d(0.5 * (cov + cov.transpose()));
}

}  // namespace kestrel::slam
