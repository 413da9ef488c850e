// The measurement models and the state bookkeeping around them: one harness checks every
// model's residual (zero at the truth) and its Jacobian (against finite differences of the
// residual through ⊞) on random states with clones; cloning and marginalising keep P right.

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <random>

#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "estimator/filter_state.h"
#include "estimator/measurements.h"
#include "test/support/numerical.h"

namespace kestrel::estimator {
namespace {

Eigen::Vector3d random_vector(std::mt19937& rng, double s) {
  std::normal_distribution<double> n(0.0, s);
  return {n(rng), n(rng), n(rng)};
}

FilterMean random_mean(std::mt19937& rng, int clones) {
  FilterMean x;
  x.utime = 1000;
  x.nav.p_world_body = random_vector(rng, 2.0);
  x.nav.v_world_body = random_vector(rng, 1.0);
  x.nav.R_world_body = so3::exp(random_vector(rng, 1.0));
  x.nav.gyro_bias = random_vector(rng, 0.01);
  x.nav.accel_bias = random_vector(rng, 0.1);
  for (int i = 0; i < clones; ++i) {
    Clone& c = x.clones[static_cast<size_t>(i)];
    c.utime = 100 * (i + 1);
    c.p_world_body = random_vector(rng, 2.0);
    c.R_world_body = so3::exp(random_vector(rng, 1.0));
  }
  x.num_clones = clones;
  return x;
}

Eigen::Isometry3d camera_mount() {
  // Optical frame: z along body x, x along -body y, y along -body z, tilted 10 degrees down.
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return se3::make(so3::exp(Eigen::Vector3d(0, 0.17, 0)) * R, Eigen::Vector3d(0.1, 0.0, -0.05));
}

using ModelFactory = std::function<std::unique_ptr<Measurement>(const FilterMean& truth)>;

struct ModelCase {
  const char* name;
  ModelFactory make;
};

std::vector<ModelCase> models() {
  const Matrix6d Q = Matrix6d::Identity() * 1e-4;
  return {
      {"relative pose to clone 0",
       [Q](const FilterMean& x) -> std::unique_ptr<Measurement> {
         const RelativePoseMeasurement probe(0, Eigen::Isometry3d::Identity(), Q, camera_mount());
         return std::make_unique<RelativePoseMeasurement>(0, probe.predict(x), Q, camera_mount());
       }},
      {"relative pose to clone 1",
       [Q](const FilterMean& x) -> std::unique_ptr<Measurement> {
         const RelativePoseMeasurement probe(1, Eigen::Isometry3d::Identity(), Q, camera_mount());
         return std::make_unique<RelativePoseMeasurement>(1, probe.predict(x), Q, camera_mount());
       }},
      {"absolute pose",
       [Q](const FilterMean& x) -> std::unique_ptr<Measurement> {
         return std::make_unique<AbsolutePoseMeasurement>(x.nav.T_world_body(), Q);
       }},
  };
}

TEST(Measurements, ResidualIsZeroAtTheTruthAndJacobianMatchesFiniteDifferences) {
  std::mt19937 rng(17);
  for (const ModelCase& model : models()) {
    for (int trial = 0; trial < 20; ++trial) {
      const FilterMean truth = random_mean(rng, 2);
      const auto m = model.make(truth);
      EXPECT_LT(m->residual(truth).norm(), 1e-12) << model.name;
      // Linearise away from the truth, where the residual (and the Jr^-1 term) is not zero.
      ErrorVector offset(truth.dim());
      for (int i = 0; i < offset.size(); ++i) offset[i] = 0.2 * std::normal_distribution<double>()(rng);
      const FilterMean x = boxplus(truth, offset);
      const MeasurementJacobian H = m->jacobian(x);
      ASSERT_EQ(H.cols(), x.dim());
      const Eigen::MatrixXd numeric = test::numerical_jacobian<Eigen::Dynamic>(
          [&](const Eigen::VectorXd& d) -> Eigen::VectorXd { return m->residual(boxplus(x, d)); }, 1e-6, x.dim());
      for (int k = 0; k < x.dim(); ++k) {
        EXPECT_LT((H.col(k) - numeric.col(k)).norm(), 1e-6) << model.name << " column " << k;
      }
    }
  }
}

TEST(Measurements, RelativePoseWithAnIdentityMountIsTheBodyMotion) {
  std::mt19937 rng(23);
  const FilterMean x = random_mean(rng, 1);
  const RelativePoseMeasurement m(0, Eigen::Isometry3d::Identity(), Matrix6d::Identity(),
                                  Eigen::Isometry3d::Identity());
  const Clone& c = x.clones[0];
  const Eigen::Isometry3d expected = se3::make(c.R_world_body, c.p_world_body).inverse() * x.nav.T_world_body();
  EXPECT_TRUE(m.predict(x).isApprox(expected, 1e-12));
}

TEST(FilterState, BoxplusAndBoxminusAreInverse) {
  std::mt19937 rng(29);
  const FilterMean x = random_mean(rng, 3);
  ErrorVector d(x.dim());
  for (int i = 0; i < d.size(); ++i) d[i] = 0.3 * std::normal_distribution<double>()(rng);
  EXPECT_LT((boxminus(boxplus(x, d), x) - d).norm(), 1e-12);
}

TEST(FilterState, CloneCopiesThePoseBlocksAndMarginalisingRemovesThem) {
  std::mt19937 rng(31);
  FilterState s;
  s.mean = random_mean(rng, 0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(15, 15);
  s.P = A * A.transpose();
  const Covariance P0 = s.P;
  add_clone(s);
  ASSERT_EQ(s.mean.num_clones, 1);
  ASSERT_EQ(s.P.rows(), 21);
  // [p; theta] rows selected: the clone block must equal J P0 J^T exactly.
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(21, 15);
  J.topRows(15).setIdentity();
  J.block<3, 3>(15, idx::kP).setIdentity();
  J.block<3, 3>(18, idx::kTheta).setIdentity();
  EXPECT_LT((Eigen::MatrixXd(s.P) - J * P0 * J.transpose()).norm(), 1e-12);
  EXPECT_TRUE(s.mean.clones[0].R_world_body.isApprox(s.mean.nav.R_world_body));
  add_clone(s);  // same utime: nothing
  EXPECT_EQ(s.mean.num_clones, 1);

  // Fill to the maximum, then one more evicts the oldest.
  for (int i = 0; i < kMaxClones; ++i) {
    s.mean.utime += 10;
    s.mean.nav.p_world_body.x() += 1.0;
    add_clone(s);
  }
  EXPECT_EQ(s.mean.num_clones, kMaxClones);
  EXPECT_EQ(s.mean.clones[0].utime, 1010);
  EXPECT_EQ(s.P.rows(), 15 + 6 * kMaxClones);
  EXPECT_TRUE(s.is_valid());

  // Removing the middle clone keeps the others' blocks.
  const Covariance before = s.P;
  remove_clone(s, 1);
  EXPECT_EQ(s.mean.num_clones, kMaxClones - 1);
  EXPECT_EQ(s.mean.clones[1].utime, 1030);
  EXPECT_LT((s.P.topLeftCorner(21, 21) - before.topLeftCorner(21, 21)).norm(), 1e-15);
  EXPECT_LT((s.P.block(21, 21, 6, 6) - before.block(27, 27, 6, 6)).norm(), 1e-15);
  EXPECT_LT((s.P.block(0, 21, 21, 6) - before.block(0, 27, 21, 6)).norm(), 1e-15);
}

TEST(FilterState, InjectMovesTheMeanAndKeepsPSymmetric) {
  std::mt19937 rng(37);
  FilterState s;
  s.mean = random_mean(rng, 1);
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(21, 21);
  s.P = A * A.transpose();
  const FilterMean before = s.mean;
  ErrorVector dx = ErrorVector::Zero(21);
  dx.segment<3>(idx::kTheta) << 0.1, -0.2, 0.05;
  dx.segment<3>(18) << 0.0, 0.1, 0.0;
  inject(s, dx);
  EXPECT_LT((boxminus(s.mean, before) - dx).norm(), 1e-12);
  EXPECT_TRUE(s.is_valid());
  FilterState bad = s;
  bad.P(0, 0) = std::nan("");
  EXPECT_FALSE(bad.is_valid());
}

// A change of world moves every pose and the velocity, and the error state with them: the
// world-frame blocks (positions, velocity) turn, the body-frame ones (rotations, biases) stay.
TEST(FilterState, ChangingTheWorldTurnsItsBlocksAndLeavesTheBodysAlone) {
  std::mt19937 rng(41);
  FilterState s;
  s.mean = random_mean(rng, 2);
  s.mean.nav.v_world_body = Eigen::Vector3d(1.0, 0.0, 0.2);
  const int n = s.mean.dim();
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  s.P = A * A.transpose();
  const FilterState before = s;
  const Eigen::Matrix3d R_z = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(3.0, -2.0, 0.5);
  const Eigen::Isometry3d T = se3::make(R_z, t);
  change_world(s, T);

  // By hand: a quarter turn takes x to y.
  EXPECT_LT((s.mean.nav.v_world_body - Eigen::Vector3d(0.0, 1.0, 0.2)).norm(), 1e-15);
  EXPECT_TRUE(s.mean.nav.T_world_body().isApprox(T * before.mean.nav.T_world_body(), 1e-12));
  for (int i = 0; i < 2; ++i) {
    const Clone& c = s.mean.clones[static_cast<size_t>(i)];
    const Clone& c0 = before.mean.clones[static_cast<size_t>(i)];
    EXPECT_TRUE(se3::make(c.R_world_body, c.p_world_body).isApprox(T * se3::make(c0.R_world_body, c0.p_world_body), 1e-12));
  }
  EXPECT_TRUE(s.mean.nav.gyro_bias.isApprox(before.mean.nav.gyro_bias));

  // The error state maps through J = R_z on the world blocks, I elsewhere, and P with it.
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(n, n);
  for (const int b : {idx::kP, idx::kV, FilterMean::clone_offset(0), FilterMean::clone_offset(1)})
    J.block<3, 3>(b, b) = R_z;
  ErrorVector dx(n);
  for (int i = 0; i < n; ++i) dx[i] = 0.1 * std::normal_distribution<double>()(rng);
  FilterState moved;
  moved.mean = boxplus(before.mean, dx);
  moved.P = before.P;
  change_world(moved, T);
  EXPECT_LT((boxminus(moved.mean, s.mean) - J * dx).norm(), 1e-12);
  EXPECT_LT((Eigen::MatrixXd(s.P) - J * Eigen::MatrixXd(before.P) * J.transpose()).norm(), 1e-9);
  EXPECT_TRUE(s.is_valid());
  // The change that takes one pose onto another in position and yaw, the tilt left alone.
  const Eigen::Isometry3d ours = before.mean.nav.T_world_body();
  const Eigen::Isometry3d found = world_change(ours, T * ours);
  EXPECT_TRUE(found.isApprox(T, 1e-12));
}

// A change of world known only as well as the SLAM pose it was taken onto: that pose is then
// exactly as uncertain as SLAM's in position and yaw, a pose 3 m from it more so by the yaw's
// lever arm, the velocity turns with the yaw, and poses move together (their relative yaw
// stays certain, so relative measurements such as VO are unaffected). By hand.
TEST(FilterState, AnUncertainChangeOfWorldWidensEachPoseByItsDistanceFromTheOneTakenOnto) {
  const Eigen::Isometry3d theirs =
      se3::make(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix(), Eigen::Vector3d(2.0, 1.0, 1.0));
  Matrix6d sigma_theirs = Matrix6d::Zero();
  sigma_theirs.diagonal() << 1e-4, 1e-4, 1e-4, 4e-4, 4e-4, 4e-4;
  FilterState s;
  s.mean.nav.p_world_body = theirs.translation();
  s.mean.nav.R_world_body = theirs.linear();
  s.mean.nav.v_world_body = Eigen::Vector3d(1.0, 0.0, 0.0);
  s.mean.num_clones = 1;
  s.mean.clones[0].utime = 1;
  s.mean.clones[0].p_world_body = theirs.translation() + Eigen::Vector3d(3.0, 0.0, 0.0);
  s.mean.clones[0].R_world_body = theirs.linear();
  s.P = Covariance::Zero(s.mean.dim(), s.mean.dim());
  widen_for_world_change(s, world_change_covariance(theirs, sigma_theirs));

  const int c = FilterMean::clone_offset(0);
  EXPECT_LT((s.P.block<3, 3>(idx::kP, idx::kP) - 1e-4 * Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_NEAR(s.P(idx::kTheta + 2, idx::kTheta + 2), 4e-4, 1e-15) << "yaw (level: the body z)";
  EXPECT_NEAR(s.P(idx::kTheta, idx::kTheta), 0.0, 1e-15) << "no tilt";
  EXPECT_NEAR(s.P(c + 1, c + 1), 1e-4 + 4e-4 * 9.0, 1e-15) << "3 m from it along x: y gets the yaw's lever";
  EXPECT_NEAR(s.P(c, c), 1e-4, 1e-15);
  EXPECT_NEAR(s.P(idx::kV + 1, idx::kV + 1), 4e-4, 1e-15) << "1 m/s along x turns into y";
  const double relative_yaw = s.P(idx::kTheta + 2, idx::kTheta + 2) + s.P(c + 5, c + 5) - 2.0 * s.P(idx::kTheta + 2, c + 5);
  EXPECT_NEAR(relative_yaw, 0.0, 1e-15);

  // The Jacobian against a small change of world made by hand, at a tilted pose.
  const Eigen::Isometry3d pose = se3::make(
      (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX())).toRotationMatrix(),
      Eigen::Vector3d(-1.0, 4.0, 0.5));
  const Eigen::Vector4d d(1e-6, -2e-6, 3e-6, 1e-6);
  const Eigen::Isometry3d small =
      se3::make(Eigen::AngleAxisd(d[3], Eigen::Vector3d::UnitZ()).toRotationMatrix(), d.head<3>());
  const Vector6d moved = se3::boxminus(small * pose, pose);
  EXPECT_LT((moved - world_change_jacobian(pose.translation(), pose.linear()) * d).norm(), 1e-11);
}

}  // namespace
}  // namespace kestrel::estimator
