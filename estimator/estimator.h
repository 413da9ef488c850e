#pragma once
// The onboard state estimator: IMU propagation at IMU rate, visual odometry relative to a
// cloned keyframe pose, and late SLAM corrections, with either filter.
//
// Time model. The filter state is a deterministic function of the time-ordered inputs: the
// IMU stream defines "now"; every other input is an event at its own utime. The estimator
// keeps, for the last history_s seconds, the state after every IMU sample (a snapshot) and
// every event. An event that arrives late (visual odometry always does, by its processing
// time; a SLAM correction by seconds) is inserted at its utime and the states after it are
// recomputed from the snapshot before it. The result is therefore identical, bit for bit, to
// what the same inputs arriving on time would have given. Within an IMU interval, an event
// splits the step at its utime with the reading interpolated there.
//
// Keyframes. A VO update is T_refcam_curcam against its reference frame. The body pose at
// the reference's utime is cloned into the state (a clone event at that utime, inserted when
// the first update that needs it arrives) and every update against that reference is a
// relative-pose measurement between the clone and now, however long the keyframe is kept.
// When the reference is older than the history (or than the estimator), the first update
// against it becomes an anchor instead: the pose is cloned at that update, and later updates
// are measured against it through the anchor's own VO estimate.
//
// Robustness: non-finite or malformed inputs are rejected; a VO update failing the chi^2
// gate is refused, but after vo_max_gated_in_row refusals in a row the next is fused anyway
// (the filter, not the VO, is then the likely culprit); IMU samples that repeat or go
// back in time are dropped; VO failures only count (the filter keeps predicting and its
// covariance grows); gaps in the IMU add noise; everything is counted in counters().
//
// Gates (input_gate.h, InputGateOptions), before any input reaches the filter: IMU readings
// beyond the sensor's range; stamps beyond max_time_jump_s of the IMU's clock (an isolated
// one is dropped; resync_samples in a row on a new base restart the filter there with the
// samples held, unless they are ahead by no more than the history: a gap, bridged); VO and
// corrections stamped that far ahead of the IMU; VO motions faster than vo_max_speed /
// vo_max_rate over the time between their frames; corrections further than
// correction_max_jump_m from the state at their time; and VO updates against a reference the
// estimator cannot place: one older than the history that is neither a frame referenced
// before nor the keyframe the VO held before this estimator's first VO update. A refused
// input leaves the state as it was; it is counted by its reason and kept as
// last_rejection() for the operator.

#include <cmath>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/geometry/se3.h"
#include "estimator/filter.h"
#include "estimator/initializer.h"
#include "estimator/input_gate.h"
#include "estimator/inputs.h"
#include "estimator/options.h"
#include "estimator/ring.h"

namespace kestrel::estimator {

/// kDegraded: no VO fused for vo_timeout_s, the state runs on the IMU alone. (A diverged filter
/// is not reported as failed: it starts initialising again, so there is no state to publish.)
enum class Status { kInitializing, kOk, kDegraded };

struct EstimatorOutput {
  int64_t utime = 0;
  Status status = Status::kInitializing;
  NavState nav;
  Matrix15d covariance = Matrix15d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< body, bias-corrected
};

/// What happened to an input when it was handed over.
enum class Verdict {
  kAccepted,
  kInvalid,          ///< non-finite or malformed (see the message of validate_*)
  kDuplicate,        ///< same utime as one already received
  kOutOfOrder,       ///< older than the newest of its stream
  kTooOld,           ///< before the kept history
  kNotInitialized,   ///< arrived before the filter had a state
  kNoMeasurement,    ///< a VO failure: nothing to fuse, counted
  kImplausible,      ///< beyond the sensor's range, or a motion or correction no vehicle makes
  kTimeJump,         ///< stamped beyond max_time_jump_s of the estimator's clock
  kUnknownReference, ///< a VO update against a frame the estimator cannot place
};


struct EstimatorCounters {
  int64_t imu_accepted = 0, imu_invalid = 0, imu_duplicate = 0, imu_out_of_order = 0;
  int64_t imu_gaps = 0;
  int64_t vo_received = 0, vo_failed = 0, vo_invalid = 0, vo_duplicate = 0,
          vo_out_of_order = 0, vo_too_old = 0, vo_before_init = 0, vo_anchors = 0;
  int64_t vo_applied = 0, vo_gated = 0, vo_unreferenced = 0;
  int64_t vo_forced = 0;  ///< fused past the gate after vo_max_gated_in_row refusals (in vo_applied too)
  int64_t corrections_received = 0, corrections_invalid = 0, corrections_duplicate = 0,
          corrections_too_old = 0, corrections_before_init = 0;
  int64_t corrections_applied = 0, corrections_gated = 0;
  int64_t replays = 0, replayed_steps = 0, resets = 0, filter_failures = 0, init_restarts = 0;
  int64_t moving_starts = 0;  ///< initialisations on the move (no still window)
  int64_t world_alignments = 0;  ///< first corrections that moved the filter's world onto SLAM's
  int64_t gravity_updates = 0;  ///< visual only: frames levelled by the accelerometer
  // Refused by the gates (input_gate.h), by reason; the *_invalid above count all malformed
  // inputs (non-finite, not rigid), the *_bad_covariance below those of them for the covariance.
  int64_t imu_accel_range = 0, imu_gyro_range = 0;  ///< beyond the sensor's range
  int64_t imu_time_jumps = 0;  ///< stamps held as beyond max_time_jump_s (a new base's, a bridged gap's included)
  int64_t imu_resyncs = 0;     ///< restarts on a new time base of the IMU
  int64_t vo_bad_covariance = 0, vo_time_jumps = 0, vo_unknown_reference = 0, vo_implausible = 0;
  int64_t vo_resyncs = 0;      ///< visual only: restarts on a new time base of the VO
  int64_t corrections_bad_covariance = 0, corrections_time_jumps = 0, corrections_implausible = 0;
};

class Estimator {
 public:
  explicit Estimator(const EstimatorOptions& options);
  ~Estimator();
  Estimator(const Estimator&) = delete;
  Estimator& operator=(const Estimator&) = delete;

  /// Starts from a known state at `sample` (its utime and reading), instead of waiting for a
  /// still vehicle. Clears everything received before.
  void initialize(const NavState& nav, const Matrix15d& P, const ImuSample& sample);

  Verdict add_imu(const ImuSample& sample);
  Verdict add_vo(const VoUpdate& update);
  Verdict add_correction(const PoseCorrection& correction);
  /// Drops all state and history; the next IMU samples initialise again.
  void reset();

  bool initialized() const { return !history_.empty(); }
  /// Started on the move, and the VO has not yet measured velocity and tilt as well as a
  /// still start knows them (InitOptions): the filter runs, but there is no state to publish.
  bool settling() const { return settling_; }
  /// The state at the newest IMU sample; empty while initialising or settling.
  std::optional<EstimatorOutput> output() const;
  /// The full filter state (with clones) at the newest IMU sample; empty while initialising.
  const FilterState* filter_state() const;
  EstimatorCounters counters() const;
  const EstimatorOptions& options() const { return options_; }
  /// The newest IMU stamp taken (the estimator's time); -1 before the first.
  int64_t now_utime() const { return imu_clock_.newest(); }
  /// The latest refused input, and how many were refused in all (never reset).
  const std::optional<Rejection>& last_rejection() const { return last_rejection_; }
  int64_t refusals() const { return refusals_; }
  /// Restarts on a new time base of the IMU so far, and what the latest was ("" before one).
  int64_t resyncs() const { return counters_.imu_resyncs; }
  const std::string& last_resync() const { return last_resync_; }

 private:
  struct CloneSpec {
    int64_t clone_utime = 0;
    bool anchored = false;
    Eigen::Isometry3d anchor = Eigen::Isometry3d::Identity();  ///< T_refcam_anchorcam
    Matrix6d anchor_covariance = Matrix6d::Zero();
  };
  enum class EventKind { kCorrection = 0, kVo = 1, kClone = 2 };  // order at equal utime
  // kAligned: a correction that moved the filter onto SLAM's world (align_world). Its position
  // and yaw are the change of world's, and its covariance went into P with it: fusing it as
  // well would count it twice, so replays pass it by (its tilt, which gravity observes, goes
  // unused).
  enum class Outcome { kPending, kApplied, kForced, kGated, kUnreferenced, kAligned };
  struct Event {
    int64_t utime = 0;
    EventKind kind = EventKind::kVo;
    int64_t seq = 0;
    VoUpdate vo;
    PoseCorrection correction;
    Outcome outcome = Outcome::kPending;
  };
  struct Snapshot {
    ImuSample imu;
    FilterState state;
  };

  void start(const NavState& nav, const Matrix15d& P, const ImuSample& sample);
  /// Drops the filter's states, events and references, keeping the clocks and counters.
  void clear_state();
  /// A sample past the clock's gate: the range gate, then the filter.
  Verdict take_imu(const ImuSample& sample);
  /// Restarts the filter on the IMU's new time base, with the samples held on it.
  Verdict resync_imu(int64_t old_newest);
  Verdict refuse(Verdict verdict, Reason reason, std::string what);
  bool reference_known(int64_t reference_utime) const;
  void remember_reference(int64_t reference_utime);
  /// The snapshot at or before `utime` (the oldest if all are after), and the body pose there,
  /// interpolated to `utime` between it and the next.
  size_t snapshot_before(int64_t utime) const;
  Eigen::Isometry3d pose_at(int64_t utime) const;
  void insert_event(Event event);
  void replay_from(int64_t utime);
  void step(const Snapshot& previous, Snapshot& next);
  void step_filter(const Snapshot& previous, Snapshot& next);
  void apply(Event& event, FilterState& s);
  void trim();
  bool align_world(const PoseCorrection& c);
  void retire(const Event& event);
  int64_t oldest_utime() const { return history_.front().imu.utime; }
  static int64_t to_utime(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

  EstimatorOptions options_;
  std::unique_ptr<Filter> filter_;
  Initializer initializer_;
  Ring<Snapshot> history_;  // a snapshot per IMU sample, oldest first
  // Sorted by (utime, kind, seq). A deque: events retire from the front at VO rate, and a
  // vector would move the whole history of events (tens of kilobytes) each time.
  std::deque<Event> events_;
  std::map<int64_t, CloneSpec> clone_specs_;  // by VO reference utime
  int64_t next_seq_ = 0;
  TimeBase<ImuSample> imu_clock_;  // the estimator's time
  int64_t last_vo_utime_ = -1;
  int64_t first_vo_utime_ = -1;  // of the first VO update since the start (its keyframe may be older)
  std::deque<int64_t> references_;  // the latest VO references taken, newest last
  int64_t newest_reference_ = -1;
  std::optional<Rejection> last_rejection_;
  int64_t refusals_ = 0;
  std::string last_resync_;
  int64_t last_retired_vo_applied_ = -1;
  bool settling_ = false;
  bool correction_since_start_ = false;  // only the first correction may align the world
  EstimatorCounters counters_;  // inputs, and outcomes of retired events
};

}  // namespace kestrel::estimator
