// One property harness for the two pose spaces of the pose graph (SE(2), SE(3)): the error
// convention (g2o's) and the exact Jacobians the solver relies on.

#include <gtest/gtest.h>

#include <random>

#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "slam/posegraph/spaces.h"

namespace kestrel::slam {
namespace {

template <class Space>
struct Samples;

template <>
struct Samples<Se2> {
  static Se2::Pose pose(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    return {u(rng), u(rng), wrap_angle(u(rng))};
  }
};

template <>
struct Samples<Se3> {
  static Se3::Pose pose(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    Vector6d xi;
    for (int k = 0; k < 6; ++k) xi(k) = n(rng);
    return se3::exp(xi);
  }
};

template <class Space>
class SpaceTest : public ::testing::Test {};
using Spaces = ::testing::Types<Se2, Se3>;
TYPED_TEST_SUITE(SpaceTest, Spaces);

TYPED_TEST(SpaceTest, ErrorVanishesForAConsistentMeasurement) {
  using S = TypeParam;
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const auto Xi = Samples<S>::pose(rng), Xj = Samples<S>::pose(rng);
    const auto Z = S::compose(S::inverse(Xi), Xj);
    EXPECT_LT(S::error(Xi, Xj, S::inverse(Z)).norm(), 1e-12);
  }
}

TYPED_TEST(SpaceTest, ComposeAndInverseAreAGroup) {
  using S = TypeParam;
  std::mt19937 rng(4);
  for (int trial = 0; trial < 50; ++trial) {
    const auto A = Samples<S>::pose(rng), B = Samples<S>::pose(rng), C = Samples<S>::pose(rng);
    const typename S::Pose I = S::identity();
    // (AB)C = A(BC) and A A^-1 = identity, compared through the error (zero iff equal).
    EXPECT_LT(S::error(S::compose(S::compose(A, B), C), S::compose(A, S::compose(B, C)), I).norm(), 1e-12);
    EXPECT_LT(S::error(S::compose(A, S::inverse(A)), I, I).norm(), 1e-12);
  }
}

TYPED_TEST(SpaceTest, JacobiansMatchCentralDifferences) {
  using S = TypeParam;
  std::mt19937 rng(5);
  const double h = 1e-6;
  for (int trial = 0; trial < 100; ++trial) {
    const auto Xi = Samples<S>::pose(rng), Xj = Samples<S>::pose(rng);
    const auto Z_inv = S::inverse(Samples<S>::pose(rng));
    typename S::Matrix Ji, Jj, Ni, Nj;
    const typename S::Vector e = S::linearize(Xi, Xj, Z_inv, Ji, Jj);
    EXPECT_LT((e - S::error(Xi, Xj, Z_inv)).norm(), 1e-12);
    for (int k = 0; k < S::kDim; ++k) {
      typename S::Vector d = S::Vector::Zero();
      d(k) = h;
      Ni.col(k) = (S::error(S::retract(Xi, d), Xj, Z_inv) - S::error(S::retract(Xi, -d), Xj, Z_inv)) / (2 * h);
      Nj.col(k) = (S::error(Xi, S::retract(Xj, d), Z_inv) - S::error(Xi, S::retract(Xj, -d), Z_inv)) / (2 * h);
    }
    EXPECT_LT((Ni - Ji).cwiseAbs().maxCoeff(), 1e-7) << "trial " << trial;
    EXPECT_LT((Nj - Jj).cwiseAbs().maxCoeff(), 1e-7) << "trial " << trial;
  }
}

TEST(Se2, ErrorIsG2osTranslationInTheMeasurementFrameAndWrappedAngle) {
  // X_i at the origin, X_j one metre ahead turned by 170 degrees; the measurement says
  // 0.9 m ahead and -170 degrees: e = (0.1, 0, 20 degrees) wrapped, in the measurement frame.
  const Se2::Pose Xi(0, 0, 0), Xj(1, 0, 170 * kPi / 180);
  const Se2::Pose Z(0.9, 0, -170 * kPi / 180);
  const Se2::Vector e = Se2::error(Xi, Xj, Se2::inverse(Z));
  const Eigen::Vector2d t = Se2::rotation(-Z.z()) * Eigen::Vector2d(0.1, 0.0);
  EXPECT_NEAR(e.x(), t.x(), 1e-12);
  EXPECT_NEAR(e.y(), t.y(), 1e-12);
  EXPECT_NEAR(e.z(), -20 * kPi / 180, 1e-12);
}

TEST(Se3, RotationErrorIsTheVectorOfAPositiveQuaternion) {
  // A rotation error of 0.3 rad about z gives vec(q) = (0, 0, sin(0.15)); its sign does not
  // depend on which of q, -q Eigen returns.
  const Se3::Pose Xi = Se3::Pose::Identity();
  const Se3::Pose Xj = se3::make(so3::exp(Eigen::Vector3d(0, 0, 0.3)), Eigen::Vector3d(1, 2, 3));
  const Se3::Pose Z = se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 2, 3));
  const Se3::Vector e = Se3::error(Xi, Xj, Se3::inverse(Z));
  EXPECT_LT(e.head<3>().norm(), 1e-12);
  EXPECT_NEAR(e(5), std::sin(0.15), 1e-12);
  const Se3::Pose Xk = se3::make(so3::exp(Eigen::Vector3d(0, 0, -0.3)), Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(Se3::error(Xi, Xk, Se3::inverse(Z))(5), -std::sin(0.15), 1e-12);
}

TEST(Se3, TranslationErrorIsInTheMeasurementFrame) {
  // Measured 1 m along x of a frame turned 90 degrees about z; the truth is 1.5 m: the error is
  // R_z^T (t - t_z) = (0.5, 0, 0) in the measurement's frame.
  const Se3::Pose Xi = Se3::Pose::Identity();
  const Eigen::Matrix3d Rz = so3::exp(Eigen::Vector3d(0, 0, kPi / 2));
  const Se3::Pose Z = se3::make(Rz, Rz * Eigen::Vector3d(1, 0, 0));
  const Se3::Pose Xj = se3::make(Rz, Rz * Eigen::Vector3d(1.5, 0, 0));
  const Se3::Vector e = Se3::error(Xi, Xj, Se3::inverse(Z));
  EXPECT_LT((e.head<3>() - Eigen::Vector3d(0.5, 0, 0)).norm(), 1e-12);
  EXPECT_LT(e.tail<3>().norm(), 1e-12);
}

TEST(WrapAngle, StaysInTheHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrap_angle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrap_angle(-kPi), kPi);
  EXPECT_NEAR(wrap_angle(3 * kPi + 0.1), -kPi + 0.1, 1e-12);
  EXPECT_NEAR(wrap_angle(-0.2), -0.2, 1e-15);
}

}  // namespace
}  // namespace kestrel::slam
