// Every bad or unlucky input the estimator handles: each is rejected or absorbed, counted, and
// leaves a usable state behind.

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>

#include "common/error.h"
#include "common/geometry/so3.h"
#include "estimator/estimator.h"
#include "test/estimator/scenario.h"

namespace kestrel::estimator {
namespace {

using test::AnalyticMotion;
using test::ScenarioOptions;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// An estimator that has run 3 s of the gentle motion.
struct Running {
  EstimatorOptions options;
  Estimator estimator{options};
  std::vector<test::ScenarioStep> steps;
  Running() {
    steps = test::run_scenario(estimator, AnalyticMotion::gentle(), test::gentle_run(3.0));
  }
  int64_t now() const { return estimator.output()->utime; }
  FilterState state() const { return *estimator.filter_state(); }
};

bool same_state(const FilterState& a, const FilterState& b) {
  return a.mean.utime == b.mean.utime && boxminus(a.mean.nav, b.mean.nav).norm() == 0.0 &&
         Eigen::MatrixXd(a.P) == Eigen::MatrixXd(b.P);
}

VoUpdate good_vo(int64_t utime, int64_t reference) {
  VoUpdate u;
  u.utime = utime;
  u.reference_utime = reference;
  u.ok = true;
  u.covariance = Matrix6d::Identity() * 1e-5;
  return u;
}

TEST(Robustness, NonFiniteImuIsRejected) {
  Running r;
  const FilterState before = r.state();
  ImuSample s;
  s.utime = r.now() + 5000;
  s.accel = {0, 0, kNan};
  EXPECT_EQ(r.estimator.add_imu(s), Verdict::kInvalid);
  s.accel = {0, 0, 9.8};
  s.gyro = {std::numeric_limits<double>::infinity(), 0, 0};
  EXPECT_EQ(r.estimator.add_imu(s), Verdict::kInvalid);
  EXPECT_EQ(r.estimator.counters().imu_invalid, 2);
  EXPECT_TRUE(same_state(before, r.state()));
  EXPECT_THROW(validate_imu(s, "IMU"), InputError);
}

TEST(Robustness, DuplicateAndOutOfOrderImuAreDroppedAndCounted) {
  Running r;
  const FilterState before = r.state();
  ImuSample s;
  s.utime = r.now();
  s.accel = {0, 0, 9.8};
  EXPECT_EQ(r.estimator.add_imu(s), Verdict::kDuplicate);
  s.utime = r.now() - 10000;
  EXPECT_EQ(r.estimator.add_imu(s), Verdict::kOutOfOrder);
  const auto c = r.estimator.counters();
  EXPECT_EQ(c.imu_duplicate, 1);
  EXPECT_EQ(c.imu_out_of_order, 1);
  EXPECT_TRUE(same_state(before, r.state()));
}

TEST(Robustness, ImuGapIsCountedAndWidensTheCovariance) {
  // 0.3 s of IMU missing at t = 3 s, with the VO also silent over it.
  const auto in_gap = [](int64_t t) { return t > 1000000 + 3000000 && t < 1000000 + 3300000; };
  for (bool with_gap : {false, true}) {
    EstimatorOptions options;
    Estimator e(options);
    ScenarioOptions o = test::gentle_run(3.6);
    o.alter_vo = [&](VoUpdate& u) {
      if (in_gap(u.utime)) u.ok = false;
    };
    if (with_gap) o.drop_imu = [&](const ImuSample& s) { return in_gap(s.utime); };
    std::vector<double> sigma_v;
    const auto steps = test::run_scenario(e, AnalyticMotion::gentle(), o);
    double peak = 0.0;
    for (const auto& s : steps)
      if (s.output.utime > 1000000 + 3000000 && s.output.utime <= 1000000 + 3300000)
        peak = std::max(peak, std::sqrt(s.output.covariance(idx::kV, idx::kV)));
    if (with_gap) {
      EXPECT_EQ(e.counters().imu_gaps, 1);
      // 0.3 s of unknown 2 m/s^2 acceleration: about 0.6 m/s.
      EXPECT_GT(peak, 0.5 * options.imu.gap_accel_sigma * 0.3);
    } else {
      EXPECT_EQ(e.counters().imu_gaps, 0);
      EXPECT_LT(peak, 0.05);
    }
    // Once the VO is back the estimate is good again.
    EXPECT_LT((steps.back().output.nav.p_world_body - steps.back().truth.p_world_body).norm(), 0.03);
    EXPECT_EQ(steps.back().output.status, Status::kOk);
  }
}

TEST(Robustness, VoFailuresKeepPredictingWithGrowingCovariance) {
  EstimatorOptions options;
  Estimator e(options);
  ScenarioOptions o = test::gentle_run(8.0);
  const auto outage = [](int64_t t) { return t > 1000000 + 3000000 && t < 1000000 + 5000000; };
  o.alter_vo = [&](VoUpdate& u) {
    if (outage(u.utime)) u.ok = false;
  };
  const auto steps = test::run_scenario(e, AnalyticMotion::gentle(), o);
  double previous = 0.0;
  bool grew = true, degraded = false;
  double last_in_outage = 0.0, after_recovery = 1e9;
  for (const auto& s : steps) {
    const double sigma_p = std::sqrt(s.output.covariance.block<3, 3>(0, 0).trace());
    if (s.output.utime > 1000000 + 3100000 && s.output.utime < 1000000 + 5000000) {
      grew = grew && sigma_p >= previous;
      degraded = degraded || s.output.status == Status::kDegraded;
      last_in_outage = sigma_p;
      // Honest: the error stays inside the covariance it reports.
      EXPECT_LT((s.output.nav.p_world_body - s.truth.p_world_body).norm(), 4.0 * sigma_p + 1e-3);
    }
    if (s.output.utime > 1000000 + 7000000) after_recovery = std::min(after_recovery, sigma_p);
    previous = sigma_p;
  }
  EXPECT_TRUE(grew);
  EXPECT_TRUE(degraded);
  EXPECT_EQ(steps.back().output.status, Status::kOk);
  EXPECT_GT(e.counters().vo_failed, 50);
  // The VO kept its keyframe through the outage (the gentle motion never leaves it), and its
  // pose is still cloned in the state: the first update after the outage ties the position
  // back to it, so the uncertainty falls back to the keyframe's.
  EXPECT_LT(after_recovery, 0.3 * last_in_outage);
  EXPECT_LT((steps.back().output.nav.p_world_body - steps.back().truth.p_world_body).norm(), 0.01);
}

TEST(Robustness, MalformedVoIsRejected) {
  Running r;
  const FilterState before = r.state();
  const int64_t t = r.now() - 20000;
  VoUpdate u = good_vo(t, t - 100000);
  u.T_refcam_curcam.translation().x() = kNan;
  EXPECT_EQ(r.estimator.add_vo(u), Verdict::kInvalid);
  u = good_vo(t, t - 100000);
  u.T_refcam_curcam.linear() *= 1.1;  // not a rotation
  EXPECT_EQ(r.estimator.add_vo(u), Verdict::kInvalid);
  u = good_vo(t, t - 100000);
  u.covariance(0, 0) = -1.0;
  EXPECT_EQ(r.estimator.add_vo(u), Verdict::kInvalid);
  u = good_vo(t, t - 100000);
  u.covariance.setZero();  // the reported model needs a covariance
  EXPECT_EQ(r.estimator.add_vo(u), Verdict::kInvalid);
  u = good_vo(t, t + 1);  // the reference after the frame
  EXPECT_EQ(r.estimator.add_vo(u), Verdict::kInvalid);
  EXPECT_EQ(r.estimator.counters().vo_invalid, 5);
  EXPECT_TRUE(same_state(before, r.state()));
  EXPECT_THROW(validate_vo(u, true, "VO_UPDATE"), InputError);
}

TEST(Robustness, ConstantNoiseModelNeedsNoReportedCovariance) {
  EstimatorOptions options;
  options.vo_noise.source = VoNoiseOptions::Source::kConstant;
  Estimator e(options);
  ScenarioOptions o = test::gentle_run(3.0);
  o.alter_vo = [](VoUpdate& u) { u.covariance.setZero(); };
  const auto steps = test::run_scenario(e, AnalyticMotion::gentle(), o);
  EXPECT_GT(e.counters().vo_applied, 60);
  EXPECT_EQ(e.counters().vo_invalid, 0);
}

TEST(Robustness, DuplicateOutOfOrderAndStaleVoAreDropped) {
  EstimatorOptions options;
  options.history_s = 1.0;
  Estimator e(options);
  const auto steps =
      test::run_scenario(e, AnalyticMotion::gentle(), test::gentle_run(3.0));
  const int64_t now = e.output()->utime;
  EXPECT_EQ(e.add_vo(good_vo(now - 10000, now - 50000)), Verdict::kAccepted);
  EXPECT_EQ(e.add_vo(good_vo(now - 10000, now - 50000)), Verdict::kDuplicate);
  EXPECT_EQ(e.add_vo(good_vo(now - 20000, now - 50000)), Verdict::kOutOfOrder);
  const auto c = e.counters();
  EXPECT_EQ(c.vo_duplicate, 1);
  EXPECT_EQ(c.vo_out_of_order, 1);
  // A VO stream that lags by more than the history: its update is too old to place.
  Estimator lagging(options);
  ScenarioOptions o = test::gentle_run(3.0);
  o.alter_vo = [](VoUpdate& u) { u.ok = false; };
  const auto steps2 = test::run_scenario(lagging, AnalyticMotion::gentle(), o);
  EXPECT_EQ(lagging.add_vo(good_vo(1000000 + 1500000, 1000000 + 1400000)), Verdict::kTooOld);
  EXPECT_EQ(lagging.counters().vo_too_old, 1);
  VoUpdate stale = good_vo(1000000 + 500000, 1000000 + 400000);
  Estimator blank(options);
  EXPECT_EQ(blank.add_vo(stale), Verdict::kNotInitialized);
  EXPECT_EQ(blank.counters().vo_before_init, 1);
}

TEST(Robustness, InconsistentVoIsGated) {
  Running r;
  const int64_t now = r.now();
  // Claims 2 m of motion in 30 ms against a keyframe 100 ms old.
  VoUpdate u = good_vo(now - 5000, now - 105000);
  u.T_refcam_curcam.translation() = Eigen::Vector3d(2.0, 0.0, 0.0);
  const FilterState before = r.state();
  EXPECT_EQ(r.estimator.add_vo(u), Verdict::kAccepted);  // taken in, then refused by the gate
  EXPECT_EQ(r.estimator.counters().vo_gated, 1);
  EXPECT_LT((r.state().mean.nav.p_world_body - before.mean.nav.p_world_body).norm(), 0.05);
}

TEST(Robustness, MalformedOrEarlyCorrectionsAreRejected) {
  PoseCorrection c;
  c.utime = 5;
  Estimator blank(EstimatorOptions{});
  EXPECT_EQ(blank.add_correction(c), Verdict::kNotInitialized);
  Running r;
  c.utime = r.now() - 100000;
  c.T_world_body.translation().y() = kNan;
  EXPECT_EQ(r.estimator.add_correction(c), Verdict::kInvalid);
  c.T_world_body = Eigen::Isometry3d::Identity();
  c.covariance(2, 3) = 1.0;  // not symmetric
  EXPECT_EQ(r.estimator.add_correction(c), Verdict::kInvalid);
  EXPECT_EQ(r.estimator.counters().corrections_invalid, 2);
  EXPECT_THROW(validate_correction(c, "SLAM_CORRECTION"), InputError);
  // No covariance: the configured default is used.
  c.covariance.setZero();
  c.T_world_body = r.steps.back().truth.T_world_body();
  EXPECT_EQ(r.estimator.add_correction(c), Verdict::kAccepted);
  EXPECT_EQ(r.estimator.counters().corrections_applied, 1);
}

TEST(Robustness, ResetStartsOver) {
  Running r;
  r.estimator.reset();
  EXPECT_FALSE(r.estimator.output().has_value());
  EXPECT_EQ(r.estimator.counters().resets, 1);
  // Still IMU for 0.6 s initialises it again.
  test::ImuNoiseTruth truth;
  const auto imu = test::generate_imu(AnalyticMotion::still(), 200.0, 0.6, truth, 5, r.now() + 5000);
  for (const auto& s : imu.samples) r.estimator.add_imu(s);
  EXPECT_TRUE(r.estimator.output().has_value());
  EXPECT_EQ(r.estimator.output()->status, Status::kDegraded);
}

}  // namespace
}  // namespace kestrel::estimator

namespace kestrel::estimator {
namespace {

// After vo_max_gated_in_row updates refused by the gate in a row, the next is fused anyway (a
// filter gone wrong, e.g. with a gyro bias mistaken at start-up, would otherwise never see VO
// again); the count restarts after it. Off (0), the gate refuses them all.
TEST(Robustness, AfterTooManyGatedUpdatesInARowTheNextIsFused) {
  for (int max_in_row : {0, 3}) {
    Running r;
    r.options.vo_max_gated_in_row = max_in_row;
    Estimator e(r.options);
    const auto steps =
        test::run_scenario(e, AnalyticMotion::gentle(), test::gentle_run(3.0));
    const int64_t now = e.output()->utime;
    const auto gated_before = e.counters().vo_gated;
    for (int k = 0; k < 5; ++k) {
      // 2 m of motion in 30 ms: refused by the gate unless forced.
      VoUpdate u = good_vo(now - 40000 + 5000 * k, now - 300000);
      u.T_refcam_curcam.translation() = Eigen::Vector3d(2.0, 0.0, 0.0);
      EXPECT_EQ(e.add_vo(u), Verdict::kAccepted);
    }
    const auto c = e.counters();
    if (max_in_row == 0) {
      EXPECT_EQ(c.vo_gated - gated_before, 5);
      EXPECT_EQ(c.vo_forced, 0);
    } else {
      EXPECT_EQ(c.vo_gated - gated_before, 4);  // 3 refused, the 4th forced, the 5th refused
      EXPECT_EQ(c.vo_forced, 1);
      EXPECT_GT((e.output()->nav.p_world_body - steps.back().output.nav.p_world_body).norm(), 0.05);
    }
  }
}

}  // namespace
}  // namespace kestrel::estimator
