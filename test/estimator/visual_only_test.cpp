// The visual-only estimator (no gyro) against known answers: noiseless VO chained to the true
// trajectory, a covariance that matches the spread of Monte-Carlo runs, the velocity of a
// steady motion, gaps and restarts, SLAM corrections early, late and too late, the level
// start from the accelerometer; and the choice StateEstimator makes between it and the IMU
// filter.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>

#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "estimator/eval/synthetic_vo.h"
#include "estimator/state_estimator.h"
#include "estimator/visual_only.h"
#include "test/estimator/analytic_motion.h"

namespace kestrel::estimator {
namespace {

constexpr int64_t kT0 = 1000000;
constexpr int64_t kFrameUs = 33333;

int64_t frame_utime(int k) { return kT0 + k * kFrameUs; }

// The camera looks forward and down from 10 cm ahead of the body, as on the vehicle.
Eigen::Isometry3d camera_mount() {
  const Eigen::Matrix3d R_body_camera =
      (Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished() *
      Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return se3::make(R_body_camera, Eigen::Vector3d(0.1, 0.0, -0.05));
}

// The true state at frame k: a motion that starts at the estimator's default origin
// (position 0, yaw 0, level), so its world is the estimator's.
struct Truth {
  test::AnalyticMotion motion;
  Eigen::Isometry3d origin_inverse;
  Eigen::Matrix3d R_origin;
  explicit Truth(test::AnalyticMotion m = test::AnalyticMotion::aggressive()) : motion(std::move(m)) {
    const NavState s = motion.state(0.0);
    // Keep the true tilt at the start; move the yaw and position to the options' zero.
    const double yaw = std::atan2(s.R_world_body(1, 0), s.R_world_body(0, 0));
    R_origin = Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    origin_inverse = se3::make(R_origin, -(R_origin * s.p_world_body));
  }
  Eigen::Isometry3d pose(int k) const { return origin_inverse * motion.state(test::seconds(frame_utime(k), kT0)).T_world_body(); }
  Eigen::Vector3d velocity(int k) const { return R_origin * motion.state(test::seconds(frame_utime(k), kT0)).v_world_body; }
};

// A VO stand-in whose first update is against frame 0 (the estimator's origin frame).
SyntheticVoOptions vo_options(bool noisy) {
  SyntheticVoOptions o;
  o.T_body_camera = camera_mount();
  // Independent updates: the visual-only estimator's constant-velocity model takes each
  // chained pose's noise as its own (a keyframe's common error is not modelled there).
  o.keyframe_share = 0.0;
  if (!noisy) o.sigma.setConstant(1e-12);
  return o;
}

// The options of a start that knows its pose (the tilt from a still sensor's gravity).
EstimatorOptions exact_start() {
  EstimatorOptions o;
  o.init.sigma_position = 1e-6;
  o.init.sigma_tilt = 1e-6;
  o.init.sigma_yaw = 1e-6;
  return o;
}

// Gravity as a still accelerometer at frame 0's attitude reads it: the start levels the
// world with the true tilt.
void level_start(VisualOnlyEstimator& e, const Truth& truth) {
  const Eigen::Vector3d f = truth.pose(0).linear().transpose() * Eigen::Vector3d(0, 0, kStandardGravity);
  for (int i = 10; i >= 1; --i) e.add_accel(kT0 - i * 5000, f);
}

double pose_nees(const Eigen::Isometry3d& truth, const Eigen::Isometry3d& estimate, const Matrix6d& P) {
  const Vector6d e = se3::boxminus(truth, estimate);
  return e.dot(P.ldlt().solve(e));
}

Matrix6d pose_covariance(const EstimatorOutput& out) {
  Matrix6d P;
  P << out.covariance.block<3, 3>(idx::kP, idx::kP), out.covariance.block<3, 3>(idx::kP, idx::kTheta),
      out.covariance.block<3, 3>(idx::kTheta, idx::kP), out.covariance.block<3, 3>(idx::kTheta, idx::kTheta);
  return P;
}

TEST(VisualOnly, NoiselessOdometryThroughKeyframesIsTheTrueTrajectory) {
  const Truth truth;
  VisualOnlyEstimator e(exact_start());
  level_start(e, truth);
  SyntheticVo vo(vo_options(false), 1);
  vo.next(frame_utime(0), truth.pose(0));  // frame 0 becomes the first keyframe
  double worst_m = 0.0, worst_rad = 0.0;
  for (int k = 1; k < 300; ++k) {
    ASSERT_EQ(e.add_vo(vo.next(frame_utime(k), truth.pose(k))), Verdict::kAccepted);
    const auto out = e.output();
    ASSERT_TRUE(out);
    ASSERT_EQ(out->utime, frame_utime(k));
    EXPECT_EQ(out->status, Status::kOk);
    worst_m = std::max(worst_m, (out->nav.p_world_body - truth.pose(k).translation()).norm());
    worst_rad = std::max(worst_rad, so3::angle(out->nav.R_world_body.transpose() * truth.pose(k).linear()));
  }
  // 10 s of metres and tens of degrees, through keyframes every 0.25 m or 10 degrees: the
  // chain is exact up to the start's levelling (the accelerometer's tilt is exact here).
  EXPECT_LT(worst_m, 1e-6);
  EXPECT_LT(worst_rad, 1e-6);
  EXPECT_GT(e.counters().vo_applied, 298);
}

TEST(VisualOnly, ThePoseCovarianceIsTheSpreadOfMonteCarloRuns) {
  // The chained covariance against 200 runs with noise drawn from the reported covariance:
  // the mean NEES (6 dof) of the last pose must be 6 within its 99.7 % band for 200 runs.
  const Truth truth;
  constexpr int kRuns = 200, kFrames = 90;
  // A long lever arm and a noisy rotation, so that the camera mounting's part of the
  // covariance is as large as the translation's (on the vehicle it is a tenth of it).
  SyntheticVoOptions mc_vo = vo_options(true);
  mc_vo.T_body_camera.translation() << 0.5, 0.3, -0.4;
  mc_vo.sigma.tail<3>().setConstant(0.01);
  double nees_sum = 0.0;
  for (int run = 0; run < kRuns; ++run) {
    VisualOnlyEstimator e(exact_start());
    level_start(e, truth);
    SyntheticVo vo(mc_vo, 100 + run);
    vo.next(frame_utime(0), truth.pose(0));
    for (int k = 1; k < kFrames; ++k) e.add_vo(vo.next(frame_utime(k), truth.pose(k)));
    const auto out = e.output();
    ASSERT_TRUE(out);
    nees_sum += pose_nees(truth.pose(kFrames - 1), out->nav.T_world_body(), pose_covariance(*out));
  }
  const double mean = nees_sum / kRuns;
  const double band = 3.0 * std::sqrt(2.0 * 6.0 / kRuns);
  std::cout << "mean NEES of the last pose over " << kRuns << " runs: " << mean << " (6 expected)\n";
  EXPECT_NEAR(mean, 6.0, band) << "the chain's covariance does not describe its error";
}

TEST(VisualOnly, VelocityOfASteadyMotionConvergesToTheTruth) {
  // A straight line at 0.4 m/s with a steady turn of 0.3 rad/s, noiseless VO against the
  // previous frame: the constant-velocity filter settles on the true rates.
  EstimatorOptions o;
  VisualOnlyEstimator e(o);
  const Eigen::Vector3d v(0.3, -0.2, 0.1);
  const Eigen::Vector3d w(0.0, 0.0, 0.3);
  auto pose = [&](int k) {
    const double t = k * kFrameUs * 1e-6;
    return se3::make(so3::exp(w * t), v * t);
  };
  for (int k = 1; k < 120; ++k) {
    VoUpdate u;
    u.utime = frame_utime(k);
    u.reference_utime = frame_utime(k - 1);
    u.ok = true;
    u.T_refcam_curcam = pose(k - 1).inverse() * pose(k);
    u.covariance = Matrix6d::Identity() * 1e-8;
    ASSERT_EQ(e.add_vo(u), Verdict::kAccepted);
  }
  const auto out = e.output();
  ASSERT_TRUE(out);
  // The body's velocity in the world is v rotated by nothing (the start is level and at
  // yaw 0): the chord velocity of a turning body is the true one to (w dt)^2.
  EXPECT_LT((out->nav.v_world_body - v).norm(), 2e-3);
  EXPECT_LT((out->angular_velocity - w).norm(), 1e-3);
  // The velocity's covariance is what the filter has converged to: small, but not zero.
  const double sigma_v = std::sqrt(out->covariance(idx::kV, idx::kV));
  EXPECT_GT(sigma_v, 0.0);
  EXPECT_LT(sigma_v, 0.01);
}

TEST(VisualOnly, AGapIsPredictedDegradedAndARestartAgainstAFailedFrameChainsOn) {
  // A hovering vehicle's wander: what the constant-velocity model is for (through a second
  // of aggressive flight it would be metres off, as any such model would).
  const Truth truth(test::AnalyticMotion::gentle());
  EstimatorOptions o = exact_start();
  VisualOnlyEstimator e(o);
  level_start(e, truth);
  SyntheticVo vo(vo_options(false), 1);
  vo.next(frame_utime(0), truth.pose(0));
  for (int k = 1; k < 60; ++k) e.add_vo(vo.next(frame_utime(k), truth.pose(k)));
  const Matrix6d P_before = pose_covariance(*e.output());
  // 30 failed frames (1 s, past the 0.5 s timeout): predicted, DEGRADED, growing covariance.
  for (int k = 60; k < 90; ++k) {
    VoUpdate failed;
    failed.utime = frame_utime(k);
    EXPECT_EQ(e.add_vo(failed), Verdict::kNoMeasurement);
    ASSERT_EQ(e.output()->utime, failed.utime) << "a failed frame still gets a state";
  }
  EXPECT_EQ(e.output()->status, Status::kDegraded);
  const Matrix6d P_gap = pose_covariance(*e.output());
  EXPECT_GT(P_gap.trace(), 10.0 * P_before.trace());
  const double gap_error = (e.output()->nav.p_world_body - truth.pose(89).translation()).norm();
  EXPECT_LT(gap_error, 3.0 * std::sqrt(P_gap.topLeftCorner<3, 3>().trace()) + 0.02);

  // The VO restarts on frame 90, which failed here: its pose is the prediction, and every
  // update against it chains from that same pose.
  const Eigen::Isometry3d T_keyframe = truth.pose(90);
  for (int k = 91; k < 100; ++k) {
    VoUpdate u;
    u.utime = frame_utime(k);
    u.reference_utime = frame_utime(90);
    u.ok = true;
    u.T_body_camera = camera_mount();
    u.T_refcam_curcam = (T_keyframe * camera_mount()).inverse() * truth.pose(k) * camera_mount();
    u.covariance = Matrix6d::Identity() * 1e-8;
    ASSERT_EQ(e.add_vo(u), Verdict::kAccepted);
    EXPECT_EQ(e.output()->status, Status::kOk);
  }
  EXPECT_EQ(e.counters().vo_anchors, 1);
  EXPECT_EQ(e.counters().vo_failed, 30);
}

TEST(VisualOnly, ASlamCorrectionMovesTheChainAfterItAndALateOneToo) {
  const Truth truth;
  EstimatorOptions o = exact_start();
  o.history_s = 2.0;
  VisualOnlyEstimator e(o);
  level_start(e, truth);
  SyntheticVo vo(vo_options(true), 7);
  vo.next(frame_utime(0), truth.pose(0));
  std::map<int, Eigen::Isometry3d> poses;
  for (int k = 1; k < 150; ++k) {
    e.add_vo(vo.next(frame_utime(k), truth.pose(k)));
    poses[k] = e.output()->nav.T_world_body();
  }
  const Matrix6d P_old = pose_covariance(*e.output());
  ASSERT_GT((poses.at(119).translation() - truth.pose(119).translation()).norm(), 0.005)
      << "the noisy chain should have drifted for the test to mean anything";

  // A late correction (1 s back, frame 119) at the true pose, with a covariance far below the
  // chain's: the pose there becomes the truth, and every later frame moves with it, keeping
  // the VO's motion since.
  const Eigen::Isometry3d T_old_119 = poses.at(119), T_old_149 = poses.at(149);
  PoseCorrection c;
  c.utime = frame_utime(119);
  c.T_world_body = truth.pose(119);
  c.covariance = Matrix6d::Identity() * 1e-12;
  EXPECT_EQ(e.add_correction(c), Verdict::kAccepted);
  const auto out = e.output();
  const Eigen::Isometry3d expected = truth.pose(119) * T_old_119.inverse() * T_old_149;
  EXPECT_LT((out->nav.p_world_body - expected.translation()).norm(), 1e-5);
  EXPECT_LT(so3::angle(out->nav.R_world_body.transpose() * expected.linear()), 1e-5);
  EXPECT_LT(pose_covariance(*out).trace(), P_old.trace()) << "the correction removed uncertainty";
  EXPECT_EQ(e.counters().corrections_applied, 1);
  EXPECT_EQ(e.counters().world_alignments, 0) << "a correction in the estimator's own world";
  // Older than the kept frames (2 s): refused, nothing moves.
  PoseCorrection old = c;
  old.utime = frame_utime(10);
  EXPECT_EQ(e.add_correction(old), Verdict::kTooOld);
  EXPECT_TRUE(e.output()->nav.T_world_body().isApprox(out->nav.T_world_body()));
  // A correction between two frames is applied to the pose interpolated there.
  const Eigen::Isometry3d move = truth.pose(119) * T_old_119.inverse();
  const Eigen::Isometry3d T_140 = move * poses.at(140), T_141 = move * poses.at(141);
  PoseCorrection between = c;
  between.utime = frame_utime(140) + kFrameUs / 2;
  between.T_world_body = se3::interpolate(truth.pose(140), truth.pose(141), 0.5);
  EXPECT_EQ(e.add_correction(between), Verdict::kAccepted);
  const Eigen::Isometry3d moved = between.T_world_body * se3::interpolate(T_140, T_141, 0.5).inverse() *
                                  out->nav.T_world_body();
  EXPECT_LT((e.output()->nav.p_world_body - moved.translation()).norm(), 1e-5);

  // The VO's keyframe often precedes SLAM's: an update against frame 130, from before both
  // corrections, must land on the corrected chain, not jump back by the drift.
  const Eigen::Isometry3d move2 = between.T_world_body * se3::interpolate(T_140, T_141, 0.5).inverse();
  VoUpdate u;
  u.utime = frame_utime(150);
  u.reference_utime = frame_utime(130);
  u.ok = true;
  u.T_body_camera = camera_mount();
  u.T_refcam_curcam = (truth.pose(130) * camera_mount()).inverse() * truth.pose(150) * camera_mount();
  u.covariance = Matrix6d::Identity() * 1e-8;
  ASSERT_EQ(e.add_vo(u), Verdict::kAccepted);
  const Eigen::Isometry3d chained = move2 * move * poses.at(130) * truth.pose(130).inverse() * truth.pose(150);
  EXPECT_LT((e.output()->nav.p_world_body - chained.translation()).norm(), 1e-5);
  // NaN: refused and counted.
  PoseCorrection bad = c;
  bad.T_world_body.translation().x() = std::nan("");
  EXPECT_EQ(e.add_correction(bad), Verdict::kInvalid);
}

// Restarted while SLAM's map lived on: the estimator's world (the options' origin) is not
// SLAM's, and SLAM's first correction, a world away, moves every kept frame and the velocity
// onto SLAM's world instead of being weighed against the chain's millimetres.
TEST(VisualOnly, ARestartedEstimatorMovesOntoSlamsWorldAtItsFirstCorrection) {
  const Truth truth;
  const Eigen::Isometry3d slam_world =
      se3::make(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()).toRotationMatrix(), Eigen::Vector3d(3.0, -2.0, 0.5));
  for (const bool aligned : {true, false}) {
    SCOPED_TRACE(aligned ? "aligned" : "world_align_chi2 = 0");
    EstimatorOptions o = exact_start();
    if (!aligned) o.world_align_chi2 = 0.0;
    VisualOnlyEstimator e(o);
    level_start(e, truth);
    SyntheticVo vo(vo_options(true), 11);
    vo.next(frame_utime(0), truth.pose(0));
    for (int k = 1; k < 60; ++k) e.add_vo(vo.next(frame_utime(k), truth.pose(k)));
    PoseCorrection c;
    c.utime = frame_utime(40);
    c.T_world_body = slam_world * truth.pose(40);
    c.covariance = Matrix6d::Identity() * 1e-4;
    const Matrix15d P_before = e.output()->covariance;
    EXPECT_EQ(e.add_correction(c), Verdict::kAccepted);
    EXPECT_EQ(e.counters().world_alignments, aligned ? 1 : 0);
    EXPECT_EQ(e.counters().corrections_applied, 1);
    const Matrix15d P_after = e.output()->covariance;
    const auto yaw_variance = [&](const Matrix15d& P) {
      const Eigen::Vector3d up_body = e.output()->nav.R_world_body.transpose() * Eigen::Vector3d::UnitZ();
      return up_body.dot(P.block<3, 3>(idx::kTheta, idx::kTheta) * up_body);
    };
    const double position_growth = P_after.block<3, 3>(idx::kP, idx::kP).trace() -
                                   P_before.block<3, 3>(idx::kP, idx::kP).trace();
    const double yaw_growth = yaw_variance(P_after) - yaw_variance(P_before);
    std::printf("frame 59's variance grew by %.3g m^2 (position trace), %.3g rad^2 (yaw)\n",
                position_growth, yaw_growth);
    const Eigen::Isometry3d expected = slam_world * truth.pose(59);
    const double error = (e.output()->nav.p_world_body - expected.translation()).norm();
    const Eigen::Vector3d v_error = e.output()->nav.v_world_body - slam_world.linear() * truth.velocity(59);
    std::printf("frame 59 against SLAM's world: %.4f m, velocity %.3f m/s\n", error, v_error.norm());
    if (aligned) {
      // The noisy chain's own drift over the 19 frames since (up to 1.5 m/s) is a few cm.
      EXPECT_LT(error, 0.05);
      EXPECT_LT(v_error.norm(), 0.2) << "the velocity turned with the world";
      // The newest frame is now as uncertain as SLAM's pose (1e-4 per axis) on top of what it
      // was in the old world: at least the correction's position trace and yaw variance.
      EXPECT_GT(position_growth, 3e-4 * 0.99);
      EXPECT_GT(yaw_growth, 1e-4 * 0.99);
      // Later frames chain on in SLAM's world.
      for (int k = 60; k < 70; ++k) e.add_vo(vo.next(frame_utime(k), truth.pose(k)));
      EXPECT_LT((e.output()->nav.p_world_body - (slam_world * truth.pose(69)).translation()).norm(), 0.06);
    } else {
      EXPECT_GT(error, 1.0) << "fused, the correction barely moves a chain that knows its start";
    }
  }
}

TEST(VisualOnly, TheWorldIsLevelledByTheAccelerometerAndYawAndPositionComeFromTheOptions) {
  EstimatorOptions o;
  o.init.yaw = 0.7;
  o.init.position = Eigen::Vector3d(1.0, 2.0, 0.5);
  VisualOnlyEstimator e(o);
  // A sensor rolled by 0.2 rad and pitched by -0.1: gravity's reading in its frame.
  const Eigen::Matrix3d R_true = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX())).toRotationMatrix();
  const Eigen::Vector3d f = R_true.transpose() * Eigen::Vector3d(0, 0, kStandardGravity);
  for (int i = 0; i < 50; ++i) e.add_accel(kT0 - 500000 + i * 10000, f);
  VoUpdate u;
  u.utime = kT0 + kFrameUs;
  u.reference_utime = kT0;
  u.ok = true;
  u.covariance = Matrix6d::Identity() * 1e-8;
  ASSERT_EQ(e.add_vo(u), Verdict::kAccepted);  // no motion: the frame is the origin's pose
  const auto out = e.output();
  ASSERT_TRUE(out);
  EXPECT_LT(so3::angle(out->nav.R_world_body.transpose() * R_true), 1e-9);
  EXPECT_LT((out->nav.p_world_body - o.init.position).norm(), 1e-12);
  // A still sensor: the tilt is known to sigma_tilt, not to the moving start's 0.15 rad.
  EXPECT_LT(std::sqrt(out->covariance(idx::kTheta, idx::kTheta)), 2.0 * o.init.sigma_tilt);

  // Without any accelerometer the world is the first frame's, level, with a wide tilt.
  VisualOnlyEstimator blind(o);
  ASSERT_EQ(blind.add_vo(u), Verdict::kAccepted);
  EXPECT_NEAR(std::sqrt(blind.output()->covariance(idx::kTheta, idx::kTheta)), o.init.moving_sigma_tilt, 1e-6);
}

// The VO's rotation drifts in roll (2e-4 rad a frame, 0.12 rad over 20 s, within the 3.2e-4
// rad of noise it reports); the accelerometer (the true specific force of a hovering wander,
// at 100 Hz) holds the tilt: its error stops growing, at the lag a steady drift leaves
// against a filter whose VO is trusted that much (drift / gain, ~0.02 rad), and the tilt's
// sigma settles below where SLAM anchors (0.01 rad).
TEST(VisualOnly, TheAccelerometerHoldsTheTiltWhenTheOdometryDrifts) {
  const Truth truth(test::AnalyticMotion::gentle());
  auto tilt_error = [&](const EstimatorOutput& out, int k) {
    const Eigen::Vector3d up_est = out.nav.R_world_body.transpose() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d up_true = truth.pose(k).linear().transpose() * Eigen::Vector3d::UnitZ();
    return std::acos(std::min(1.0, up_est.dot(up_true)));
  };
  struct Run {
    double error_10s = 0.0, error_20s = 0.0, sigma = 0.0;
    int64_t updates = 0;
  };
  auto run = [&](bool with_accel) {
    EstimatorOptions o = exact_start();
    o.init.sigma_tilt = 0.02;
    o.visual_only.gravity_sigma = 0.5;
    VisualOnlyEstimator e(o);
    level_start(e, truth);
    const Eigen::Isometry3d drift = se3::make(so3::exp(Eigen::Vector3d(2e-4, 0, 0)), Eigen::Vector3d::Zero());
    Run r;
    for (int k = 1; k <= 600; ++k) {
      if (with_accel) {
        for (int64_t t = frame_utime(k - 1) + 10000; t <= frame_utime(k); t += 10000)
          e.add_accel(t, truth.motion.specific_force_body(test::seconds(t, kT0)));
      }
      VoUpdate u;
      u.utime = frame_utime(k);
      u.reference_utime = frame_utime(k - 1);
      u.ok = true;
      u.T_body_camera = camera_mount();
      u.T_refcam_curcam = (truth.pose(k - 1) * camera_mount()).inverse() * truth.pose(k) * camera_mount() * drift;
      u.covariance = Matrix6d::Identity() * 1e-7;
      e.add_vo(u);
      if (k == 300) r.error_10s = tilt_error(*e.output(), k);
    }
    const auto out = e.output();
    r.error_20s = tilt_error(*out, 600);
    r.sigma = std::sqrt(std::max(out->covariance(idx::kTheta, idx::kTheta), out->covariance(idx::kTheta + 1, idx::kTheta + 1)));
    r.updates = e.counters().gravity_updates;
    return r;
  };
  const Run drifted = run(false), levelled = run(true);
  std::cout << "tilt error at 10 s / 20 s: " << drifted.error_10s << " / " << drifted.error_20s
            << " rad on the odometry alone, " << levelled.error_10s << " / " << levelled.error_20s
            << " rad with the accelerometer (sigma " << levelled.sigma << ", " << levelled.updates << " updates)\n";
  EXPECT_GT(drifted.error_20s, 0.1);
  EXPECT_EQ(drifted.updates, 0);
  EXPECT_LT(levelled.error_20s, 0.03);
  EXPECT_LT(std::abs(levelled.error_20s - levelled.error_10s), 0.005) << "the tilt error still grows";
  EXPECT_LT(levelled.sigma, 0.01);
  EXPECT_EQ(levelled.updates, 600);
}

TEST(VisualOnly, BadDuplicateAndOutOfOrderUpdatesAreRefusedAndCounted) {
  EstimatorOptions o;
  VisualOnlyEstimator e(o);
  VoUpdate u;
  u.utime = kT0 + kFrameUs;
  u.reference_utime = kT0;
  u.ok = true;
  u.covariance = Matrix6d::Identity() * 1e-6;
  VoUpdate nan = u;
  nan.T_refcam_curcam.translation().x() = std::nan("");
  EXPECT_EQ(e.add_vo(nan), Verdict::kInvalid);
  EXPECT_FALSE(e.initialized());
  VoUpdate failed;
  failed.utime = kT0;
  EXPECT_EQ(e.add_vo(failed), Verdict::kNoMeasurement);  // before the start: nothing to predict
  EXPECT_FALSE(e.initialized());
  EXPECT_EQ(e.add_vo(u), Verdict::kAccepted);
  EXPECT_EQ(e.add_vo(u), Verdict::kDuplicate);
  VoUpdate older = u;
  older.utime -= 1000;
  EXPECT_EQ(e.add_vo(older), Verdict::kOutOfOrder);
  const EstimatorCounters c = e.counters();
  EXPECT_EQ(c.vo_invalid, 1);
  EXPECT_EQ(c.vo_duplicate, 1);
  EXPECT_EQ(c.vo_out_of_order, 1);
  EXPECT_EQ(c.vo_applied, 1);
  PoseCorrection early;
  VisualOnlyEstimator fresh(o);
  EXPECT_EQ(fresh.add_correction(early), Verdict::kNotInitialized);
}

// StateEstimator: which estimator runs.
ImuReading reading(int64_t utime, bool gyro) {
  ImuReading r;
  r.utime = utime;
  r.accel = Eigen::Vector3d(0, 0, kStandardGravity);
  if (gyro) r.gyro = Eigen::Vector3d::Zero();
  return r;
}

VoUpdate still_update(int k) {
  VoUpdate u;
  u.utime = frame_utime(k);
  u.reference_utime = frame_utime(k - 1);
  u.ok = true;
  u.covariance = Matrix6d::Identity() * 1e-6;
  return u;
}

TEST(StateEstimator, AnImuWithoutAGyroSelectsTheVisualOnlyEstimatorWhichPublishesPerFrame) {
  StateEstimator e{EstimatorOptions{}};
  EXPECT_EQ(e.mode(), EstimatorMode::kAuto);
  EXPECT_FALSE(e.add_imu(reading(kT0 - 10000, false)).state);
  EXPECT_EQ(e.mode(), EstimatorMode::kVisualOnly);
  const StepResult step = e.add_vo(still_update(1));
  EXPECT_EQ(step.verdict, Verdict::kAccepted);
  ASSERT_TRUE(step.state);
  EXPECT_EQ(step.state->utime, frame_utime(1));
  e.reset();
  EXPECT_EQ(e.mode(), EstimatorMode::kAuto);
}

TEST(StateEstimator, AFullImuSelectsTheImuFilterAndTheImuModeRefusesAnAccelerometerAlone) {
  StateEstimator e{EstimatorOptions{}};
  e.add_imu(reading(kT0, true));
  EXPECT_EQ(e.mode(), EstimatorMode::kImu);
  EXPECT_EQ(e.add_imu(reading(kT0 + 5000, false)).verdict, Verdict::kInvalid);
  EXPECT_EQ(e.incomplete_imu(), 1);
  // A still IMU for the initialisation's 0.5 s: then a state after every sample.
  std::optional<EstimatorOutput> last;
  for (int i = 2; i <= 120; ++i)
    if (auto s = e.add_imu(reading(kT0 + i * 5000, true)).state) last = s;
  ASSERT_TRUE(last);
  EXPECT_EQ(last->utime, kT0 + 120 * 5000);
}

TEST(StateEstimator, VoWithNoImuAtAllSelectsTheVisualOnlyEstimatorAfterASecond) {
  EstimatorOptions o;
  StateEstimator e(o);
  int published = 0;
  for (int k = 1; k <= 60; ++k)
    if (e.add_vo(still_update(k)).state) ++published;
  EXPECT_EQ(e.mode(), EstimatorMode::kVisualOnly);
  // Frames 1..31 span 0.99999 s: dropped while undecided; from frame 32 on, a state each.
  EXPECT_EQ(published, 29);
  EXPECT_EQ(e.counters().vo_before_init, 31);
}

// --await-world: a filter (re)started beside SLAM publishes INITIALIZING states, not to be
// flown on, until SLAM's correction has given it the map's world, or for await_world_s of
// sensor time at most; then usable ones. Both estimators, through StateEstimator.
TEST(StateEstimator, StatesAwaitSlamsWorldUntilACorrectionIsTakenOrTheTimeGiven) {
  EstimatorOptions o;
  o.await_world_s = 1.0;
  PoseCorrection c;  // where the still vehicle is: the start's origin
  c.covariance = Matrix6d::Identity() * 1e-4;
  for (const bool corrected : {false, true}) {
    SCOPED_TRACE(corrected ? "a correction at 0.3 s" : "no correction");
    StateEstimator e(o);
    int64_t first = -1, usable = -1;
    for (int i = 0; i <= 600; ++i) {  // a still IMU, 3 s
      const int64_t t = kT0 + i * 5000;
      const StepResult step = e.add_imu(reading(t, true));
      if (!step.state) continue;
      if (first < 0) first = t;
      EXPECT_EQ(e.output()->status, step.state->status) << t;
      if (step.state->status == Status::kInitializing) {
        EXPECT_LT(usable, 0) << "usable, then not at " << t;
      } else if (usable < 0) {
        usable = t;
      }
      if (corrected && t == first + 300000) {
        c.utime = t - 20000;
        ASSERT_EQ(e.add_correction(c), Verdict::kAccepted);
      }
    }
    ASSERT_GE(first, 0);
    EXPECT_EQ(usable - first, corrected ? 305000 : 1000000) << "the first usable state after the first";
    e.reset();
    int64_t restarted = -1;  // a reset (a lock-step replay starting again) awaits again
    for (int i = 0; i <= 200 && restarted < 0; ++i)
      if (const StepResult step = e.add_imu(reading(kT0 + 10'000'000 + i * 5000, true)); step.state)
        restarted = step.state->status == Status::kInitializing;
    EXPECT_EQ(restarted, 1);
  }
  // The visual-only estimator (no gyro) alike; 0 (the default) publishes usable states at once.
  for (const double await : {1.0, 0.0}) {
    o.await_world_s = await;
    StateEstimator e(o);
    e.add_imu(reading(kT0 - 10000, false));
    const StepResult step = e.add_vo(still_update(1));
    ASSERT_TRUE(step.state);
    EXPECT_EQ(step.state->status == Status::kInitializing, await > 0.0);
  }
}

}  // namespace
}  // namespace kestrel::estimator
