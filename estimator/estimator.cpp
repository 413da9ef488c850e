#include "estimator/estimator.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "estimator/measurements.h"

namespace kestrel::estimator {

Estimator::Estimator(const EstimatorOptions& options)
    : options_(options),
      filter_(make_filter(options.filter, options.imu, options.gravity, options.unscented)),
      initializer_(options.init, options.gravity) {}

Estimator::~Estimator() = default;

void Estimator::reset() {
  history_.clear();
  events_.clear();
  clone_specs_.clear();
  initializer_.reset();
  last_imu_utime_ = -1;
  last_vo_utime_ = -1;
  last_retired_vo_applied_ = -1;
  settling_ = false;
  correction_since_start_ = false;
  ++counters_.resets;
}

void Estimator::initialize(const NavState& nav, const Matrix15d& P, const ImuSample& sample) {
  reset();
  --counters_.resets;  // not a reset the user asked for
  start(nav, P, sample);
}

void Estimator::start(const NavState& nav, const Matrix15d& P, const ImuSample& sample) {
  Snapshot s;
  s.imu = sample;
  s.state.mean.utime = sample.utime;
  s.state.mean.nav = nav;
  s.state.P = P;
  history_.push_back() = s;
  last_imu_utime_ = sample.utime;
}

Verdict Estimator::add_imu(const ImuSample& sample) {
  try {
    validate_imu(sample, "IMU");
  } catch (const InputError&) {
    ++counters_.imu_invalid;
    return Verdict::kInvalid;
  }
  if (last_imu_utime_ >= 0 && sample.utime <= last_imu_utime_) {
    if (sample.utime == last_imu_utime_) {
      ++counters_.imu_duplicate;
      return Verdict::kDuplicate;
    }
    ++counters_.imu_out_of_order;
    return Verdict::kOutOfOrder;
  }
  ++counters_.imu_accepted;
  last_imu_utime_ = sample.utime;
  if (!initialized()) {
    const auto init = initializer_.add(sample);
    counters_.init_restarts = initializer_.restarts();
    if (init) {
      counters_.moving_starts += init->moving;
      start(init->nav, init->P, init->last);
      settling_ = init->moving;
    }
    return Verdict::kAccepted;
  }
  if (sample.utime - history_.back().imu.utime > to_utime(options_.max_imu_dt_s))
    ++counters_.imu_gaps;
  // Stepped in place at the back of the history: a snapshot is kilobytes (inline storage
  // cannot be moved), and this runs at IMU rate.
  Snapshot& next = history_.push_back();
  next.imu = sample;
  step(history_[history_.size() - 2], next);
  if (!next.state.is_valid(/*check_symmetry=*/false)) {
    history_.pop_back();
    // Divergence (absurd input or a bug): start over rather than publish garbage.
    ++counters_.filter_failures;
    const int64_t keep = last_imu_utime_;
    reset();
    --counters_.resets;
    last_imu_utime_ = keep;
    return Verdict::kAccepted;
  }
  trim();
  if (settling_) {
    // Checked at IMU rate only: a VO update lands between samples, and the next sample
    // carries its effect. Once settled, a start stays settled (no flicker at the bound).
    const auto& P = history_.back().state.P;
    const InitOptions& o = options_.init;
    settling_ = std::sqrt(P.block<3, 3>(idx::kV, idx::kV).diagonal().maxCoeff()) > o.sigma_velocity ||
                tilt_sigma(history_.back().state.mean.nav.R_world_body,
                           P.block<3, 3>(idx::kTheta, idx::kTheta)) > o.sigma_tilt;
  }
  return Verdict::kAccepted;
}

Verdict Estimator::add_vo(const VoUpdate& u) {
  ++counters_.vo_received;
  if (!u.ok) {
    ++counters_.vo_failed;
    return Verdict::kNoMeasurement;
  }
  try {
    validate_vo(u, options_.vo_noise.source == VoNoiseOptions::Source::kReported, "VO_UPDATE");
  } catch (const InputError&) {
    ++counters_.vo_invalid;
    return Verdict::kInvalid;
  }
  if (last_vo_utime_ >= 0 && u.utime <= last_vo_utime_) {
    if (u.utime == last_vo_utime_) {
      ++counters_.vo_duplicate;
      return Verdict::kDuplicate;
    }
    ++counters_.vo_out_of_order;
    return Verdict::kOutOfOrder;
  }
  last_vo_utime_ = u.utime;
  if (!initialized()) {
    ++counters_.vo_before_init;
    initializer_.add_vo(u);  // motion the IMU cannot see rules a still start out
    return Verdict::kNotInitialized;
  }
  if (u.utime <= oldest_utime()) {
    ++counters_.vo_too_old;
    return Verdict::kTooOld;
  }
  int64_t replay_time = u.utime;
  if (clone_specs_.find(u.reference_utime) == clone_specs_.end()) {
    CloneSpec spec;
    if (u.reference_utime > oldest_utime()) {
      spec.clone_utime = u.reference_utime;
    } else {
      spec.clone_utime = u.utime;
      spec.anchored = true;
      spec.anchor = u.T_refcam_curcam;
      spec.anchor_covariance = vo_noise(options_.vo_noise, u);
    }
    clone_specs_[u.reference_utime] = spec;
    Event clone;
    clone.utime = spec.clone_utime;
    clone.kind = EventKind::kClone;
    insert_event(clone);
    replay_time = spec.clone_utime;
    if (spec.anchored) {
      ++counters_.vo_anchors;
      replay_from(replay_time);
      return Verdict::kAccepted;
    }
  }
  Event e;
  e.utime = u.utime;
  e.kind = EventKind::kVo;
  e.vo = u;
  insert_event(e);
  replay_from(replay_time);
  return Verdict::kAccepted;
}

Verdict Estimator::add_correction(const PoseCorrection& c) {
  ++counters_.corrections_received;
  try {
    validate_correction(c, "SLAM_CORRECTION");
  } catch (const InputError&) {
    ++counters_.corrections_invalid;
    return Verdict::kInvalid;
  }
  if (!initialized()) {
    ++counters_.corrections_before_init;
    return Verdict::kNotInitialized;
  }
  if (c.utime <= oldest_utime()) {
    ++counters_.corrections_too_old;
    return Verdict::kTooOld;
  }
  for (Event& e : events_) {
    if (e.kind != EventKind::kCorrection || e.utime != c.utime) continue;
    if (c.revision <= e.correction.revision) {
      ++counters_.corrections_duplicate;
      return Verdict::kDuplicate;
    }
    // A newer graph revision replaces the pose for the same time, and is fused (even where
    // the one it replaces aligned the world: that one's share is then counted twice).
    e.correction = c;
    e.outcome = Outcome::kPending;
    replay_from(c.utime);
    return Verdict::kAccepted;
  }
  Event e;
  e.utime = c.utime;
  e.kind = EventKind::kCorrection;
  e.correction = c;
  if (!correction_since_start_) {
    correction_since_start_ = true;
    if (align_world(c)) {
      ++counters_.world_alignments;
      e.outcome = Outcome::kAligned;
    }
  }
  insert_event(e);
  replay_from(c.utime);
  return Verdict::kAccepted;
}

bool Estimator::align_world(const PoseCorrection& c) {
  if (!(options_.world_align_chi2 > 0.0)) return false;
  size_t k = history_.size() - 1;
  while (k > 0 && history_[k].imu.utime > c.utime) --k;
  const FilterState& s = history_[k].state;
  const Matrix6d noise = correction_noise(options_, c);
  const AbsolutePoseMeasurement m(c.T_world_body, noise);
  if (innovation(m, s).mahalanobis2() <= options_.world_align_chi2) return false;
  // The pose at the correction's time, between the IMU samples either side, is put on the
  // correction's position and yaw exactly: the correction is not fused afterwards (kAligned).
  Eigen::Isometry3d T = s.mean.nav.T_world_body();
  if (k + 1 < history_.size() && history_[k].imu.utime < c.utime) {
    const int64_t t0 = history_[k].imu.utime, t1 = history_[k + 1].imu.utime;
    T = se3::interpolate(T, history_[k + 1].state.mean.nav.T_world_body(),
                         static_cast<double>(c.utime - t0) / static_cast<double>(t1 - t0));
  }
  const Eigen::Isometry3d change = world_change(T, c.T_world_body);
  // The change is as uncertain as SLAM's pose; the filter's own uncertainty in its old world
  // stays in P too (a new filter's millimetres: conservative by that much).
  const Eigen::Matrix4d sigma = world_change_covariance(c.T_world_body, noise);
  for (size_t i = 0; i < history_.size(); ++i) {
    change_world(history_[i].state, change);
    widen_for_world_change(history_[i].state, sigma);
  }
  return true;
}

EstimatorCounters Estimator::counters() const {
  EstimatorCounters c = counters_;
  for (const Event& e : events_) {
    const bool applied = e.outcome == Outcome::kApplied || e.outcome == Outcome::kForced ||
                         e.outcome == Outcome::kAligned;
    const bool gated = e.outcome == Outcome::kGated;
    if (e.kind == EventKind::kVo) {
      c.vo_forced += e.outcome == Outcome::kForced;
      c.vo_applied += applied;
      c.vo_gated += gated;
      c.vo_unreferenced += e.outcome == Outcome::kUnreferenced;
    } else if (e.kind == EventKind::kCorrection) {
      c.corrections_applied += applied;
      c.corrections_gated += gated;
    }
  }
  return c;
}

const FilterState* Estimator::filter_state() const {
  return history_.empty() ? nullptr : &history_.back().state;
}

std::optional<EstimatorOutput> Estimator::output() const {
  if (!initialized() || settling_) return std::nullopt;
  const Snapshot& now = history_.back();
  EstimatorOutput out;
  out.utime = now.imu.utime;
  out.nav = now.state.mean.nav;
  out.covariance = now.state.P.topLeftCorner<idx::kNav, idx::kNav>();
  out.angular_velocity = now.imu.gyro - out.nav.gyro_bias;
  int64_t last_vo = last_retired_vo_applied_;
  for (const Event& e : events_)
    if (e.kind == EventKind::kVo &&
        (e.outcome == Outcome::kApplied || e.outcome == Outcome::kForced) && e.utime <= now.imu.utime)
      last_vo = std::max(last_vo, e.utime);
  const bool recent = last_vo >= 0 && now.imu.utime - last_vo <= to_utime(options_.vo_timeout_s);
  out.status = recent ? Status::kOk : Status::kDegraded;
  return out;
}

}  // namespace kestrel::estimator
