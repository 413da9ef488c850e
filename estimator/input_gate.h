#pragma once
// The gates every input of the estimators passes before a filter sees it, beyond the checks of
// inputs.h (finite values, rigid poses, proper covariances): readings beyond the sensor's
// range, stamps beyond a jump of their stream's clock, motions no vehicle makes in the time
// between their frames (InputGateOptions). A refused input changes nothing but the counter of
// its reason (EstimatorCounters) and the estimator's last Rejection, one line for the operator.
//
// Clocks. TimeBase keeps the newest stamp of a stream. A stamp within max_time_jump_s of it is
// judged as always (next, duplicate, out of order). One beyond it, ahead or back, is held
// instead of taken, so an isolated outlier never becomes the newest stamp that every later
// input is out of order against (one IMU sample an hour ahead stopped STATE for good).
// resync_samples held stamps in a row, each after the one before by at most max_time_jump_s,
// are a new time base (a driver restarted, a log replayed from its start): the estimator then
// restarts on it with the held inputs, and says so, unless the held inputs only continue after
// a gap it can bridge (ahead by no more than its history, or VO against a frame it keeps):
// those it takes in order, late by resync_samples inputs. A stamp that continues the old base
// (within the bound of the newest) drops what was held.
// Invariants: the held inputs are in time order, each within the bound after the one before;
// newest() only moves to a stamp taken (kNext) or to the last of a new base (kResync).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "estimator/inputs.h"
#include "estimator/options.h"

namespace kestrel::estimator {

struct EstimatorCounters;  // estimator.h

/// Why an input was refused: one counter of EstimatorCounters each.
enum class Reason {
  kImuInvalid, kImuAccelRange, kImuGyroRange, kImuTimeJump, kImuResync,
  kVoInvalid, kVoCovariance, kVoTimeJump, kVoImplausible, kVoUnknownReference, kVoResync,
  kCorrectionInvalid, kCorrectionCovariance, kCorrectionTimeJump, kCorrectionImplausible,
};
/// Counts a refusal for `reason` in `c` (a resync's: imu_resyncs, vo_resyncs); a covariance
/// counts as malformed too (vo_invalid, corrections_invalid hold all malformed inputs).
void count_refusal(EstimatorCounters& c, Reason reason);
/// One line for the reason, the same for every input refused for it (a health message that
/// changes with every refused input would send a heartbeat for each).
std::string describe(Reason reason, const InputGateOptions& o);

/// Why the latest refused input was refused.
struct Rejection {
  int64_t at_utime = -1;  ///< the estimator's time then: the newest stamp of its clock
  Reason reason = Reason::kImuInvalid;
  std::string summary;    ///< describe(reason)
  std::string what;       ///< one line: the stream, the input's utime, why, the bound
};

template <class Input>
class TimeBase {
 public:
  enum class Step { kNext, kDuplicate, kOutOfOrder, kJump, kResync };

  explicit TimeBase(const InputGateOptions& o)
      : max_jump_us_(std::llround(o.max_time_jump_s * 1e6)), resync_samples_(std::max(1, o.resync_samples)) {}

  /// Judges the stamp of `input` (any int64_t: a corrupt stamp must not overflow the sums).
  Step check(int64_t utime, const Input& input) {
    if (newest_ < 0 || follows(newest_, utime)) {
      newest_ = utime;
      held_.clear();
      return Step::kNext;
    }
    if (utime == newest_) return Step::kDuplicate;
    if (follows(utime, newest_)) return Step::kOutOfOrder;
    if (!held_.empty() && !follows(held_.back().first, utime)) held_.clear();  // not the base held so far
    held_.emplace_back(utime, input);
    if (static_cast<int>(held_.size()) < resync_samples_) return Step::kJump;
    newest_ = utime;
    return Step::kResync;
  }

  /// After kResync: the inputs of the new time base, oldest first (the one just judged last).
  std::vector<Input> take_held() {
    std::vector<Input> out;
    out.reserve(held_.size());
    for (auto& h : held_) out.push_back(std::move(h.second));
    held_.clear();
    return out;
  }

  int64_t newest() const { return newest_; }  ///< -1 before the first stamp
  int64_t max_jump_us() const { return max_jump_us_; }
  int resync_samples() const { return resync_samples_; }
  /// The clock at `utime`, nothing held (a state given from outside starts there).
  void start_at(int64_t utime) {
    newest_ = utime;
    held_.clear();
  }
  void reset() { start_at(-1); }

 private:
  /// `later` is after `earlier` by at most the bound (the difference taken exactly, unsigned).
  bool follows(int64_t earlier, int64_t later) const {
    return later > earlier &&
           static_cast<uint64_t>(later) - static_cast<uint64_t>(earlier) <= static_cast<uint64_t>(max_jump_us_);
  }

  int64_t max_jump_us_;
  int resync_samples_;
  int64_t newest_ = -1;
  std::vector<std::pair<int64_t, Input>> held_;
};

/// Empty if every axis of the reading is within the sensor's range, else why (naming `what`,
/// the stream, and the sample's utime).
std::string accel_beyond_range(const InputGateOptions& o, const Eigen::Vector3d& accel, int64_t utime,
                               const std::string& what);
std::string gyro_beyond_range(const InputGateOptions& o, const Eigen::Vector3d& gyro, int64_t utime,
                              const std::string& what);
/// Empty if the body's motion in `update` (T_body_camera T_refcam_curcam T_camera_body), over
/// the time between its frames, is within vo_max_speed and vo_max_rate; else why.
std::string implausible_motion(const InputGateOptions& o, const VoUpdate& update, const std::string& what);
/// "`what` at utime U is S s ahead of (behind) the newest, utime N, beyond --max-time-jump B s".
std::string time_jump(const InputGateOptions& o, const std::string& what, int64_t utime, int64_t newest);
/// `utime` is more than the bound ahead of `newest` (no overflow for any stamp; newest >= 0).
inline bool too_far_ahead(int64_t utime, int64_t newest, int64_t max_jump_us) {
  return utime > newest &&
         static_cast<uint64_t>(utime) - static_cast<uint64_t>(newest) > static_cast<uint64_t>(max_jump_us);
}
/// b - a in seconds, without overflow for any stamps.
inline double seconds_between(int64_t a, int64_t b) {
  return 1e-6 * (static_cast<double>(b) - static_cast<double>(a));
}
/// A number for a message, to 4 significant digits however large (never 300 of them).
std::string short_number(double v);

}  // namespace kestrel::estimator
