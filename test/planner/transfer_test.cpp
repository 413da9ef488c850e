// One property harness for every transfer function (Sophus-style): the same identities are
// checked on the symplectic and the scattering form against step-by-step EKF propagation.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <random>

#include "planner/transfer.h"

namespace kestrel::planner {
namespace {

Mat4 random_spd(std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  Mat4 A;
  for (int i = 0; i < 16; ++i) A(i) = n(rng);
  return scale * (A * A.transpose() + 0.1 * Mat4::Identity());
}

// A random step: G near the identity (a non-trivial, invertible dynamics), R positive
// definite, M of random rank 0..4 (a sensor seeing part of the state, or nothing).
BeliefStep random_step(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  BeliefStep s;
  for (int i = 0; i < 16; ++i) s.G(i) += 0.2 * n(rng);
  s.R = random_spd(rng, 0.05);
  const int rank = static_cast<int>(rng() % 5);
  Eigen::Matrix<double, 4, Eigen::Dynamic> H(4, rank);
  for (int i = 0; i < H.size(); ++i) H(i) = n(rng);
  s.M = H * H.transpose();
  return s;
}

double relative_trace_error(const Mat4& a, const Mat4& b) { return std::abs(a.trace() - b.trace()) / b.trace(); }

template <class T>
class TransferTest : public ::testing::Test {};
using TransferTypes = ::testing::Types<SymplecticTransfer, ScatteringTransfer>;
TYPED_TEST_SUITE(TransferTest, TransferTypes);

TYPED_TEST(TransferTest, IdentityLeavesCovarianceUnchanged) {
  std::mt19937_64 rng(1);
  const Mat4 S = random_spd(rng, 1.0);
  EXPECT_LT((TypeParam::identity().apply(S) - S).norm(), 1e-12 * S.norm());
}

TYPED_TEST(TransferTest, OneStepEqualsEkfStep) {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 200; ++trial) {
    const BeliefStep s = random_step(rng);
    const Mat4 S = random_spd(rng, 1.0);
    const Mat4 expected = propagate_ekf(S, {s});
    EXPECT_LT((TypeParam::from_step(s).apply(S) - expected).norm(), 1e-9 * expected.norm()) << trial;
  }
}

TYPED_TEST(TransferTest, RandomShortEdgesMatchStepByStepEkf) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<BeliefStep> steps(1 + rng() % 10);
    for (auto& s : steps) s = random_step(rng);
    const Mat4 S0 = random_spd(rng, 1.0);
    const Mat4 expected = propagate_ekf(S0, steps);
    const Mat4 got = TypeParam::from_steps(steps).apply(S0);
    EXPECT_LT(relative_trace_error(got, expected), 1e-9) << trial;
    EXPECT_LT((got - expected).norm(), 1e-9 * expected.norm()) << trial;
  }
}

TYPED_TEST(TransferTest, CompositionIsAssociativeAndMatchesSequentialApplication) {
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 50; ++trial) {
    const auto a = TypeParam::from_step(random_step(rng));
    const auto b = TypeParam::from_step(random_step(rng));
    const auto c = TypeParam::from_step(random_step(rng));
    const Mat4 S = random_spd(rng, 1.0);
    const Mat4 sequential = c.apply(b.apply(a.apply(S)));
    EXPECT_LT((a.then(b).then(c).apply(S) - sequential).norm(), 1e-9 * sequential.norm());
    EXPECT_LT((a.then(b.then(c)).apply(S) - sequential).norm(), 1e-9 * sequential.norm());
  }
}

TYPED_TEST(TransferTest, ResultIsSymmetricPositiveDefinite) {
  std::mt19937_64 rng(5);
  std::vector<BeliefStep> steps(20);
  for (auto& s : steps) s = random_step(rng);
  const Mat4 out = TypeParam::from_steps(steps).apply(random_spd(rng, 1.0));
  EXPECT_EQ(out, out.transpose());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat4>(out).eigenvalues().minCoeff(), 0.0);
}

// A 10 m edge (40 steps) with one direction observed well: each step multiplies the
// symplectic product's dynamic range (eigenvalue pairs lambda, 1/lambda),
// so B C^-1 is formed from nearly parallel huge columns. The scattering form stays exact.
std::vector<BeliefStep> long_observed_edge(int n) {
  // One direction observed strongly, the others not at all, in a rotated basis so the
  // directions mix in every block of the product.
  const Mat4 U = Eigen::HouseholderQR<Mat4>(Mat4::NullaryExpr([](Eigen::Index i, Eigen::Index j) {
                   return std::sin(1.0 + 3.0 * static_cast<double>(i) + 7.0 * static_cast<double>(j));
                 })).householderQ();
  BeliefStep s;
  s.R = 0.01 * Mat4::Identity();
  s.M = U * Eigen::Vector4d(100.0, 0.0, 0.0, 0.0).asDiagonal() * U.transpose();
  return std::vector<BeliefStep>(n, s);
}

TEST(TransferPrecision, ScatteringStaysExactWhereSymplecticLosesDigits) {
  const std::vector<BeliefStep> steps = long_observed_edge(40);
  const Mat4 S0 = Eigen::Vector4d(4.0, 3.0, 1.0, 0.5).asDiagonal();
  const Mat4 expected = propagate_ekf(S0, steps);
  const double symplectic = relative_trace_error(SymplecticTransfer::from_steps(steps).apply(S0), expected);
  const double scattering = relative_trace_error(ScatteringTransfer::from_steps(steps).apply(S0), expected);
  std::cout << "long edge relative tr error: symplectic " << symplectic << ", scattering " << scattering << "\n";
  EXPECT_GT(symplectic, 1e-6);  // more than 6 of 16 digits lost
  EXPECT_LT(scattering, 1e-9);
}

}  // namespace
}  // namespace kestrel::planner
