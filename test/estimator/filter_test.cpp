// The two filters on exact synthetic motion: a noiseless IMU integrates to the true
// trajectory, and the EKF and the UKF agree where the problem is close to linear.

#include <gtest/gtest.h>

#include <random>

#include "common/geometry/so3.h"
#include "estimator/filter.h"
#include "test/estimator/analytic_motion.h"

namespace kestrel::estimator {
namespace {

using test::AnalyticMotion;

ImuInterval interval(const ImuSample& a, const ImuSample& b) {
  ImuInterval u;
  u.dt = 1e-6 * static_cast<double>(b.utime - a.utime);
  u.gyro0 = a.gyro;
  u.accel0 = a.accel;
  u.gyro1 = b.gyro;
  u.accel1 = b.accel;
  return u;
}

FilterState start_state(const NavState& nav) {
  FilterState s;
  s.mean.nav = nav;
  s.P = Covariance::Zero(15, 15);
  s.P.diagonal() << Eigen::Vector3d::Constant(1e-6), Eigen::Vector3d::Constant(1e-4),
      Eigen::Vector3d::Constant(1e-6), Eigen::Vector3d::Constant(1e-8),
      Eigen::Vector3d::Constant(1e-4);
  return s;
}

TEST(Filter, NoiselessImuReproducesTheTrueTrajectory) {
  // 20 s of the aggressive motion (metres, tens of degrees, up to ~1.5 m/s) at 200 Hz,
  // integrated open loop from the true start. The integrator's own error must stay far below
  // what the noise of a real IMU does over the same time: under a tenth of the standard
  // deviations the filter's covariance (with the default noise model) predicts, at every step.
  const AnalyticMotion motion = AnalyticMotion::aggressive();
  test::ImuNoiseTruth truth;
  truth.add_noise = false;
  const double duration = 20.0;
  const auto imu = test::generate_imu(motion, 200.0, duration, truth, 1);
  for (FilterKind kind : {FilterKind::kEkf, FilterKind::kUkf}) {
    const auto filter = make_filter(kind, ImuNoise{}, kStandardGravity, {});
    FilterState s = start_state(motion.state(0.0));
    s.P.setZero();  // the start is exact: the covariance is the IMU noise's alone
    double worst_p = 0.0, worst_v = 0.0, worst_r = 0.0, worst_ratio = 0.0;
    for (size_t i = 1; i < imu.samples.size(); ++i) {
      filter->predict(s, interval(imu.samples[i - 1], imu.samples[i]));
      const NavState t = motion.state(test::seconds(imu.samples[i].utime));
      const Vector15d e = boxminus(t, s.mean.nav);
      worst_p = std::max(worst_p, e.segment<3>(idx::kP).norm());
      worst_v = std::max(worst_v, e.segment<3>(idx::kV).norm());
      worst_r = std::max(worst_r, e.segment<3>(idx::kTheta).norm());
      if (i >= 200) {  // after 1 s, once the noise has had time to act
        for (int block : {idx::kP, idx::kV, idx::kTheta}) {
          const double sigma = std::sqrt(s.P.block<3, 3>(block, block).trace());
          worst_ratio = std::max(worst_ratio, e.segment<3>(block).norm() / sigma);
        }
      }
    }
    const char* name = kind == FilterKind::kEkf ? "EKF" : "UKF";
    EXPECT_LT(worst_ratio, 0.1) << name;
    // The absolute figures, for the record: centimetre-level after 20 s of open-loop flight.
    EXPECT_LT(worst_p, 0.02) << name;
    EXPECT_LT(worst_v, 3e-3) << name;
    EXPECT_LT(worst_r, 5e-5) << name;
    EXPECT_TRUE(s.is_valid());
  }
}

TEST(Filter, IntegrationErrorShrinksWithTheSquareOfTheStep) {
  const AnalyticMotion motion = AnalyticMotion::aggressive();
  test::ImuNoiseTruth truth;
  truth.add_noise = false;
  const Ekf ekf(ImuNoise{}, kStandardGravity);
  std::vector<double> errors;
  for (double rate : {100.0, 200.0, 400.0}) {
    const auto imu = test::generate_imu(motion, rate, 5.0, truth, 1);
    FilterState s = start_state(motion.state(0.0));
    for (size_t i = 1; i < imu.samples.size(); ++i)
      ekf.predict(s, interval(imu.samples[i - 1], imu.samples[i]));
    errors.push_back((s.mean.nav.p_world_body - motion.state(5.0).p_world_body).norm());
  }
  EXPECT_NEAR(errors[0] / errors[1], 4.0, 1.0);
  EXPECT_NEAR(errors[1] / errors[2], 4.0, 1.0);
}

TEST(Filter, EkfAndUkfAgreeOnANearlyLinearProblem) {
  // Gentle motion, small uncertainty: both filters linearise the same models at nearly the
  // same points, so they must give nearly the same estimate and covariance.
  const AnalyticMotion motion = AnalyticMotion::gentle();
  test::ImuNoiseTruth truth;
  const auto imu = test::generate_imu(motion, 200.0, 5.0, truth, 7);
  const Ekf ekf(truth.noise, kStandardGravity);
  const Ukf ukf(truth.noise, kStandardGravity, {});
  FilterState a = start_state(motion.state(0.0));
  a.mean.nav.p_world_body += Eigen::Vector3d(1e-3, -1e-3, 5e-4);  // start off the truth
  a.mean.utime = imu.samples[0].utime;
  add_clone(a);
  FilterState b = a;
  std::mt19937 rng(8);
  std::normal_distribution<double> n(0.0, 1.0);
  const Matrix6d Q = (Vector6d() << 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6).finished().asDiagonal();
  const Eigen::Isometry3d T_bc = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d T_w_ref = motion.state(0.0).T_world_body();
  for (size_t i = 1; i < imu.samples.size(); ++i) {
    const ImuInterval u = interval(imu.samples[i - 1], imu.samples[i]);
    ekf.predict(a, u);
    ukf.predict(b, u);
    if (i % 7 == 0) {
      Vector6d noise;
      for (int k = 0; k < 6; ++k) noise[k] = 1e-3 * n(rng);
      const Eigen::Isometry3d z = se3::boxplus(
          T_w_ref.inverse() * motion.state(test::seconds(imu.samples[i].utime)).T_world_body(), noise);
      const RelativePoseMeasurement m(0, z, Q, T_bc);
      EXPECT_TRUE(ekf.update(a, m, 0.0).applied);
      EXPECT_TRUE(ukf.update(b, m, 0.0).applied);
    }
  }
  const ErrorVector diff = boxminus(a.mean, b.mean);
  EXPECT_LT(diff.head<3>().norm(), 1e-4);
  EXPECT_LT(diff.segment<3>(3).norm(), 1e-4);
  EXPECT_LT(diff.segment<3>(6).norm(), 1e-5);
  const Eigen::MatrixXd Pa = a.P, Pb = b.P;
  const Eigen::VectorXd sa = Pa.diagonal().cwiseSqrt(), sb = Pb.diagonal().cwiseSqrt();
  EXPECT_LT(((sa - sb).array() / sa.array()).abs().maxCoeff(), 0.02)
      << "sigma EKF " << sa.transpose() << "\nsigma UKF " << sb.transpose();
}

TEST(Filter, GatingRejectsAnOutlierAndLeavesTheStateAlone) {
  for (FilterKind kind : {FilterKind::kEkf, FilterKind::kUkf}) {
    const auto filter = make_filter(kind, ImuNoise{}, kStandardGravity, {});
    FilterState s = start_state(NavState{});
    add_clone(s);
    s.P.diagonal().array() += 1e-4;  // the clone no longer equals the current pose exactly
    const FilterState before = s;
    const Eigen::Isometry3d far = se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1.0, 0, 0));
    const RelativePoseMeasurement m(0, far, Matrix6d::Identity() * 1e-4, Eigen::Isometry3d::Identity());
    const UpdateResult r = filter->update(s, m, 30.0);
    EXPECT_FALSE(r.applied);
    EXPECT_GT(r.mahalanobis2, 30.0);
    EXPECT_EQ(boxminus(s.mean, before.mean).norm(), 0.0);
    EXPECT_EQ(Eigen::MatrixXd(s.P), Eigen::MatrixXd(before.P));
    EXPECT_TRUE(filter->update(s, m, 0.0).applied);  // without the gate it is fused
    EXPECT_GT(s.mean.nav.p_world_body.x(), 0.1);
  }
}

}  // namespace
}  // namespace kestrel::estimator
