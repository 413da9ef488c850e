#include "estimator/estimator.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

#include "common/error.h"
#include "common/geometry/so3.h"
#include "estimator/measurements.h"

namespace kestrel::estimator {
namespace {

int64_t to_utime(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

bool finite_pose(const Eigen::Isometry3d& T) { return se3::is_valid(T, 1e-6); }

bool symmetric_psd(const Matrix6d& C, bool allow_zero) {
  if (!C.allFinite()) return false;
  if ((C - C.transpose()).cwiseAbs().maxCoeff() > 1e-9 * std::max(1.0, C.cwiseAbs().maxCoeff()))
    return false;
  if (C.isZero(0.0)) return allow_zero;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(C, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().minCoeff() > 0.0;
}

// Covariance of A^-1 z from those of an anchor A = T_ref_anchor and z = T_ref_cur, treated
// as independent (conservative: both share the reference frame's errors).
Matrix6d anchored_covariance(const Eigen::Isometry3d& A, const Matrix6d& cov_A,
                             const Eigen::Isometry3d& z, const Matrix6d& cov_z) {
  const Eigen::Isometry3d rel = A.inverse() * z;
  const Eigen::Matrix3d Rt = A.linear().transpose();
  Matrix6d Jz = Matrix6d::Zero();
  Jz.topLeftCorner<3, 3>() = Rt;
  Jz.bottomRightCorner<3, 3>().setIdentity();
  Matrix6d JA = Matrix6d::Zero();
  JA.topLeftCorner<3, 3>() = -Rt;
  JA.topRightCorner<3, 3>() = so3::hat(rel.translation());
  JA.bottomRightCorner<3, 3>() = -rel.linear().transpose();
  return Jz * cov_z * Jz.transpose() + JA * cov_A * JA.transpose();
}

}  // namespace

void validate_imu(const ImuSample& s, const std::string& what) {
  if (!s.gyro.allFinite() || !s.accel.allFinite())
    throw InputError(what + ": non-finite IMU reading at utime " + std::to_string(s.utime));
  if (s.utime < 0) throw InputError(what + ": negative utime " + std::to_string(s.utime));
}

void validate_vo(const VoUpdate& u, bool need_covariance, const std::string& what) {
  if (!u.ok) return;  // a failure carries nothing to check
  if (!finite_pose(u.T_refcam_curcam) || !finite_pose(u.T_body_camera))
    throw InputError(what + ": non-finite or non-rigid pose at utime " + std::to_string(u.utime));
  if (u.reference_utime >= u.utime)
    throw InputError(what + ": reference utime " + std::to_string(u.reference_utime) +
                     " is not before the frame's " + std::to_string(u.utime));
  if (!symmetric_psd(u.covariance, !need_covariance))
    throw InputError(what + ": covariance is not symmetric positive definite at utime " +
                     std::to_string(u.utime));
}

void validate_correction(const PoseCorrection& c, const std::string& what) {
  if (!finite_pose(c.T_world_body))
    throw InputError(what + ": non-finite or non-rigid pose at utime " + std::to_string(c.utime));
  if (!symmetric_psd(c.covariance, true))
    throw InputError(what + ": covariance is not symmetric positive definite at utime " +
                     std::to_string(c.utime));
}

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
  history_.push_back(s);
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
    if (init) start(init->nav, init->P, init->last);
    return Verdict::kAccepted;
  }
  if (sample.utime - history_.back().imu.utime > to_utime(options_.max_imu_dt_s))
    ++counters_.imu_gaps;
  // Stepped in place at the back of the history: a snapshot is kilobytes (inline storage
  // cannot be moved), and this runs at IMU rate.
  history_.emplace_back();
  Snapshot& next = history_.back();
  next.imu = sample;
  step(history_[history_.size() - 2], next);
  if (!next.state.is_valid()) {
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
      spec.anchor_covariance = vo_noise(u);
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
    e.correction = c;  // a newer graph revision replaces the pose for the same time
    e.outcome = Outcome::kPending;
    replay_from(c.utime);
    return Verdict::kAccepted;
  }
  Event e;
  e.utime = c.utime;
  e.kind = EventKind::kCorrection;
  e.correction = c;
  insert_event(e);
  replay_from(c.utime);
  return Verdict::kAccepted;
}

void Estimator::insert_event(Event event) {
  event.seq = next_seq_++;
  const auto key = [](const Event& e) { return std::make_tuple(e.utime, static_cast<int>(e.kind), e.seq); };
  const auto pos = std::upper_bound(events_.begin(), events_.end(), event,
                                    [&](const Event& a, const Event& b) { return key(a) < key(b); });
  events_.insert(pos, std::move(event));
}

void Estimator::replay_from(int64_t utime) {
  if (history_.empty() || utime > history_.back().imu.utime) return;  // applied when the IMU passes
  const auto first_after = std::partition_point(
      history_.begin(), history_.end(), [utime](const Snapshot& s) { return s.imu.utime < utime; });
  const size_t j = static_cast<size_t>(first_after - history_.begin()) - 1;  // the snapshot before
  for (size_t k = j + 1; k < history_.size(); ++k) step(history_[k - 1], history_[k]);
  ++counters_.replays;
  counters_.replayed_steps += static_cast<int64_t>(history_.size() - j - 1);
  if (!history_.back().state.is_valid()) {
    ++counters_.filter_failures;
    const int64_t keep_imu = last_imu_utime_, keep_vo = last_vo_utime_;
    reset();
    --counters_.resets;
    last_imu_utime_ = keep_imu;
    last_vo_utime_ = keep_vo;
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

Matrix6d Estimator::vo_noise(const VoUpdate& u) const {
  if (options_.vo_noise.source == VoNoiseOptions::Source::kConstant)
    return options_.vo_noise.constant_sigma.array().square().matrix().asDiagonal();
  return options_.vo_noise.reported_scale * u.covariance;
}

void Estimator::apply(Event& e, FilterState& s) {
  switch (e.kind) {
    case EventKind::kClone:
      add_clone(s);
      e.outcome = Outcome::kApplied;
      return;
    case EventKind::kVo: {
      const auto spec = clone_specs_.find(e.vo.reference_utime);
      const int clone = spec == clone_specs_.end() ? -1 : s.mean.find_clone(spec->second.clone_utime);
      if (clone < 0) {
        e.outcome = Outcome::kUnreferenced;
        return;
      }
      Eigen::Isometry3d z = e.vo.T_refcam_curcam;
      Matrix6d Q = vo_noise(e.vo);
      if (spec->second.anchored) {
        Q = anchored_covariance(spec->second.anchor, spec->second.anchor_covariance, z, Q);
        z = spec->second.anchor.inverse() * z;
      }
      const RelativePoseMeasurement m(clone, z, Q, e.vo.T_body_camera);
      const int max_in_row = options_.vo_max_gated_in_row;
      const bool force = max_in_row > 0 && s.vo_gated_in_row >= max_in_row;
      const UpdateResult r = filter_->update(s, m, force ? 0.0 : options_.vo_gate_chi2);
      e.outcome = r.applied ? (force ? Outcome::kForced : Outcome::kApplied) : Outcome::kGated;
      s.vo_gated_in_row = r.applied ? 0 : s.vo_gated_in_row + 1;
      return;
    }
    case EventKind::kCorrection: {
      Matrix6d Q = e.correction.covariance;
      if (Q.isZero(0.0)) {
        Q.setZero();
        Q.diagonal() << Eigen::Vector3d::Constant(std::pow(options_.correction_sigma_position, 2)),
            Eigen::Vector3d::Constant(std::pow(options_.correction_sigma_rotation, 2));
      }
      const AbsolutePoseMeasurement m(e.correction.T_world_body, Q);
      const UpdateResult r = filter_->update(s, m, options_.correction_gate_chi2);
      e.outcome = r.applied ? Outcome::kApplied : Outcome::kGated;
      return;
    }
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
    if (e.outcome == Outcome::kApplied) ++counters_.corrections_applied;
    if (e.outcome == Outcome::kGated) ++counters_.corrections_gated;
  }
}

EstimatorCounters Estimator::counters() const {
  EstimatorCounters c = counters_;
  for (const Event& e : events_) {
    const bool applied = e.outcome == Outcome::kApplied || e.outcome == Outcome::kForced;
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
  if (!initialized()) return std::nullopt;
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
