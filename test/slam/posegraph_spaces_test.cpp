// The two pose spaces of the pose graph (SE(2), SE(3)): the manifold and group laws
// (test/support/manifold_laws.h) of their retractions, the error convention (g2o's) and the
// exact Jacobians the solver relies on.

#include <gtest/gtest.h>

#include <random>

#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "slam/posegraph/spaces.h"
#include "test/support/manifold_laws.h"
#include "test/support/numerical.h"

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

// The spaces as manifolds: their own retract and group operations; ⊟ written here as the
// inverse the solver's retract must have (g2o's: translation in the pose's frame for SE(3),
// plain differences with the angle wrapped for SE(2)), with each space's embedding and validity.
template <class Space>
struct SpaceModel {
  using Point = typename Space::Pose;
  static constexpr int kDim = Space::kDim;
  static constexpr double kChartRadius = 3.1;
  static Point sample(std::mt19937& rng) { return Samples<Space>::pose(rng); }
  static Point plus(const Point& X, const typename Space::Vector& d) { return Space::retract(X, d); }
  static Point identity() { return Space::identity(); }
  static Point compose(const Point& a, const Point& b) { return Space::compose(a, b); }
  static Point inverse(const Point& a) { return Space::inverse(a); }
};

struct Se2Model : SpaceModel<Se2> {
  static Se2::Vector minus(const Point& Y, const Point& X) {
    return {Y.x() - X.x(), Y.y() - X.y(), wrap_angle(Y.z() - X.z())};
  }
  static Eigen::VectorXd embed(const Point& X) { return Eigen::Vector4d(X.x(), X.y(), std::cos(X.z()), std::sin(X.z())); }
  static bool valid(const Point& X) { return X.allFinite() && std::abs(X.z()) <= kPi; }
};

struct Se3Model : SpaceModel<Se3> {
  static Se3::Vector minus(const Point& Y, const Point& X) {
    Se3::Vector d;
    d << X.linear().transpose() * (Y.translation() - X.translation()), so3::log(X.linear().transpose() * Y.linear());
    return d;
  }
  static Eigen::VectorXd embed(const Point& X) { return test::embed_pose(X.linear(), X.translation()); }
  static bool valid(const Point& X) { return se3::is_valid(X, test::kLawTolerance); }
};

using namespace ::kestrel::test;  // the suites' names, as INSTANTIATE_TYPED_TEST_SUITE_P needs them
using PoseGraphManifolds = ::testing::Types<Se2Model, Se3Model>;
INSTANTIATE_TYPED_TEST_SUITE_P(PoseGraph, ManifoldLaws, PoseGraphManifolds);
INSTANTIATE_TYPED_TEST_SUITE_P(PoseGraph, GroupLaws, PoseGraphManifolds);

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

TYPED_TEST(SpaceTest, JacobiansMatchCentralDifferences) {
  using S = TypeParam;
  std::mt19937 rng(5);
  using V = typename S::Vector;
  for (int trial = 0; trial < 100; ++trial) {
    const auto Xi = Samples<S>::pose(rng), Xj = Samples<S>::pose(rng);
    const auto Z_inv = S::inverse(Samples<S>::pose(rng));
    typename S::Matrix Ji, Jj;
    const V e = S::linearize(Xi, Xj, Z_inv, Ji, Jj);
    EXPECT_LT((e - S::error(Xi, Xj, Z_inv)).norm(), 1e-12);
    const auto Ni = test::numerical_jacobian<S::kDim>([&](const V& d) -> V { return S::error(S::retract(Xi, d), Xj, Z_inv); });
    const auto Nj = test::numerical_jacobian<S::kDim>([&](const V& d) -> V { return S::error(Xi, S::retract(Xj, d), Z_inv); });
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
