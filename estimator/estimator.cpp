#include "estimator/estimator.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "estimator/measurements.h"

namespace kestrel::estimator {

Estimator::Estimator(const EstimatorOptions& options)
    : options_(options),
      filter_(make_filter(options.filter, options.imu, options.gravity, options.unscented)),
      initializer_(options.init, options.gravity),
      imu_clock_(options.gates) {}

Estimator::~Estimator() = default;

void Estimator::reset() {
  clear_state();
  imu_clock_.reset();
  last_vo_utime_ = -1;
  last_rejection_.reset();  // a replay's new session must not show the last one's refusals
  last_resync_.clear();
  ++counters_.resets;
}

void Estimator::clear_state() {
  history_.clear();
  events_.clear();
  clone_specs_.clear();
  initializer_.reset();
  last_retired_vo_applied_ = -1;
  settling_ = false;
  correction_since_start_ = false;
  first_vo_utime_ = -1;
  references_.clear();
  newest_reference_ = -1;
}

void Estimator::initialize(const NavState& nav, const Matrix15d& P, const ImuSample& sample) {
  reset();
  --counters_.resets;  // not a reset the user asked for
  start(nav, P, sample);
  imu_clock_.start_at(sample.utime);
}

void Estimator::start(const NavState& nav, const Matrix15d& P, const ImuSample& sample) {
  Snapshot s;
  s.imu = sample;
  s.state.mean.utime = sample.utime;
  s.state.mean.nav = nav;
  s.state.P = P;
  history_.push_back() = s;
}

Verdict Estimator::add_imu(const ImuSample& sample) {
  try {
    validate_imu(sample, "IMU");
  } catch (const InputError& e) {
    return refuse(Verdict::kInvalid, Reason::kImuInvalid, e.what());
  }
  const int64_t newest = imu_clock_.newest();
  switch (imu_clock_.check(sample.utime, sample)) {
    case TimeBase<ImuSample>::Step::kNext: return take_imu(sample);
    case TimeBase<ImuSample>::Step::kDuplicate: ++counters_.imu_duplicate; return Verdict::kDuplicate;
    case TimeBase<ImuSample>::Step::kOutOfOrder: ++counters_.imu_out_of_order; return Verdict::kOutOfOrder;
    case TimeBase<ImuSample>::Step::kResync: ++counters_.imu_time_jumps; return resync_imu(newest);
    case TimeBase<ImuSample>::Step::kJump: break;
  }
  return refuse(Verdict::kTimeJump, Reason::kImuTimeJump,
                time_jump(options_.gates, "IMU: sample", sample.utime, newest) + ": held as a possible new time base (" +
                    std::to_string(imu_clock_.resync_samples()) + " in a row restart the filter on it)");
}

Verdict Estimator::take_imu(const ImuSample& sample) {
  // The clock has moved to this sample's stamp whatever its reading: a spike does not make
  // the next sample look like a jump.
  if (std::string why = accel_beyond_range(options_.gates, sample.accel, sample.utime, "IMU"); !why.empty())
    return refuse(Verdict::kImplausible, Reason::kImuAccelRange, std::move(why));
  if (std::string why = gyro_beyond_range(options_.gates, sample.gyro, sample.utime, "IMU"); !why.empty())
    return refuse(Verdict::kImplausible, Reason::kImuGyroRange, std::move(why));
  ++counters_.imu_accepted;
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
    clear_state();
    last_vo_utime_ = -1;
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
  if (const InputFault f = check_vo(u, options_.vo_noise.source == VoNoiseOptions::Source::kReported, "VO_UPDATE"))
    return refuse(Verdict::kInvalid,
                  f.kind == InputFault::Kind::kCovariance ? Reason::kVoCovariance : Reason::kVoInvalid, f.what);
  // The IMU is the clock: VO from beyond the jump bound ahead of it would otherwise wait
  // there, and every later update be out of order against it.
  const int64_t now = imu_clock_.newest();
  if (now >= 0 && too_far_ahead(u.utime, now, imu_clock_.max_jump_us()))
    return refuse(Verdict::kTimeJump, Reason::kVoTimeJump,
                  time_jump(options_.gates, "VO_UPDATE: update", u.utime, now) + " (the IMU's)");
  if (first_vo_utime_ < 0) first_vo_utime_ = u.utime;  // a failed frame is a frame too
  if (!u.ok) {
    ++counters_.vo_failed;
    return Verdict::kNoMeasurement;
  }
  if (last_vo_utime_ >= 0 && u.utime <= last_vo_utime_) {
    if (u.utime == last_vo_utime_) {
      ++counters_.vo_duplicate;
      return Verdict::kDuplicate;
    }
    ++counters_.vo_out_of_order;
    return Verdict::kOutOfOrder;
  }
  if (std::string why = implausible_motion(options_.gates, u, "VO_UPDATE"); !why.empty())
    return refuse(Verdict::kImplausible, Reason::kVoImplausible, std::move(why));
  last_vo_utime_ = u.utime;
  if (!initialized()) {
    ++counters_.vo_before_init;
    initializer_.add_vo(u);  // motion the IMU cannot see rules a still start out
    remember_reference(u.reference_utime);
    return Verdict::kNotInitialized;
  }
  if (u.utime <= oldest_utime()) {
    ++counters_.vo_too_old;
    return Verdict::kTooOld;
  }
  if (!reference_known(u.reference_utime))
    return refuse(Verdict::kUnknownReference, Reason::kVoUnknownReference,
                  "VO_UPDATE: update at utime " + std::to_string(u.utime) + " is against frame " +
                      std::to_string(u.reference_utime) +
                      ", which this estimator cannot place: older than its history, not a frame the VO "
                      "referenced before, nor its keyframe from before this estimator's first update");
  remember_reference(u.reference_utime);
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
  if (const InputFault f = check_correction(c, "SLAM_CORRECTION"))
    return refuse(Verdict::kInvalid,
                  f.kind == InputFault::Kind::kCovariance ? Reason::kCorrectionCovariance
                                                          : Reason::kCorrectionInvalid,
                  f.what);
  const int64_t now = imu_clock_.newest();
  if (now >= 0 && too_far_ahead(c.utime, now, imu_clock_.max_jump_us()))
    return refuse(Verdict::kTimeJump, Reason::kCorrectionTimeJump,
                  time_jump(options_.gates, "SLAM_CORRECTION: correction", c.utime, now) + " (the IMU's)");
  if (!initialized()) {
    ++counters_.corrections_before_init;
    return Verdict::kNotInitialized;
  }
  if (c.utime <= oldest_utime()) {
    ++counters_.corrections_too_old;
    return Verdict::kTooOld;
  }
  // The first correction since a start may be anywhere: it is how a restarted filter moves
  // onto SLAM's world (align below), which in a large map is far from its own origin.
  const bool first_takes_slams_world = !correction_since_start_ && options_.world_align_chi2 > 0.0;
  if (const double jump_m = (c.T_world_body.translation() - pose_at(c.utime).translation()).norm();
      !first_takes_slams_world && !(jump_m <= options_.gates.correction_max_jump_m))
    return refuse(Verdict::kImplausible, Reason::kCorrectionImplausible,
                  "SLAM_CORRECTION: correction at utime " + std::to_string(c.utime) + " is " +
                      short_number(jump_m) + " m from the state there, beyond --correction-max-jump " +
                      short_number(options_.gates.correction_max_jump_m) + " m");
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
  const FilterState& s = history_[snapshot_before(c.utime)].state;
  const Matrix6d noise = correction_noise(options_, c);
  const AbsolutePoseMeasurement m(c.T_world_body, noise);
  const bool awaited = options_.await_world_s > 0.0;  // options.h: the first correction is the world
  if (!awaited && innovation(m, s).mahalanobis2() <= options_.world_align_chi2) return false;
  // The pose at the correction's time, between the IMU samples either side, is put on the
  // correction's position and yaw exactly: the correction is not fused afterwards (kAligned).
  const Eigen::Isometry3d change = world_change(pose_at(c.utime), c.T_world_body);
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
