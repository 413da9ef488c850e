#pragma once
// The estimator a source gets: the IMU filter (estimator.h) when its IMU has a gyro and an
// accelerometer, the visual-only estimator (visual_only.h) when it has no gyro or no IMU at
// all. The process kestrel-estimator and the offline run over a log (log_run.h) both go
// through it, so they choose, and publish, alike.
//
// EstimatorMode::kAuto decides once, from the inputs alone (so a replay decides the same):
// the first IMU reading selects the IMU filter if it has both parts, the visual-only
// estimator if it lacks the gyro; VO updates spanning visual_only.no_imu_after_s with no IMU
// reading at all select the visual-only estimator. VO updates before the decision are
// dropped (counted as vo_before_init). reset() forgets the decision.
//
// States to publish: the IMU filter gives one after every IMU sample once initialised, the
// visual-only estimator one after every VO update (a failed one included) once started.
// With await_world_s, they are INITIALIZING from the first until a SLAM correction is taken
// or await_world_s of sensor time has passed (options.h): a filter restarted while SLAM's map
// lives on is in a world of its own until SLAM's correction moves it (estimator.h). A restart
// on a new time base (input_gate.h) is a start like any other: its states await the world again.
//
// Refused inputs (input_gate.h): last_rejection() is the latest, for the operator; the process
// rethrows it to its Node, which shows DEGRADED while inputs are refused.

#include <optional>

#include "estimator/estimator.h"
#include "estimator/visual_only.h"

namespace kestrel::estimator {


/// What an input did, and the state to publish after it, if any.
struct StepResult {
  Verdict verdict = Verdict::kAccepted;
  std::optional<EstimatorOutput> state;
};

class StateEstimator {
 public:
  explicit StateEstimator(const EstimatorOptions& options);

  /// In the IMU filter's mode a reading without both parts is refused (kInvalid).
  StepResult add_imu(const ImuReading& reading);
  StepResult add_vo(const VoUpdate& update);
  Verdict add_correction(const PoseCorrection& correction);
  void reset();

  /// kAuto while undecided, else the estimator that runs.
  EstimatorMode mode() const { return mode_; }
  /// The newest state; empty while undecided, initialising or settling; INITIALIZING while
  /// it awaits SLAM's world.
  std::optional<EstimatorOutput> output() const;
  /// The IMU filter started on the move and waits for the VO (Estimator::settling()).
  bool settling() const { return mode_ == EstimatorMode::kImu && imu_filter_.settling(); }
  EstimatorCounters counters() const;
  /// IMU readings refused for a missing part (the IMU filter's mode only).
  int64_t incomplete_imu() const { return incomplete_imu_; }
  /// Inputs refused by the gates so far (both estimators; never reset), and the latest of them.
  int64_t refusals() const { return imu_filter_.refusals() + visual_.refusals(); }
  const std::optional<Rejection>& last_rejection() const;
  /// Restarts on a new time base so far (both estimators), and what the latest was.
  int64_t resyncs() const { return imu_filter_.resyncs() + visual_.resyncs(); }
  const std::string& last_resync() const;

 private:
  EstimatorOptions options_;
  EstimatorMode mode_;
  Estimator imu_filter_;
  VisualOnlyEstimator visual_;
  // A state at utime awaits SLAM's world: no correction taken yet, and not yet await_world_s
  // since the first state.
  bool awaits_world(int64_t utime) const;
  std::optional<EstimatorOutput> awaited(std::optional<EstimatorOutput> state) const;
  void note_first_state(const std::optional<EstimatorOutput>& state);
  /// After a restart on a new time base: the states await SLAM's world again.
  void note_resync(int64_t resyncs_before);

  int64_t first_vo_utime_ = -1;  // while undecided (the first IMU reading decides at once)
  int64_t first_state_utime_ = -1;  // of the first state given out
  bool world_taken_ = false;        // a SLAM correction was taken since the start
  int64_t last_undecided_vo_utime_ = -1;
  int64_t vo_before_decision_ = 0;
  int64_t incomplete_imu_ = 0;
};

}  // namespace kestrel::estimator
