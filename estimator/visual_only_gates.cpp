// The visual-only estimator's side of the input gates (input_gate.h): its clocks (the VO's
// stamps are its time; the accelerometer's only fill the levelling buffer), refusing with a
// reason, and the restart on a new time base of the VO.

#include "estimator/visual_only.h"

#include <algorithm>
#include <cmath>

namespace kestrel::estimator {

Verdict VisualOnlyEstimator::refuse(Verdict verdict, Reason reason, std::string what) {
  count_refusal(counters_, reason);
  ++refusals_;
  last_rejection_ = Rejection{vo_clock_.newest(), reason, describe(reason, options_.gates), std::move(what)};
  return verdict;
}

void VisualOnlyEstimator::add_accel(int64_t utime, const Eigen::Vector3d& f) {
  if (!f.allFinite()) return;
  using Step = TimeBase<std::pair<int64_t, Eigen::Vector3d>>::Step;
  const int64_t newest = accel_clock_.newest();
  switch (accel_clock_.check(utime, {utime, f})) {
    case Step::kNext: take_accel(utime, f); return;
    case Step::kDuplicate:
    case Step::kOutOfOrder: return;
    case Step::kResync:
      // Readings of the old base level nothing on the new one; the frames follow the VO's clock.
      counters_.imu_time_jumps++;
      counters_.imu_resyncs++;
      accel_.clear();
      for (const auto& [t, reading] : accel_clock_.take_held()) take_accel(t, reading);
      return;
    case Step::kJump:
      refuse(Verdict::kTimeJump, Reason::kImuTimeJump,
             time_jump(options_.gates, "IMU: sample", utime, newest) + ": held as a possible new time base");
      return;
  }
}

Verdict VisualOnlyEstimator::add_vo(const VoUpdate& u) {
  counters_.vo_received++;
  if (const InputFault f = check_vo(u, options_.vo_noise.source == VoNoiseOptions::Source::kReported, "VO_UPDATE"))
    return refuse(Verdict::kInvalid,
                  f.kind == InputFault::Kind::kCovariance ? Reason::kVoCovariance : Reason::kVoInvalid, f.what);
  using Step = TimeBase<VoUpdate>::Step;
  const int64_t newest = vo_clock_.newest();
  switch (vo_clock_.check(u.utime, u)) {
    case Step::kNext: return take_vo(u);
    case Step::kDuplicate: counters_.vo_duplicate++; return Verdict::kDuplicate;
    case Step::kOutOfOrder: counters_.vo_out_of_order++; return Verdict::kOutOfOrder;
    case Step::kResync: counters_.vo_time_jumps++; return resync_vo(newest);
    case Step::kJump: break;
  }
  return refuse(Verdict::kTimeJump, Reason::kVoTimeJump,
                time_jump(options_.gates, "VO_UPDATE: update", u.utime, newest) + ": held as a possible new time base (" +
                    std::to_string(vo_clock_.resync_samples()) + " in a row restart the estimator on it)");
}

Verdict VisualOnlyEstimator::resync_vo(int64_t old_newest) {
  const std::vector<VoUpdate> held = vo_clock_.take_held();
  const int64_t first = held.front().utime;
  // A gap, not a new base, when the held updates go on from a frame kept here (the camera
  // stalled, the chain holds), or when they are ahead by no more than the history.
  const auto first_ok = std::find_if(held.begin(), held.end(), [](const VoUpdate& h) { return h.ok; });
  const bool gap = first > old_newest &&
                   ((first_ok != held.end() && find(first_ok->reference_utime) != nullptr) ||
                    !too_far_ahead(first, old_newest, std::llround(options_.history_s * 1e6)));
  Verdict verdict = Verdict::kAccepted;
  if (gap) {
    for (const VoUpdate& h : held) verdict = take_vo(h);
    return verdict;
  }
  counters_.vo_resyncs++;
  clear_state();  // the old base's frames mean nothing on the new one
  last_resync_ = "VO_UPDATE: " + std::to_string(held.size()) + " updates in a row from utime " +
                 std::to_string(first) + " are " +
                 short_number(std::abs(seconds_between(old_newest, first))) + " s " +
                 (first > old_newest ? "ahead of" : "behind") + " the old time base (utime " +
                 std::to_string(old_newest) + "): the visual-only estimator restarts on the new one";
  last_rejection_ =
      Rejection{vo_clock_.newest(), Reason::kVoResync, describe(Reason::kVoResync, options_.gates), last_resync_};
  for (const VoUpdate& h : held) verdict = take_vo(h);
  return verdict;
}

}  // namespace kestrel::estimator
