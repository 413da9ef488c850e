#include "tools/eval/vo_chain.h"

#include <stdexcept>

namespace kestrel::eval {

void VoChain::add(const VoStep& step) {
  if (!frame_utimes_.empty() && step.utime <= frame_utimes_.back())
    throw std::invalid_argument("VoChain::add: utime not after the previous frame's");
  frame_utimes_.push_back(step.utime);

  if (step.valid) {
    Eigen::Isometry3d T_world_reference = Eigen::Isometry3d::Identity();
    if (const auto known = trajectory_.at(step.reference_utime, 0)) {
      T_world_reference = *known;
    } else if (!trajectory_.empty()) {
      T_world_reference = trajectory_.poses().back().T;
      ++unknown_reference_;
    }
    trajectory_.push_back(step.utime, T_world_reference * step.T_reference_current);
  } else if (step.no_reference && trajectory_.empty()) {
    trajectory_.push_back(step.utime, Eigen::Isometry3d::Identity());
  } else {
    ++without_estimate_;
  }
}

}  // namespace kestrel::eval
