// The estimator's time machinery: events kept in time order, the states after every IMU
// sample for history_s seconds, the re-play of the states after a late event, the IMU step
// split at the events inside it, and the retirement of what falls out of the history.

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <tuple>

#include "estimator/estimator.h"

namespace kestrel::estimator {

void Estimator::insert_event(Event event) {
  event.seq = next_seq_++;
  const auto key = [](const Event& e) { return std::make_tuple(e.utime, static_cast<int>(e.kind), e.seq); };
  const auto pos = std::upper_bound(events_.begin(), events_.end(), event,
                                    [&](const Event& a, const Event& b) { return key(a) < key(b); });
  events_.insert(pos, std::move(event));
}

void Estimator::replay_from(int64_t utime) {
  if (history_.empty() || utime > history_.back().imu.utime) return;  // applied when the IMU passes
  const size_t first_after =
      history_.partition_point([utime](const Snapshot& s) { return s.imu.utime < utime; });
  const size_t j = first_after - 1;  // the snapshot before
  for (size_t k = j + 1; k < history_.size(); ++k) step(history_[k - 1], history_[k]);
  ++counters_.replays;
  counters_.replayed_steps += static_cast<int64_t>(history_.size() - j - 1);
  if (!history_.back().state.is_valid()) {
    ++counters_.filter_failures;
    clear_state();  // the clocks stay: the inputs go on
  }
}

void Estimator::step(const Snapshot& previous, Snapshot& next) {
  try {
    step_filter(previous, next);
  } catch (const std::invalid_argument&) {
    // The filter refused its own covariance (indefinite beyond rounding): mark the state
    // invalid, so the caller counts a filter failure and starts over instead of crashing.
    next.state = previous.state;
    next.state.P(0, 0) = std::numeric_limits<double>::quiet_NaN();
  }
}

void Estimator::step_filter(const Snapshot& previous, Snapshot& next) {
  FilterState& s = next.state;  // written in place (see add_imu)
  s = previous.state;
  const int64_t t0 = previous.imu.utime, t1 = next.imu.utime;
  const bool gap = t1 - t0 > to_utime(options_.max_imu_dt_s);
  ImuInterval u;
  u.gap = gap;
  u.gyro0 = previous.imu.gyro;
  u.accel0 = previous.imu.accel;
  int64_t t = t0;
  auto it = std::partition_point(events_.begin(), events_.end(),
                                 [t0](const Event& e) { return e.utime <= t0; });
  for (; it != events_.end() && it->utime <= t1; ++it) {
    if (it->utime > t) {
      const double frac = static_cast<double>(it->utime - t0) / static_cast<double>(t1 - t0);
      u.gyro1 = previous.imu.gyro + frac * (next.imu.gyro - previous.imu.gyro);
      u.accel1 = previous.imu.accel + frac * (next.imu.accel - previous.imu.accel);
      u.dt = 1e-6 * static_cast<double>(it->utime - t);
      filter_->predict(s, u);
      t = it->utime;
      s.mean.utime = t;
      u.gyro0 = u.gyro1;
      u.accel0 = u.accel1;
    }
    apply(*it, s);
  }
  if (t < t1) {
    u.gyro1 = next.imu.gyro;
    u.accel1 = next.imu.accel;
    u.dt = 1e-6 * static_cast<double>(t1 - t);
    filter_->predict(s, u);
    s.mean.utime = t1;
  }
}

void Estimator::trim() {
  const int64_t keep_from = history_.back().imu.utime - to_utime(options_.history_s);
  while (history_.size() > 2 && history_[1].imu.utime <= keep_from) history_.pop_front();
  const int64_t oldest = oldest_utime();
  const auto end_retired = std::partition_point(
      events_.begin(), events_.end(), [oldest](const Event& e) { return e.utime <= oldest; });
  for (auto it = events_.begin(); it != end_retired; ++it) retire(*it);
  events_.erase(events_.begin(), end_retired);
  const FilterMean& now = history_.back().state.mean;
  for (auto it = clone_specs_.begin(); it != clone_specs_.end();) {
    const bool gone = it->second.clone_utime <= oldest && now.find_clone(it->second.clone_utime) < 0;
    it = gone ? clone_specs_.erase(it) : std::next(it);
  }
}

void Estimator::retire(const Event& e) {
  if (e.kind == EventKind::kVo) {
    if (e.outcome == Outcome::kForced) ++counters_.vo_forced;
    if (e.outcome == Outcome::kApplied || e.outcome == Outcome::kForced) {
      ++counters_.vo_applied;
      last_retired_vo_applied_ = std::max(last_retired_vo_applied_, e.utime);
    }
    if (e.outcome == Outcome::kGated) ++counters_.vo_gated;
    if (e.outcome == Outcome::kUnreferenced) ++counters_.vo_unreferenced;
  } else if (e.kind == EventKind::kCorrection) {
    if (e.outcome == Outcome::kApplied || e.outcome == Outcome::kAligned) ++counters_.corrections_applied;
    if (e.outcome == Outcome::kGated) ++counters_.corrections_gated;
  }
}

}  // namespace kestrel::estimator
