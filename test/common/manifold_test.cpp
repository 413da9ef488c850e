// The manifold and group laws (test/support/manifold_laws.h) on common's rotations and rigid
// transforms, and the laws themselves shown to fail on models broken the ways a retraction
// usually is.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "test/support/manifold_laws.h"

namespace kestrel {
namespace {

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d axis(n(rng), n(rng), n(rng));
  return so3::exp(axis.normalized() * std::uniform_real_distribution<double>(0.0, kPi)(rng));
}

// SO(3) with the right perturbation the filters use: R ⊞ d = R Exp(d).
struct So3Model {
  using Point = Eigen::Matrix3d;
  static constexpr int kDim = 3;
  static constexpr double kChartRadius = 3.1;  // log is the inverse of Exp below pi
  static Point sample(std::mt19937& rng) { return random_rotation(rng); }
  static Point plus(const Point& R, const Eigen::Vector3d& d) { return R * so3::exp(d); }
  static Eigen::Vector3d minus(const Point& S, const Point& R) { return so3::log(R.transpose() * S); }
  static Eigen::VectorXd embed(const Point& R) { return test::embed_rotation(R); }
  static bool valid(const Point& R) { return so3::is_valid(R, test::kLawTolerance); }
  static Point identity() { return Point::Identity(); }
  static Point compose(const Point& a, const Point& b) { return a * b; }
  static Point inverse(const Point& a) { return a.transpose(); }
};

// Rigid transforms as the estimator and SLAM perturb them (se3::boxplus: p + dp, R Exp(dθ)).
struct Se3Model {
  using Point = Eigen::Isometry3d;
  static constexpr int kDim = 6;
  static constexpr double kChartRadius = 3.1;
  static Point sample(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    return se3::make(random_rotation(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  static Point plus(const Point& T, const Vector6d& d) { return se3::boxplus(T, d); }
  static Vector6d minus(const Point& U, const Point& T) { return se3::boxminus(U, T); }
  static Eigen::VectorXd embed(const Point& T) { return test::embed_pose(T.linear(), T.translation()); }
  static bool valid(const Point& T) { return se3::is_valid(T, test::kLawTolerance); }
  static Point identity() { return Point::Identity(); }
  static Point compose(const Point& a, const Point& b) { return a * b; }
  static Point inverse(const Point& a) { return a.inverse(Eigen::Isometry); }
};

using namespace ::kestrel::test;  // the suites' names, as INSTANTIATE_TYPED_TEST_SUITE_P needs them
using CommonManifolds = ::testing::Types<So3Model, Se3Model>;
INSTANTIATE_TYPED_TEST_SUITE_P(Common, ManifoldLaws, CommonManifolds);
INSTANTIATE_TYPED_TEST_SUITE_P(Common, GroupLaws, CommonManifolds);

// ---- The laws catch what they are for -----------------------------------------------------

// ⊟ without the wrap: the angle difference leaves (-pi, pi] for large steps.
struct UnwrappedCircle {
  using Point = double;
  static constexpr int kDim = 1;
  static Point plus(Point x, const Eigen::Matrix<double, 1, 1>& d) { return std::remainder(x + d(0), 2.0 * kPi); }
  static Eigen::Matrix<double, 1, 1> minus(Point y, Point x) { return Eigen::Matrix<double, 1, 1>(y - x); }
  static Eigen::VectorXd embed(Point x) { return Eigen::Vector2d(std::cos(x), std::sin(x)); }
  static bool valid(Point x) { return std::abs(x) <= kPi; }
};

// ⊞ by adding the generator, R + R hat(d): right to first order, off the manifold beyond it.
struct LinearisedRotation : So3Model {
  static Point plus(const Point& R, const Eigen::Vector3d& d) { return R + R * so3::hat(d); }
};

// ⊞ that drops the third direction (a Jacobian column of zeros, as a missing term gives).
struct DroppedAxis : So3Model {
  static Point plus(const Point& R, const Eigen::Vector3d& d) { return R * so3::exp(Eigen::Vector3d(d.x(), d.y(), 0.0)); }
};

// Composition that multiplies in the wrong order for the inverse (a⁻¹ taken as the transpose of
// the whole 4 x 4 matrix).
struct WrongInverse : Se3Model {
  static Point inverse(const Point& a) {
    Point out;
    out.linear() = a.linear().transpose();
    out.translation() = -a.translation();
    return out;
  }
};

TEST(ManifoldLawsCheck, AMinusWithoutTheWrapFailsToUndoPlusNearPi) {
  EXPECT_FALSE(test::laws::minus_undoes_plus<UnwrappedCircle>(3.0, Eigen::Matrix<double, 1, 1>(0.5)));
  EXPECT_TRUE(test::laws::minus_undoes_plus<UnwrappedCircle>(0.0, Eigen::Matrix<double, 1, 1>(0.5)));
}

TEST(ManifoldLawsCheck, APlusThatLeavesTheManifoldIsCaught) {
  const Eigen::Matrix3d R = so3::exp(Eigen::Vector3d(0.2, -0.4, 1.0));
  EXPECT_FALSE(test::laws::plus_stays_on_the_manifold<LinearisedRotation>(R, Eigen::Vector3d(0.3, 0.0, 0.0)));
  EXPECT_TRUE(test::laws::plus_stays_on_the_manifold<So3Model>(R, Eigen::Vector3d(0.3, 0.0, 0.0)));
}

TEST(ManifoldLawsCheck, APlusThatLosesADirectionIsCaught) {
  const Eigen::Matrix3d R = so3::exp(Eigen::Vector3d(0.2, -0.4, 1.0));
  EXPECT_FALSE(test::laws::plus_has_full_rank<DroppedAxis>(R));
  EXPECT_FALSE(test::laws::minus_undoes_plus<DroppedAxis>(R, Eigen::Vector3d(0.0, 0.0, 0.1)));
  EXPECT_TRUE(test::laws::plus_has_full_rank<So3Model>(R));
}

TEST(ManifoldLawsCheck, AWrongInverseBreaksTheGroup) {
  std::mt19937 rng(9);
  const auto a = Se3Model::sample(rng), b = Se3Model::sample(rng), c = Se3Model::sample(rng);
  EXPECT_FALSE(test::laws::group_axioms<WrongInverse>(a, b, c));
  EXPECT_TRUE(test::laws::group_axioms<Se3Model>(a, b, c));
}

// The helper's own known answer: d/dd of (x + d)^2 componentwise is 2x on the diagonal, and
// a linear map's Jacobian is its matrix to rounding.
TEST(NumericalJacobian, KnownDerivatives) {
  const Eigen::Vector2d x(1.5, -2.0);
  const auto J = test::numerical_jacobian<2>(
      [&](const Eigen::Vector2d& d) -> Eigen::Vector2d { return (x + d).array().square().matrix(); });
  EXPECT_NEAR(J(0, 0), 3.0, 1e-8);
  EXPECT_NEAR(J(1, 1), -4.0, 1e-8);
  EXPECT_NEAR(J(0, 1), 0.0, 1e-12);
  Eigen::Matrix<double, 3, 2> A;
  A << 1, 2, 3, 4, 5, 6;
  const auto L = test::numerical_jacobian<2>([&](const Eigen::Vector2d& d) -> Eigen::Vector3d { return A * (x + d); });
  EXPECT_LT((L - A).cwiseAbs().maxCoeff(), 1e-8);
  const auto D = test::numerical_jacobian<Eigen::Dynamic>(
      [&](const Eigen::VectorXd& d) -> Eigen::VectorXd { return A * (x + d); }, 1e-6, 2);
  EXPECT_LT((D - A).cwiseAbs().maxCoeff(), 1e-8);
}

}  // namespace
}  // namespace kestrel
