#pragma once
// The state without a gyro: for a source whose IMU is an accelerometer only (a Kinect, a TUM
// recording) or that has no IMU at all. The IMU filter has nothing to propagate with there;
// this estimator gives the same output, at the camera's rate instead of the IMU's.
//
// Pose. Each VO update T_refcam_curcam is chained onto the pose of its reference frame,
// which is an earlier frame's output: T_world_cur = T_world_ref * T_body_cam * T_refcam_curcam
// * T_cam_body. The pose covariance ([dp (world); dtheta (body)], as everywhere) is carried
// along the chain: Sigma_cur = A Sigma_ref A^T + B Q B^T, with A, B the Jacobians of the
// composition with respect to the reference pose and to the VO's motion. Frames are kept from
// the newest VO reference on (so a keyframe held for a minute chains correctly) and for
// history_s seconds (for late SLAM corrections).
//
// Velocity and angular velocity: a Kalman filter with a constant-velocity model (white
// acceleration and angular acceleration, VisualOnlyOptions), measured by the motion between
// consecutive frames divided by their interval. Its noise is the VO noise of the two frames
// (both against one reference: their errors do not cancel; the current against the previous:
// the current update's noise alone).
//
// Gaps. A frame whose VO failed, and the reference of an update whose reference frame was
// never seen (the VO restarted on a frame that failed here, or before this estimator), get a
// pose predicted with the velocity from the nearest frame, and a covariance grown by it.
// Without an applied update for vo_timeout_s the status is DEGRADED.
//
// Corrections. A SLAM correction (an absolute body pose at a past frame) is fused with the
// pose there, weighted by both covariances. The change is a rigid transform that moves every
// kept frame with it: the later ones keep the VO's motions since, and the earlier ones, which
// later updates may still be measured against (the VO's keyframe often precedes SLAM's), stay
// on the same chain, so the next state does not jump back. Covariances: a later frame keeps
// what the chain added after the correction's utime, an earlier one gets the Kalman posterior
// of the correction seen through the chain. A correction between two frames uses the pose
// interpolated there. This is first order: the chain's cross-covariances are not kept.
//
// A first correction a world away (beyond world_align_chi2) moves every kept frame and the
// velocity onto SLAM's world before it is fused, as the IMU filter does (estimator.h): this
// estimator was restarted while SLAM's map lived on.
//
// Start. The first successful update's reference frame is the world frame's origin pose:
// position and yaw from InitOptions, roll and pitch from the accelerometer readings given
// before it (the mean over init.duration_s, if their spread is that of a still sensor:
// sigma_tilt; else moving_sigma_tilt), or level with moving_sigma_tilt without any.
//
// Gravity (off by default, VisualOnlyOptions::gravity_sigma). After the start, the
// accelerometer readings up to each frame measure its tilt:
// their mean direction is the body's up, to the motion's acceleration (gravity_sigma, m/s^2,
// per reading), fused like a correction. So roll and pitch stay level however the VO's
// rotation drifts, and their sigma settles (SLAM anchors its map on a settled tilt). A mean
// whose size is off gravity by more than 2 gravity_sigma is an acceleration, and skipped.
//
// Outputs carry zero biases, with the prior sigmas of InitOptions: they are not estimated.
//
// Gates (input_gate.h), as in the IMU filter: the VO's stamps are this estimator's clock, so
// one beyond max_time_jump_s of the newest is held, and resync_samples in a row on a new base
// restart the estimator there (unless they go on from a kept frame, or are ahead by no more
// than the history: a gap, taken in order); motions faster than vo_max_speed / vo_max_rate, accelerometer readings
// beyond the sensor's range, corrections stamped that far ahead or further than
// correction_max_jump_m from the pose at their time are refused; so is an update against a
// frame older than every kept one that is not kept itself: predicting its pose would extrapolate
// the velocity over any time at all (a reference at utime 1 against TUM's stamps put STATE
// 1e8 m away).

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>

#include "common/geometry/se3.h"
#include "estimator/estimator.h"
#include "estimator/input_gate.h"
#include "estimator/inputs.h"
#include "estimator/options.h"

namespace kestrel::estimator {

class VisualOnlyEstimator {
 public:
  explicit VisualOnlyEstimator(const EstimatorOptions& options);

  /// An accelerometer reading (specific force, body frame). Readings before the first VO
  /// update level the world frame; later ones are not used.
  void add_accel(int64_t utime, const Eigen::Vector3d& specific_force_body);
  /// A VO result, in time order. kAccepted when it gave a new frame (output() is then at its
  /// utime), also for a failure, whose frame is predicted.
  Verdict add_vo(const VoUpdate& update);
  Verdict add_correction(const PoseCorrection& correction);
  void reset();

  bool initialized() const { return !frames_.empty(); }
  /// The state at the newest frame; empty before the first successful VO update.
  std::optional<EstimatorOutput> output() const;
  EstimatorCounters counters() const { return counters_; }
  /// The newest VO stamp taken (the estimator's time); -1 before the first.
  int64_t now_utime() const { return vo_clock_.newest(); }
  /// As Estimator's: the latest refused input, refusals in all, the latest restart on a new
  /// time base.
  const std::optional<Rejection>& last_rejection() const { return last_rejection_; }
  int64_t refusals() const { return refusals_; }
  int64_t resyncs() const { return counters_.vo_resyncs; }
  const std::string& last_resync() const { return last_resync_; }

 private:
  struct Frame {
    int64_t utime = 0;
    Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
    Matrix6d covariance = Matrix6d::Zero();  ///< [dp (world); dtheta (body)]
    Matrix6d vo_noise = Matrix6d::Zero();    ///< the update's own part of it (B Q B^T)
    int64_t reference_utime = -1;            ///< -1: predicted, not measured (the start: its own)
  };

  void start(const VoUpdate& first);
  /// A reading past the clock's gate: the range gate, then the buffer.
  void take_accel(int64_t utime, const Eigen::Vector3d& specific_force_body);
  /// An update past the clock's gate.
  Verdict take_vo(const VoUpdate& update);
  /// Restarts on the VO's new time base with the updates held on it.
  Verdict resync_vo(int64_t old_newest);
  /// Drops the frames, rates and readings, keeping the clocks and counters.
  void clear_state();
  Verdict refuse(Verdict verdict, Reason reason, std::string what);
  /// Fuses the accelerometer readings up to the newest frame as a measurement of its tilt.
  void level_with_gravity();
  /// Fuses a measurement (residual = H dx + noise, dx the pose error [dp; dtheta]) of the pose
  /// T_old, P_old at `at` (or between it and the frame before) and moves every kept frame.
  // T_old and P_old by value: they may be the frame's own, which the fusion moves.
  void fuse(std::deque<Frame>::iterator at, Eigen::Isometry3d T_old, Matrix6d P_old,
            const Eigen::MatrixXd& H, const Eigen::VectorXd& residual, const Eigen::MatrixXd& noise);
  /// The pose at `utime` predicted from the kept frame nearest to it.
  Frame predict(int64_t utime) const;
  /// The kept frame at exactly `utime`, or null.
  const Frame* find(int64_t utime) const;
  void push(Frame frame);
  void update_rates(const Frame& previous, const Frame& current);
  void trim();

  EstimatorOptions options_;
  std::deque<std::pair<int64_t, Eigen::Vector3d>> accel_;  // not yet used, oldest first
  std::deque<Frame> frames_;                                // oldest first
  // The constant-velocity filter, at frames_.back().utime: [v (world); omega (body)].
  Eigen::Vector3d v_world_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d omega_body_ = Eigen::Vector3d::Zero();
  Matrix6d rate_covariance_ = Matrix6d::Zero();
  int64_t newest_reference_ = -1;
  int64_t last_applied_utime_ = -1;
  TimeBase<VoUpdate> vo_clock_;  // the estimator's time
  TimeBase<std::pair<int64_t, Eigen::Vector3d>> accel_clock_;
  bool correction_since_start_ = false;  // only the first correction may change the world
  EstimatorCounters counters_;
  std::optional<Rejection> last_rejection_;
  int64_t refusals_ = 0;
  std::string last_resync_;
};

}  // namespace kestrel::estimator
