#include "control/jump_smoother.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kestrel::control {

JumpSmoother::JumpSmoother(const JumpSmoothingOptions& options) : options_(options) {
  if (!(options.min_jump_m >= 0.0)) throw std::invalid_argument("jump smoothing: the smallest jump must be >= 0");
  if (!(options.release_speed_m_s > 0.0)) throw std::invalid_argument("jump smoothing: the release speed must be > 0");
  if (!(options.max_gap_s > 0.0)) throw std::invalid_argument("jump smoothing: the longest gap must be > 0");
  if (!(options.max_offset_m > 0.0)) throw std::invalid_argument("jump smoothing: the largest offset must be > 0");
}

void JumpSmoother::reset() {
  last_.reset();
  offset_.setZero();
  jumps_ = 0;
  largest_ = last_jump_ = 0.0;
}

const Eigen::Vector3d& JumpSmoother::update(int64_t utime, const Eigen::Vector3d& position,
                                            const Eigen::Vector3d& velocity) {
  if (!position.allFinite() || !velocity.allFinite() || (last_ && utime == last_->utime)) return offset_;
  if (last_ && utime < last_->utime) {  // time went back: nothing before relates to this state
    offset_.setZero();
    last_ = Last{utime, position, velocity};
    return offset_;
  }
  if (last_) {
    const double dt = 1e-6 * static_cast<double>(utime - last_->utime);
    // Let go first (the time since the last state), then take this step's jump.
    const double norm = offset_.norm();
    const double release = options_.release_speed_m_s * dt;
    offset_ = norm > release ? Eigen::Vector3d((1.0 - release / norm) * offset_) : Eigen::Vector3d::Zero();
    if (dt <= options_.max_gap_s) {
      // The mean of the two velocities predicts the step to second order in a steady turn
      // or acceleration, so a vehicle manoeuvring hard makes no false jumps.
      const Eigen::Vector3d jump = position - last_->position - 0.5 * dt * (velocity + last_->velocity);
      const double size = jump.norm();
      if (size > options_.min_jump_m) {
        offset_ += jump;
        const double held = offset_.norm();
        if (held > options_.max_offset_m) offset_ *= options_.max_offset_m / held;
        ++jumps_;
        largest_ = std::max(largest_, size);
        last_jump_ = size;
      }
    }
  }
  last_ = Last{utime, position, velocity};
  return offset_;
}

}  // namespace kestrel::control
