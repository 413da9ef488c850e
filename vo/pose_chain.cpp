#include "vo/pose_chain.h"

namespace kestrel::vo {

std::optional<Eigen::Isometry3d> PoseChain::add(const VoResult& r) {
  std::optional<Eigen::Isometry3d> pose;
  if (r.status == VoStatus::kOk) {
    const Stamped* ref = r.reference_utime == keyframe_.utime    ? &keyframe_
                         : r.reference_utime == previous_.utime ? &previous_
                                                                : nullptr;
    // A reference the chain never saw means the stream was cut (a reset between two results):
    // no pose rather than a wrong one.
    if (ref == nullptr) return std::nullopt;
    pose = ref->T_world_camera * r.T_reference_current;
    last_ = *pose;
    previous_ = {r.utime, *pose};
  } else if (r.status == VoStatus::kNoReference) {
    pose = last_;
    previous_ = {r.utime, last_};
  } else if (r.new_reference) {
    previous_ = {r.utime, last_};  // restart after failures: continue from the last pose
  }
  if (r.new_reference) keyframe_ = {r.utime, last_};
  return pose;
}

}  // namespace kestrel::vo
