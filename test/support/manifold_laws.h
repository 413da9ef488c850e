#pragma once
// The laws every state and pose type with a retraction must satisfy, as one typed GoogleTest
// suite run over each of them (the shape of Sophus's LieGroupTests and GTSAM's testLie.h).
//
// A type enters through a model, a struct written beside the test that instantiates the suite:
//
//   struct So3Model {
//     using Point = Eigen::Matrix3d;
//     static constexpr int kDim = 3;                  // tangent dimension
//     static constexpr double kChartRadius = 3.0;     // |d| below which ⊟ undoes ⊞ (here: < pi)
//     static Point sample(std::mt19937& rng);         // a point anywhere on the manifold
//     static Point plus(const Point& x, const Tangent& d);      // x ⊞ d
//     static Tangent minus(const Point& y, const Point& x);     // y ⊟ x: x ⊞ (y ⊟ x) = y
//     static Eigen::VectorXd embed(const Point& x);   // coordinates in an ambient space
//     static bool valid(const Point& x);              // e.g. R orthonormal with det +1
//   };
//   using namespace ::kestrel::test;  // GoogleTest's macro needs the suite's unqualified name
//   INSTANTIATE_TYPED_TEST_SUITE_P(Common, ManifoldLaws, ::testing::Types<So3Model, ...>);
//
// `embed` compares points without ⊟, so that a ⊟ that is wrong in the same way as ⊞ is still
// caught; `embed_rotation` and `embed_pose` below are the pieces models share (validity is
// so3::is_valid / se3::is_valid at kLawTolerance). Groups add `identity()`, `compose(a, b)` and
// `inverse(a)` and instantiate GroupLaws too. Each law is also a function returning an
// AssertionResult (namespace laws), so that test/common/manifold_test.cpp can show that a
// broken model breaks it.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <random>
#include <string>

#include "test/support/numerical.h"

namespace kestrel::test {

template <class M>
using TangentOf = Eigen::Matrix<double, M::kDim, 1>;

/// Tolerance of the laws that hold exactly up to rounding, on points of unit scale.
inline constexpr double kLawTolerance = 1e-9;

/// A tangent vector of random direction and a length below `radius`.
template <class M>
TangentOf<M> sample_tangent(std::mt19937& rng, double radius) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  TangentOf<M> d;
  for (int k = 0; k < M::kDim; ++k) d(k) = n(rng);
  return d.normalized() * radius * u(rng);
}

/// A rotation's 9 entries (column-major): the embedding of SO(3) the models compare in.
Eigen::Matrix<double, 9, 1> embed_rotation(const Eigen::Matrix3d& R);

/// A pose (R, t) as R's 9 entries followed by t: the embedding of SE(3).
Eigen::VectorXd embed_pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

namespace laws {

// Out of line (manifold_laws.cpp): the same for every model, so compiled once.
std::string text(const Eigen::VectorXd& v);
Eigen::Index rank(const Eigen::MatrixXd& J, double threshold);

template <class M>
double embedded_distance(const typename M::Point& a, const typename M::Point& b) {
  return (M::embed(a) - M::embed(b)).cwiseAbs().maxCoeff();
}

/// x ⊞ 0 = x.
template <class M>
::testing::AssertionResult plus_zero_is_x(const typename M::Point& x) {
  const double e = embedded_distance<M>(M::plus(x, TangentOf<M>::Zero()), x);
  if (e <= kLawTolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "x ⊞ 0 differs from x by " << e;
}

/// x ⊟ x = 0.
template <class M>
::testing::AssertionResult minus_self_is_zero(const typename M::Point& x) {
  const TangentOf<M> d = M::minus(x, x);
  if (d.cwiseAbs().maxCoeff() <= kLawTolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "x ⊟ x = " << text(d);
}

/// (x ⊞ d) ⊟ x = d inside the chart.
template <class M>
::testing::AssertionResult minus_undoes_plus(const typename M::Point& x, const TangentOf<M>& d) {
  const TangentOf<M> back = M::minus(M::plus(x, d), x);
  const double e = (back - d).cwiseAbs().maxCoeff();
  if (e <= kLawTolerance * (1.0 + d.norm())) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(x ⊞ d) ⊟ x = " << text(back) << " for d = " << text(d);
}

/// x ⊞ (y ⊟ x) = y, for y = x ⊞ d inside the chart, compared in the embedding.
template <class M>
::testing::AssertionResult plus_undoes_minus(const typename M::Point& x, const TangentOf<M>& d) {
  const typename M::Point y = M::plus(x, d);
  const double e = embedded_distance<M>(M::plus(x, M::minus(y, x)), y);
  if (e <= kLawTolerance * (1.0 + d.norm())) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "x ⊞ (y ⊟ x) differs from y by " << e << " for y = x ⊞ " << text(d);
}

/// x ⊞ d is a point of the manifold for any d (not only inside the chart).
template <class M>
::testing::AssertionResult plus_stays_on_the_manifold(const typename M::Point& x, const TangentOf<M>& d) {
  if (M::valid(M::plus(x, d))) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "x ⊞ d is not a valid point for d = " << text(d);
}

/// ⊞ moves the point: d ↦ embed(x ⊞ d) has rank kDim at 0 (no tangent direction is lost).
template <class M>
::testing::AssertionResult plus_has_full_rank(const typename M::Point& x) {
  const auto J = numerical_jacobian<M::kDim>(
      [&](const TangentOf<M>& d) -> Eigen::VectorXd { return M::embed(M::plus(x, d)); });
  const Eigen::Index r = rank(J, 1e-6);
  if (r == M::kDim) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "d ↦ x ⊞ d has rank " << r << " of " << M::kDim << " at x";
}

/// e a = a = a e, a a⁻¹ = e, (a b) c = a (b c).
template <class M>
::testing::AssertionResult group_axioms(const typename M::Point& a, const typename M::Point& b,
                                        const typename M::Point& c) {
  const typename M::Point e = M::identity();
  const double left = embedded_distance<M>(M::compose(e, a), a), right = embedded_distance<M>(M::compose(a, e), a);
  const double inverse = embedded_distance<M>(M::compose(a, M::inverse(a)), e);
  const double associative = embedded_distance<M>(M::compose(M::compose(a, b), c), M::compose(a, M::compose(b, c)));
  if (std::max({left, right, inverse, associative}) <= kLawTolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "identity " << left << " / " << right << ", inverse " << inverse
                                       << ", associativity " << associative;
}

}  // namespace laws

template <class M>
class ManifoldLaws : public ::testing::Test {};
TYPED_TEST_SUITE_P(ManifoldLaws);

TYPED_TEST_P(ManifoldLaws, PlusZeroAndMinusSelfAreIdentities) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const auto x = TypeParam::sample(rng);
    EXPECT_TRUE(laws::plus_zero_is_x<TypeParam>(x)) << "trial " << trial;
    EXPECT_TRUE(laws::minus_self_is_zero<TypeParam>(x)) << "trial " << trial;
  }
}

TYPED_TEST_P(ManifoldLaws, MinusAndPlusUndoEachOtherInsideTheChart) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 200; ++trial) {
    const auto x = TypeParam::sample(rng);
    const TangentOf<TypeParam> d = sample_tangent<TypeParam>(rng, 0.99 * TypeParam::kChartRadius);
    EXPECT_TRUE(laws::minus_undoes_plus<TypeParam>(x, d)) << "trial " << trial;
    EXPECT_TRUE(laws::plus_undoes_minus<TypeParam>(x, d)) << "trial " << trial;
  }
}

TYPED_TEST_P(ManifoldLaws, PlusStaysOnTheManifoldForAnyStep) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    const auto x = TypeParam::sample(rng);
    EXPECT_TRUE(laws::plus_stays_on_the_manifold<TypeParam>(x, sample_tangent<TypeParam>(rng, 20.0))) << "trial " << trial;
  }
}

TYPED_TEST_P(ManifoldLaws, PlusLosesNoDirection) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) EXPECT_TRUE(laws::plus_has_full_rank<TypeParam>(TypeParam::sample(rng)));
}

REGISTER_TYPED_TEST_SUITE_P(ManifoldLaws, PlusZeroAndMinusSelfAreIdentities, MinusAndPlusUndoEachOtherInsideTheChart,
                            PlusStaysOnTheManifoldForAnyStep, PlusLosesNoDirection);
// A test file may instantiate one of the two suites only (a state that is no group).
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(ManifoldLaws);

template <class M>
class GroupLaws : public ::testing::Test {};
TYPED_TEST_SUITE_P(GroupLaws);

TYPED_TEST_P(GroupLaws, IdentityInverseAndAssociativity) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    const auto a = TypeParam::sample(rng), b = TypeParam::sample(rng), c = TypeParam::sample(rng);
    EXPECT_TRUE(laws::group_axioms<TypeParam>(a, b, c)) << "trial " << trial;
  }
}

REGISTER_TYPED_TEST_SUITE_P(GroupLaws, IdentityInverseAndAssociativity);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(GroupLaws);

}  // namespace kestrel::test
