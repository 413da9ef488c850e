// The IMU filter's side of the input gates (input_gate.h): refusing with a reason, the restart
// on a new time base of the IMU, which VO references the estimator can place, and the state
// at a correction's time that its plausibility is judged against.

#include <algorithm>

#include "estimator/estimator.h"

namespace kestrel::estimator {
namespace {

// References remembered beyond the history: a keyframe the VO holds for minutes is one of
// the last few it used (the VO matches against its keyframe or the frame before).
constexpr size_t kRememberedReferences = 16;

}  // namespace

Verdict Estimator::refuse(Verdict verdict, Reason reason, std::string what) {
  count_refusal(counters_, reason);
  ++refusals_;
  last_rejection_ = Rejection{imu_clock_.newest(), reason, describe(reason, options_.gates), std::move(what)};
  return verdict;
}

Verdict Estimator::resync_imu(int64_t old_newest) {
  const std::vector<ImuSample> held = imu_clock_.take_held();
  Verdict verdict = Verdict::kAccepted;
  // Ahead by no more than the history, the held samples only continue after a gap (a driver
  // stalled): bridged with the gap's noise, the states and VO of the last seconds kept.
  if (held.front().utime > old_newest && !too_far_ahead(held.front().utime, old_newest, to_utime(options_.history_s))) {
    for (const ImuSample& s : held) verdict = take_imu(s);
    return verdict;
  }
  ++counters_.imu_resyncs;
  // The old base's states, events and clones mean nothing on the new one; the VO, stamped by
  // the same source, is judged afresh too.
  clear_state();
  last_vo_utime_ = -1;
  last_resync_ = "IMU: " + std::to_string(held.size()) + " samples in a row from utime " +
                 std::to_string(held.front().utime) + " are " +
                 short_number(std::abs(seconds_between(old_newest, held.front().utime))) + " s " +
                 (held.front().utime > old_newest ? "ahead of" : "behind") + " the old time base (utime " +
                 std::to_string(old_newest) + "): the filter restarts on the new one";
  // Shown like a refusal while it lasts: what came before was refused, and the state restarts.
  last_rejection_ =
      Rejection{imu_clock_.newest(), Reason::kImuResync, describe(Reason::kImuResync, options_.gates), last_resync_};
  for (const ImuSample& s : held) verdict = take_imu(s);
  return verdict;
}

bool Estimator::reference_known(int64_t reference_utime) const {
  if (reference_utime > oldest_utime()) return true;  // the state there is kept: cloned
  if (clone_specs_.count(reference_utime)) return true;
  // The keyframe the VO held before this estimator's first VO update (a restart in flight):
  // anchored, until the VO has moved onto a frame of this estimator's (its references never
  // go back: it matches against its keyframe or the frame before, which then becomes one).
  if (first_vo_utime_ >= 0 && reference_utime < first_vo_utime_ && newest_reference_ < first_vo_utime_)
    return true;
  return std::find(references_.begin(), references_.end(), reference_utime) != references_.end();
}

void Estimator::remember_reference(int64_t reference_utime) {
  const auto it = std::find(references_.begin(), references_.end(), reference_utime);
  if (it != references_.end()) references_.erase(it);
  references_.push_back(reference_utime);
  if (references_.size() > kRememberedReferences) references_.pop_front();
  newest_reference_ = std::max(newest_reference_, reference_utime);
}

size_t Estimator::snapshot_before(int64_t utime) const {
  size_t k = history_.size() - 1;
  while (k > 0 && history_[k].imu.utime > utime) --k;
  return k;
}

Eigen::Isometry3d Estimator::pose_at(int64_t utime) const {
  const size_t k = snapshot_before(utime);
  const Eigen::Isometry3d T = history_[k].state.mean.nav.T_world_body();
  if (k + 1 >= history_.size() || history_[k].imu.utime >= utime) return T;
  const int64_t t0 = history_[k].imu.utime, t1 = history_[k + 1].imu.utime;
  return se3::interpolate(T, history_[k + 1].state.mean.nav.T_world_body(),
                          static_cast<double>(utime - t0) / static_cast<double>(t1 - t0));
}

}  // namespace kestrel::estimator
