// The sparse linear algebra under the pose-graph solver: the block system and its CHOLMOD
// factorisation agree with a dense solve, report a matrix that is not positive definite, and
// conjugate gradients converge with a good preconditioner.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "slam/posegraph/block_system.h"
#include "slam/posegraph/pcg.h"

namespace kestrel::slam {
namespace {

// A random symmetric positive-definite matrix on a ring of blocks with chords, written into
// a BlockSystem and into a dense matrix.
struct Fixture {
  static constexpr int D = 3;
  int n = 30;
  std::vector<std::pair<int, int>> pairs;
  Eigen::MatrixXd dense;

  void fill(BlockSystem<D>& system, std::mt19937& rng, double diagonal_boost) {
    std::normal_distribution<double> g(0.0, 1.0);
    dense = Eigen::MatrixXd::Zero(n * D, n * D);
    system.set_zero();
    for (size_t k = 0; k < pairs.size(); ++k) {
      Eigen::Matrix<double, D, D> B;
      for (int r = 0; r < D; ++r)
        for (int c = 0; c < D; ++c) B(r, c) = g(rng);
      const auto [a, b] = pairs[k];
      const int lo = std::min(a, b), hi = std::max(a, b);
      system.offdiagonal(static_cast<int>(k)) += B;
      dense.block<D, D>(lo * D, hi * D) += B;
      dense.block<D, D>(hi * D, lo * D) += B.transpose();
    }
    for (int b = 0; b < n; ++b) {
      // Diagonally dominant, hence positive definite, when boosted.
      Eigen::Matrix<double, D, D> A;
      for (int r = 0; r < D; ++r)
        for (int c = 0; c < D; ++c) A(r, c) = g(rng);
      const Eigen::Matrix<double, D, D> S = A * A.transpose() + diagonal_boost * Eigen::Matrix<double, D, D>::Identity();
      system.diagonal(b) = S;
      dense.block<D, D>(b * D, b * D) = S;
    }
  }

  Fixture() {
    for (int b = 0; b < n; ++b) pairs.emplace_back(b, (b + 1) % n);
    for (int b = 0; b < n; b += 3) pairs.emplace_back((b + 7) % n, b);
    pairs.emplace_back(2, 3);  // repeated pair: its blocks add up
  }
};

TEST(BlockSystem, SolvesLikeADenseCholesky) {
  Fixture f;
  BlockSystem<Fixture::D> system(f.n, f.pairs, order_blocks(f.n, f.pairs));
  std::mt19937 rng(1);
  f.fill(system, rng, 40.0);
  Eigen::VectorXd b = Eigen::VectorXd::Random(f.n * Fixture::D);
  system.rhs() = b;
  ASSERT_TRUE(system.factorize());
  const Eigen::VectorXd x = system.solve();
  const Eigen::VectorXd expected = f.dense.ldlt().solve(b);
  EXPECT_LT((x - expected).norm(), 1e-10 * expected.norm());
  EXPECT_LT((system.multiply(x) - b).norm(), 1e-10 * b.norm());
  // Damping adds lambda * diag(H) to the diagonal.
  ASSERT_TRUE(system.factorize(0.5));
  Eigen::MatrixXd damped = f.dense;
  damped.diagonal() *= 1.5;
  EXPECT_LT((system.solve() - damped.ldlt().solve(b)).norm(), 1e-10 * expected.norm());
  EXPECT_LT((system.multiply(x, 0.5) - damped * x).norm(), 1e-10 * b.norm());
  // Several right-hand sides at once.
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(f.n * Fixture::D, 3);
  EXPECT_LT((system.solve_factored(B) - damped.ldlt().solve(B)).norm(), 1e-9 * B.norm());
}

TEST(BlockSystem, ReportsAMatrixThatIsNotPositiveDefinite) {
  Fixture f;
  BlockSystem<Fixture::D> system(f.n, f.pairs, order_blocks(f.n, f.pairs));
  std::mt19937 rng(2);
  f.fill(system, rng, 40.0);
  system.diagonal(17)(1, 1) = -5.0;
  EXPECT_FALSE(system.factorize());
}

TEST(BlockSystem, RejectsBadPairs) {
  EXPECT_THROW(BlockSystem<2>(3, {{0, 0}}, {0, 1, 2}), std::invalid_argument);
  EXPECT_THROW(BlockSystem<2>(3, {{0, 3}}, {0, 1, 2}), std::invalid_argument);
  EXPECT_THROW(BlockSystem<2>(0, {}, {}), std::invalid_argument);
  EXPECT_THROW(BlockSystem<2>(3, {{0, 1}}, {0, 1}), std::invalid_argument);  // ordering too short
}

TEST(Pcg, ConvergesAndIsExactWithTheMatrixItselfAsPreconditioner) {
  Fixture f;
  BlockSystem<Fixture::D> system(f.n, f.pairs, order_blocks(f.n, f.pairs));
  std::mt19937 rng(3);
  f.fill(system, rng, 5.0);
  ASSERT_TRUE(system.factorize());
  const Eigen::VectorXd b = Eigen::VectorXd::Random(f.n * Fixture::D);
  const Eigen::VectorXd expected = f.dense.ldlt().solve(b);
  auto A = [&](const Eigen::VectorXd& v) { return system.multiply(v); };
  Eigen::VectorXd x;
  // Preconditioned by the exact factor: one iteration.
  PcgResult r = pcg(A, [&](const Eigen::VectorXd& v) { return system.solve_factored(v); }, b, x, 5, 1e-10);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_LT((x - expected).norm(), 1e-8 * expected.norm());
  // Without a preconditioner: converges within n steps (exact arithmetic), reports failure
  // when stopped early.
  r = pcg(A, [](const Eigen::VectorXd& v) { return v; }, b, x, 1000, 1e-10);
  EXPECT_TRUE(r.converged);
  EXPECT_LT((x - expected).norm(), 1e-6 * expected.norm());
  r = pcg(A, [](const Eigen::VectorXd& v) { return v; }, b, x, 2, 1e-10);
  EXPECT_FALSE(r.converged);
  // A zero right-hand side needs nothing.
  r = pcg(A, [](const Eigen::VectorXd& v) { return v; }, Eigen::VectorXd::Zero(b.size()), x, 5, 1e-10);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(x.norm(), 0.0);
}

}  // namespace
}  // namespace kestrel::slam
