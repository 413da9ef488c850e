#include "slam/backend/odometry_chain.h"

#include <string>

#include "common/error.h"
#include "common/geometry/se3.h"

namespace kestrel::slam {

void OdometryChain::reset() {
  references_.clear();
  last_.reset();
  last_utime_ = 0;
  pending_break_ = false;
}

std::optional<OdometryPose> OdometryChain::add(const VoMotion& m) {
  if (last_utime_ != 0 && m.utime <= last_utime_) {
    throw InputError("VO update utime " + std::to_string(m.utime) + " does not follow " + std::to_string(last_utime_));
  }
  if (m.ok && !se3::is_valid(m.T_reference_current, 1e-6)) {
    throw InputError("VO update " + std::to_string(m.utime) + ": motion is not a finite rigid transform");
  }
  last_utime_ = m.utime;

  std::optional<Eigen::Isometry3d> T_odom_camera;
  if (m.ok) {
    const auto ref = references_.find(m.reference_utime);
    if (ref != references_.end()) T_odom_camera = ref->second * m.T_reference_current;
  }
  if (!T_odom_camera) {
    if (!m.new_reference) {
      // No estimate for this frame; if the odometry lost its reference, what follows restarts.
      if (m.ok) pending_break_ = last_.has_value();
      return std::nullopt;
    }
    // A new segment: a restart after earlier poses, or the very first frame.
    pending_break_ = last_.has_value();
    T_odom_camera = last_ ? *last_ : m.T_body_camera;
  }
  if (m.new_reference) {
    references_[m.utime] = *T_odom_camera;
    while (references_.size() > kMaxReferences) references_.erase(references_.begin());
  }
  OdometryPose out{*T_odom_camera, pending_break_};
  pending_break_ = false;
  last_ = *T_odom_camera;
  return out;
}

}  // namespace kestrel::slam
