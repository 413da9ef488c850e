#include "estimator/state_estimator.h"

#include <cmath>
#include <cstdlib>

namespace kestrel::estimator {

StateEstimator::StateEstimator(const EstimatorOptions& options)
    : options_(options), mode_(options.mode), imu_filter_(options), visual_(options) {}

void StateEstimator::reset() {
  mode_ = options_.mode;
  imu_filter_.reset();
  visual_.reset();
  first_vo_utime_ = -1;
  last_undecided_vo_utime_ = -1;
  first_state_utime_ = -1;
  world_taken_ = false;
}

void StateEstimator::note_resync(int64_t resyncs_before) {
  if (resyncs() == resyncs_before) return;
  first_state_utime_ = -1;
  world_taken_ = false;
}

const std::optional<Rejection>& StateEstimator::last_rejection() const {
  return mode_ == EstimatorMode::kVisualOnly ? visual_.last_rejection() : imu_filter_.last_rejection();
}

const std::string& StateEstimator::last_resync() const {
  return mode_ == EstimatorMode::kVisualOnly ? visual_.last_resync() : imu_filter_.last_resync();
}

void StateEstimator::note_first_state(const std::optional<EstimatorOutput>& state) {
  if (state && first_state_utime_ < 0) first_state_utime_ = state->utime;
}

bool StateEstimator::awaits_world(int64_t utime) const {
  return options_.await_world_s > 0.0 && !world_taken_ &&
         (first_state_utime_ < 0 || 1e-6 * static_cast<double>(utime - first_state_utime_) < options_.await_world_s);
}

std::optional<EstimatorOutput> StateEstimator::awaited(std::optional<EstimatorOutput> state) const {
  if (state && awaits_world(state->utime)) state->status = Status::kInitializing;
  return state;
}

StepResult StateEstimator::add_imu(const ImuReading& r) {
  if (mode_ == EstimatorMode::kAuto)
    mode_ = r.gyro ? EstimatorMode::kImu : EstimatorMode::kVisualOnly;
  StepResult result;
  if (mode_ == EstimatorMode::kVisualOnly) {
    if (r.accel) visual_.add_accel(r.utime, *r.accel);
    return result;
  }
  if (!r.complete()) {
    ++incomplete_imu_;
    result.verdict = Verdict::kInvalid;
    return result;
  }
  const int64_t resyncs_before = resyncs();
  result.verdict = imu_filter_.add_imu(r.sample());
  note_resync(resyncs_before);
  if (result.verdict == Verdict::kAccepted) {
    if (auto out = imu_filter_.output(); out && out->utime == r.utime) {
      note_first_state(out);
      result.state = awaited(std::move(out));
    }
  }
  return result;
}

StepResult StateEstimator::add_vo(const VoUpdate& u) {
  StepResult result;
  if (mode_ == EstimatorMode::kAuto) {  // still undecided: no IMU reading has come
    // The span counts on one time base: a stamp jumping beyond the bound starts it again, so
    // one outlier cannot decide.
    if (first_vo_utime_ < 0 ||
        std::abs(seconds_between(last_undecided_vo_utime_, u.utime)) > options_.gates.max_time_jump_s)
      first_vo_utime_ = u.utime;
    last_undecided_vo_utime_ = u.utime;
    const double span_s = seconds_between(first_vo_utime_, u.utime);
    if (span_s >= options_.visual_only.no_imu_after_s) mode_ = EstimatorMode::kVisualOnly;
  }
  switch (mode_) {
    case EstimatorMode::kAuto:
      ++vo_before_decision_;
      result.verdict = Verdict::kNotInitialized;
      return result;
    case EstimatorMode::kImu:
      result.verdict = imu_filter_.add_vo(u);
      return result;
    case EstimatorMode::kVisualOnly: {
      const int64_t resyncs_before = resyncs();
      result.verdict = visual_.add_vo(u);
      note_resync(resyncs_before);
      if (auto out = visual_.output(); out && out->utime == u.utime &&
          (result.verdict == Verdict::kAccepted || result.verdict == Verdict::kNoMeasurement)) {
        note_first_state(out);
        result.state = awaited(std::move(out));
      }
      return result;
    }
  }
  return result;
}

Verdict StateEstimator::add_correction(const PoseCorrection& c) {
  Verdict verdict = Verdict::kNotInitialized;
  switch (mode_) {
    case EstimatorMode::kImu: verdict = imu_filter_.add_correction(c); break;
    case EstimatorMode::kVisualOnly: verdict = visual_.add_correction(c); break;
    case EstimatorMode::kAuto: break;
  }
  if (verdict == Verdict::kAccepted) world_taken_ = true;
  return verdict;
}

std::optional<EstimatorOutput> StateEstimator::output() const {
  switch (mode_) {
    case EstimatorMode::kImu: return awaited(imu_filter_.output());
    case EstimatorMode::kVisualOnly: return awaited(visual_.output());
    case EstimatorMode::kAuto: break;
  }
  return std::nullopt;
}

EstimatorCounters StateEstimator::counters() const {
  EstimatorCounters c = mode_ == EstimatorMode::kVisualOnly ? visual_.counters() : imu_filter_.counters();
  c.vo_received += vo_before_decision_;
  c.vo_before_init += vo_before_decision_;
  c.imu_invalid += incomplete_imu_;
  return c;
}

}  // namespace kestrel::estimator
