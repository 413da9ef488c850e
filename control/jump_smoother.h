#pragma once
// Jumps of the estimated position, taken out of what the controller sees and let go slowly.
//
// A late SLAM correction moves the estimator's STATE at once: the loop closure of floor's loop
// moved it 0.47 m within one 5 ms step (docs/decisions/2026-12-06-control-jump-smoothing.md).
// The vehicle did not move; only its estimate did. A position controller fed that step as it
// is sees a position error of that size appear at once and answers with a jolt (0.45 m with the
// simulator's gains: a velocity set point changed by 0.54 m/s in one step).
//
// The smoother keeps, per state, the part of the position step that the mean of the two
// states' velocities does not explain, when it exceeds min_jump_m, as an offset; the controller gets the
// position less the offset (continuous) and set points plus the offset (so that "where the path
// is" is unchanged in the estimator's world). The offset then shrinks towards zero at
// release_speed_m_s, so the vehicle reaches the corrected path at that speed on top of its own
// motion. Steps smaller than min_jump_m (VO updates move the state by millimetres) pass
// unchanged; across a gap between states longer than max_gap_s the previous velocity explains
// nothing, and nothing is absorbed there (the first state after a restart or an outage). The
// offset is held within max_offset_m: the rest of a larger jump (a world change after an
// estimator's restart, a gross correction) passes, so that the follower's off-path hold still
// sees it. A state older than the last one (a replay started again) starts afresh.
//
// Invariants: |offset| <= max_offset_m; it grows only by an absorbed jump; it is zero after
// reset() and clear_offset().

#include <Eigen/Core>
#include <cstdint>
#include <optional>

namespace kestrel::control {

struct JumpSmoothingOptions {
  double min_jump_m = 0.02;         ///< smaller unexplained steps pass as they are (0: absorb all)
  double release_speed_m_s = 0.1;   ///< the offset shrinks at this speed (m/s)
  double max_gap_s = 0.1;           ///< states further apart: nothing is absorbed between them
  double max_offset_m = 0.5;        ///< the offset is held within this; the rest of a jump passes
};

class JumpSmoother {
 public:
  /// Throws std::invalid_argument for a negative bound or a non-positive speed, gap or offset.
  explicit JumpSmoother(const JumpSmoothingOptions& options = {});

  /// Takes the next state and returns the offset to take out of its position: the controller's
  /// position is position - offset. An equal utime or a non-finite state changes nothing; an
  /// older utime starts afresh (no offset, the state the last).
  const Eigen::Vector3d& update(int64_t utime, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity);

  const Eigen::Vector3d& offset() const { return offset_; }
  int jumps() const { return jumps_; }               ///< steps absorbed
  double largest_jump_m() const { return largest_; }  ///< the largest absorbed step
  double last_jump_m() const { return last_jump_; }   ///< the newest absorbed step
  /// Drops the offset and keeps the last state: a new path starts from the state as it is.
  void clear_offset() { offset_.setZero(); }
  void reset();

 private:
  struct Last {
    int64_t utime;
    Eigen::Vector3d position, velocity;
  };
  JumpSmoothingOptions options_;
  std::optional<Last> last_;
  Eigen::Vector3d offset_ = Eigen::Vector3d::Zero();
  int jumps_ = 0;
  double largest_ = 0.0;
  double last_jump_ = 0.0;
};

}  // namespace kestrel::control
