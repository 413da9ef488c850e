#include "estimator/visual_only.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "common/time.h"
#include "estimator/filter_state.h"
#include "estimator/initializer.h"

namespace kestrel::estimator {
namespace {

// Jacobian of T_world_cur = T_world_ref * Delta with respect to the reference pose's error,
// both in [dp (world); dtheta (body)].
Matrix6d compose_jacobian(const Eigen::Matrix3d& R_world_ref, const Eigen::Isometry3d& Delta) {
  Matrix6d A = Matrix6d::Identity();
  A.block<3, 3>(0, 3) = -R_world_ref * so3::hat(Delta.translation());
  A.block<3, 3>(3, 3) = Delta.linear().transpose();
  return A;
}

}  // namespace

VisualOnlyEstimator::VisualOnlyEstimator(const EstimatorOptions& options)
    : options_(options), vo_clock_(options.gates), accel_clock_(options.gates) {}

void VisualOnlyEstimator::reset() {
  clear_state();
  accel_.clear();
  vo_clock_.reset();
  accel_clock_.reset();
  last_rejection_.reset();  // a replay's new session must not show the last one's refusals
  last_resync_.clear();
  counters_.resets++;
}

void VisualOnlyEstimator::clear_state() {
  frames_.clear();
  v_world_.setZero();
  omega_body_.setZero();
  rate_covariance_.setZero();
  newest_reference_ = last_applied_utime_ = -1;
  correction_since_start_ = false;
}

void VisualOnlyEstimator::take_accel(int64_t utime, const Eigen::Vector3d& f) {
  if (std::string why = accel_beyond_range(options_.gates, f, utime, "IMU"); !why.empty()) {
    refuse(Verdict::kImplausible, Reason::kImuAccelRange, std::move(why));
    return;
  }
  if (initialized() && utime <= frames_.back().utime) return;  // its frame has been levelled
  accel_.emplace_back(utime, f);
  // Before the start only the last init.duration_s count; after it, the readings since the
  // newest frame (each frame takes those up to it). Either way the buffer stays short.
  const int64_t keep_from = utime - static_cast<int64_t>(options_.init.duration_s * 1e6);
  while (accel_.front().first < keep_from) accel_.pop_front();
}

void VisualOnlyEstimator::start(const VoUpdate& first) {
  const InitOptions& o = options_.init;
  Eigen::Matrix3d R = Eigen::AngleAxisd(o.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  double sigma_tilt = o.moving_sigma_tilt;
  if (!accel_.empty()) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& a : accel_) mean += a.second;
    mean /= static_cast<double>(accel_.size());
    double spread = 0.0;
    for (const auto& a : accel_) spread = std::max(spread, (a.second - mean).cwiseAbs().maxCoeff());
    R = attitude_from_gravity(mean, o.yaw);
    // A still sensor's readings stay within a few sigma of their mean.
    if (accel_.size() >= 2 && spread < 3.0 * o.max_accel_std) sigma_tilt = o.sigma_tilt;
  }
  // What levelled the start is not measured again.
  while (!accel_.empty() && accel_.front().first <= first.reference_utime) accel_.pop_front();
  Frame origin;
  origin.utime = first.reference_utime;
  origin.reference_utime = origin.utime;  // given, not predicted: the first motion measures the rates
  origin.T_world_body = se3::make(R, o.position);
  origin.covariance.topLeftCorner<3, 3>().diagonal().setConstant(sq(o.sigma_position));
  origin.covariance.bottomRightCorner<3, 3>() = attitude_covariance(R, sigma_tilt, o.sigma_yaw);
  frames_.push_back(origin);
  rate_covariance_.setZero();
  rate_covariance_.topLeftCorner<3, 3>().diagonal().setConstant(sq(o.moving_sigma_velocity));
  rate_covariance_.bottomRightCorner<3, 3>().diagonal().setConstant(
      sq(options_.visual_only.sigma_angular_velocity));
}

const VisualOnlyEstimator::Frame* VisualOnlyEstimator::find(int64_t utime) const {
  const auto it = std::lower_bound(frames_.begin(), frames_.end(), utime,
                                   [](const Frame& f, int64_t t) { return f.utime < t; });
  return it != frames_.end() && it->utime == utime ? &*it : nullptr;
}

VisualOnlyEstimator::Frame VisualOnlyEstimator::predict(int64_t utime) const {
  // The newest frame at or before `utime`, or the oldest one if all are after it.
  auto it = std::upper_bound(frames_.begin(), frames_.end(), utime,
                             [](int64_t t, const Frame& f) { return t < f.utime; });
  const Frame& from = it == frames_.begin() ? frames_.front() : *std::prev(it);
  const double dt = to_seconds(utime - from.utime);
  Frame f;
  f.utime = utime;
  f.T_world_body = se3::make(from.T_world_body.linear() * so3::exp(omega_body_ * dt),
                             from.T_world_body.translation() + v_world_ * dt);
  // The rates' uncertainty over dt, and the acceleration the model does not know.
  const VisualOnlyOptions& m = options_.visual_only;
  const double a = std::abs(dt);
  f.covariance = from.covariance;
  f.covariance.topLeftCorner<3, 3>() += sq(dt) * rate_covariance_.topLeftCorner<3, 3>();
  f.covariance.bottomRightCorner<3, 3>() += sq(dt) * rate_covariance_.bottomRightCorner<3, 3>();
  f.covariance.topLeftCorner<3, 3>().diagonal().array() += sq(m.accel_noise_density) * a * a * a / 3.0;
  f.covariance.bottomRightCorner<3, 3>().diagonal().array() +=
      sq(m.angular_accel_noise_density) * a * a * a / 3.0;
  return f;
}

void VisualOnlyEstimator::push(Frame frame) {
  const VisualOnlyOptions& m = options_.visual_only;
  const Frame& previous = frames_.back();
  const double dt = to_seconds(frame.utime - previous.utime);
  rate_covariance_.topLeftCorner<3, 3>().diagonal().array() += sq(m.accel_noise_density) * dt;
  rate_covariance_.bottomRightCorner<3, 3>().diagonal().array() +=
      sq(m.angular_accel_noise_density) * dt;
  if (frame.reference_utime >= 0 && previous.reference_utime >= 0 && dt > 0.0 && dt <= 0.5)
    update_rates(previous, frame);
  frames_.push_back(std::move(frame));
  level_with_gravity();
  trim();
}

void VisualOnlyEstimator::update_rates(const Frame& previous, const Frame& current) {
  const double dt = to_seconds(current.utime - previous.utime);
  Vector6d z;
  z.head<3>() = (current.T_world_body.translation() - previous.T_world_body.translation()) / dt;
  z.tail<3>() = so3::log(previous.T_world_body.linear().transpose() * current.T_world_body.linear()) / dt;
  // Against the previous frame the update is the motion itself; two updates against one
  // reference each carry their own error, which the difference does not cancel.
  Matrix6d noise = current.vo_noise;
  if (current.reference_utime != previous.utime) noise += previous.vo_noise;
  noise /= sq(dt);
  Vector6d x;
  x << v_world_, omega_body_;
  const Matrix6d S = rate_covariance_ + noise;
  const Matrix6d K = S.ldlt().solve(rate_covariance_).transpose();  // P S^-1, P and S symmetric
  x += K * (z - x);
  rate_covariance_ = (Matrix6d::Identity() - K) * rate_covariance_;
  symmetrize(rate_covariance_);
  v_world_ = x.head<3>();
  omega_body_ = x.tail<3>();
}

void VisualOnlyEstimator::trim() {
  const int64_t history_from =
      frames_.back().utime - static_cast<int64_t>(options_.history_s * 1e6);
  const int64_t keep_from = std::min(history_from, newest_reference_);
  while (frames_.size() > 1 && frames_.front().utime < keep_from) frames_.pop_front();
}

Verdict VisualOnlyEstimator::take_vo(const VoUpdate& u) {
  if (!u.ok) {
    counters_.vo_failed++;
    if (initialized() && u.utime > frames_.back().utime) push(predict(u.utime));
    return Verdict::kNoMeasurement;
  }
  if (std::string why = implausible_motion(options_.gates, u, "VO_UPDATE"); !why.empty())
    return refuse(Verdict::kImplausible, Reason::kVoImplausible, std::move(why));
  if (!initialized()) start(u);
  if (u.utime <= frames_.back().utime) {  // an update for a frame already predicted past
    counters_.vo_too_old++;
    return Verdict::kTooOld;
  }

  const Frame* reference = find(u.reference_utime);
  if (reference == nullptr && u.reference_utime < frames_.front().utime)
    return refuse(Verdict::kUnknownReference, Reason::kVoUnknownReference,
                  "VO_UPDATE: update at utime " + std::to_string(u.utime) + " is against frame " +
                      std::to_string(u.reference_utime) + ", older than every frame kept (utime " +
                      std::to_string(frames_.front().utime) + " on): its pose cannot be placed");
  if (reference == nullptr) {
    // Never seen (the VO restarted on a frame that failed here, or before this estimator
    // started): its pose is predicted and kept, so later updates against it agree.
    Frame predicted = predict(u.reference_utime);
    const auto at = std::lower_bound(frames_.begin(), frames_.end(), predicted.utime,
                                     [](const Frame& f, int64_t t) { return f.utime < t; });
    reference = &*frames_.insert(at, predicted);
    counters_.vo_anchors++;
  }

  const Eigen::Isometry3d& T_body_camera = u.T_body_camera;
  const Eigen::Isometry3d Delta = T_body_camera * u.T_refcam_curcam * T_body_camera.inverse();
  const Eigen::Matrix3d R_ref = reference->T_world_body.linear();
  const Eigen::Matrix3d& R_bc = T_body_camera.linear();
  // The motion's error: dt = R_bc dp_cam + R_Delta [t_bc]x R_bc dtheta_cam, dtheta = R_bc dtheta_cam.
  Matrix6d B = Matrix6d::Zero();
  B.block<3, 3>(0, 0) = R_ref * R_bc;
  B.block<3, 3>(0, 3) = R_ref * Delta.linear() * so3::hat(T_body_camera.translation()) * R_bc;
  B.block<3, 3>(3, 3) = R_bc;
  const Matrix6d A = compose_jacobian(R_ref, Delta);

  Frame current;
  current.utime = u.utime;
  current.reference_utime = u.reference_utime;
  current.T_world_body = reference->T_world_body * Delta;
  current.vo_noise = B * vo_noise(options_.vo_noise, u) * B.transpose();
  current.covariance = A * reference->covariance * A.transpose() + current.vo_noise;
  symmetrize(current.covariance);
  newest_reference_ = std::max(newest_reference_, u.reference_utime);
  last_applied_utime_ = u.utime;
  counters_.vo_applied++;
  push(std::move(current));
  return Verdict::kAccepted;
}

Verdict VisualOnlyEstimator::add_correction(const PoseCorrection& c) {
  counters_.corrections_received++;
  if (const InputFault f = check_correction(c, "SLAM_CORRECTION"))
    return refuse(Verdict::kInvalid,
                  f.kind == InputFault::Kind::kCovariance ? Reason::kCorrectionCovariance
                                                          : Reason::kCorrectionInvalid,
                  f.what);
  if (!initialized()) {
    counters_.corrections_before_init++;
    return Verdict::kNotInitialized;
  }
  if (too_far_ahead(c.utime, frames_.back().utime, vo_clock_.max_jump_us()))
    return refuse(Verdict::kTimeJump, Reason::kCorrectionTimeJump,
                  time_jump(options_.gates, "SLAM_CORRECTION: correction", c.utime, frames_.back().utime) +
                      " (the newest frame's)");
  if (c.utime < frames_.front().utime || c.utime > frames_.back().utime) {
    counters_.corrections_too_old++;
    return Verdict::kTooOld;
  }
  // The pose at the correction's utime: a frame, or interpolated between two.
  const auto after = std::lower_bound(frames_.begin(), frames_.end(), c.utime,
                                      [](const Frame& f, int64_t t) { return f.utime < t; });
  Eigen::Isometry3d T;
  Matrix6d P;
  const auto pose_there = [&] {
    T = after->T_world_body;
    P = after->covariance;
    if (after->utime != c.utime) {
      const Frame& before = *std::prev(after);
      const double s = static_cast<double>(c.utime - before.utime) /
                       static_cast<double>(after->utime - before.utime);
      T = se3::interpolate(before.T_world_body, after->T_world_body, s);
      P = (1.0 - s) * before.covariance + s * after->covariance;
    }
  };
  pose_there();
  // The first correction since a start may be anywhere: it is how a restarted filter moves
  // onto SLAM's world (align below), which in a large map is far from its own origin.
  const bool first_takes_slams_world = !correction_since_start_ && options_.world_align_chi2 > 0.0;
  if (const double jump_m = (c.T_world_body.translation() - T.translation()).norm();
      !first_takes_slams_world && !(jump_m <= options_.gates.correction_max_jump_m))
    return refuse(Verdict::kImplausible, Reason::kCorrectionImplausible,
                  "SLAM_CORRECTION: correction at utime " + std::to_string(c.utime) + " is " +
                      short_number(jump_m) + " m from the pose there, beyond --correction-max-jump " +
                      short_number(options_.gates.correction_max_jump_m) + " m");
  const Matrix6d Q = correction_noise(options_, c);
  Vector6d innovation = se3::boxminus(c.T_world_body, T);
  // A first correction a world away: SLAM's map outlived the estimator before this one (as
  // in Estimator::align_world): move every kept frame and the velocity onto SLAM's world, as
  // uncertain as SLAM's pose there. The correction is then used up, not fused as well.
  if (!correction_since_start_) {
    correction_since_start_ = true;
    if (options_.world_align_chi2 > 0.0 &&
        (options_.await_world_s > 0.0 || innovation.dot((P + Q).ldlt().solve(innovation)) > options_.world_align_chi2)) {
      const Eigen::Isometry3d change = world_change(T, c.T_world_body);
      const Eigen::Matrix4d sigma = world_change_covariance(c.T_world_body, Q);
      for (Frame& f : frames_) {
        f.T_world_body = change * f.T_world_body;
        turn_world_block(f.covariance, idx::kP, change.linear());
        turn_world_block(f.vo_noise, idx::kP, change.linear());
        const Eigen::Matrix<double, 6, 4> J = world_change_jacobian(f.T_world_body.translation(), f.T_world_body.linear());
        f.covariance += J * sigma * J.transpose();
        symmetrize(f.covariance);
      }
      v_world_ = change.linear() * v_world_;
      turn_world_block(rate_covariance_, 0, change.linear());
      const Eigen::Vector3d dv_dyaw = Eigen::Vector3d::UnitZ().cross(v_world_);
      rate_covariance_.topLeftCorner<3, 3>() += sigma(3, 3) * dv_dyaw * dv_dyaw.transpose();
      counters_.world_alignments++;
      counters_.corrections_applied++;
      return Verdict::kAccepted;
    }
  }
  if (options_.correction_gate_chi2 > 0.0 &&
      innovation.dot((P + Q).ldlt().solve(innovation)) > options_.correction_gate_chi2) {
    counters_.corrections_gated++;
    return Verdict::kAccepted;
  }
  fuse(after, T, P, Eigen::MatrixXd::Identity(6, 6), innovation, Q);
  counters_.corrections_applied++;
  return Verdict::kAccepted;
}

void VisualOnlyEstimator::level_with_gravity() {
  const double sigma_a = options_.visual_only.gravity_sigma;
  const int64_t now = frames_.back().utime;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  while (!accel_.empty() && accel_.front().first <= now) {
    sum += accel_.front().second;
    ++n;
    accel_.pop_front();
  }
  if (sigma_a <= 0.0 || n == 0) return;
  const Eigen::Vector3d f = sum / n;
  // Only gravity is modelled: a reading whose size is off by more than the motion allows is
  // an acceleration, not a tilt.
  if (std::abs(f.norm() - options_.gravity) > 2.0 * sigma_a) return;
  Frame& frame = frames_.back();
  const Eigen::Vector3d up = frame.T_world_body.linear().transpose() * Eigen::Vector3d::UnitZ();
  // R = R_est Exp(dtheta): the measured up is Exp(dtheta)^T up ~ up + [up]x dtheta.
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3, 6);
  H.block<3, 3>(0, 3) = so3::hat(up);
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity() * sq(sigma_a / options_.gravity) / n;
  fuse(std::prev(frames_.end()), frame.T_world_body, frame.covariance, H, f.normalized() - up, R);
  counters_.gravity_updates++;
}

void VisualOnlyEstimator::fuse(std::deque<Frame>::iterator at, const Eigen::Isometry3d T_old,
                               const Matrix6d P_old, const Eigen::MatrixXd& H,
                               const Eigen::VectorXd& residual, const Eigen::MatrixXd& noise) {
  const Eigen::MatrixXd PHt = P_old * H.transpose();
  const Eigen::MatrixXd S = H * PHt + noise;
  const auto S_ldlt = S.ldlt();
  const Eigen::MatrixXd K = S_ldlt.solve(PHt.transpose()).transpose();
  const Eigen::Isometry3d T_new = se3::boxplus(T_old, Vector6d(K * residual));
  Matrix6d P_new = P_old - K * H * P_old;
  symmetrize(P_new);

  // Every kept frame moves rigidly with the fused pose: the later ones keep the VO's motions
  // since, and the earlier ones, which later updates may still be measured against (the VO's
  // keyframe often precedes SLAM's), stay on the same chain. Covariances: a later frame keeps
  // what the chain added after the fused one; an earlier one gets the Kalman posterior of the
  // measurement seen through the chain from it.
  const Eigen::Isometry3d move = T_new * T_old.inverse();
  const Matrix6d removed = P_new - P_old;
  for (auto f = frames_.begin(); f != frames_.end(); ++f) {
    if (f >= at) {
      const Matrix6d A = compose_jacobian(T_new.linear(), T_old.inverse() * f->T_world_body);
      f->covariance += A * removed * A.transpose();
    } else {
      const Matrix6d A = compose_jacobian(f->T_world_body.linear(), f->T_world_body.inverse() * T_old);
      const Eigen::MatrixXd PAtHt = f->covariance * A.transpose() * H.transpose();
      f->covariance -= PAtHt * S_ldlt.solve(PAtHt.transpose());
    }
    symmetrize(f->covariance);
    // Re-orthonormalised: a frame moved at every frame (the gravity's) would otherwise
    // compound the rounding of each product (by three times a step, through the inverse).
    f->T_world_body = move * f->T_world_body;
    f->T_world_body.linear() = so3::orthonormalize(f->T_world_body.linear());
  }
  v_world_ = move.linear() * v_world_;
  rate_covariance_.topLeftCorner<3, 3>() =
      move.linear() * rate_covariance_.topLeftCorner<3, 3>() * move.linear().transpose();
  rate_covariance_.topRightCorner<3, 3>() = move.linear() * rate_covariance_.topRightCorner<3, 3>();
  rate_covariance_.bottomLeftCorner<3, 3>() = rate_covariance_.topRightCorner<3, 3>().transpose();
}

std::optional<EstimatorOutput> VisualOnlyEstimator::output() const {
  if (!initialized()) return std::nullopt;
  const Frame& f = frames_.back();
  EstimatorOutput out;
  out.utime = f.utime;
  const bool stale = last_applied_utime_ < 0 ||
                     to_seconds(f.utime - last_applied_utime_) > options_.vo_timeout_s;
  out.status = stale ? Status::kDegraded : Status::kOk;
  out.nav.p_world_body = f.T_world_body.translation();
  out.nav.R_world_body = f.T_world_body.linear();
  out.nav.v_world_body = v_world_;
  out.angular_velocity = omega_body_;
  Matrix15d& P = out.covariance;
  P.block<3, 3>(idx::kP, idx::kP) = f.covariance.topLeftCorner<3, 3>();
  P.block<3, 3>(idx::kP, idx::kTheta) = f.covariance.topRightCorner<3, 3>();
  P.block<3, 3>(idx::kTheta, idx::kP) = f.covariance.bottomLeftCorner<3, 3>();
  P.block<3, 3>(idx::kTheta, idx::kTheta) = f.covariance.bottomRightCorner<3, 3>();
  P.block<3, 3>(idx::kV, idx::kV) = rate_covariance_.topLeftCorner<3, 3>();
  P.block<3, 3>(idx::kBg, idx::kBg).diagonal().setConstant(sq(options_.init.sigma_gyro_bias));
  P.block<3, 3>(idx::kBa, idx::kBa).diagonal().setConstant(sq(options_.init.sigma_accel_bias));
  return out;
}

}  // namespace kestrel::estimator
