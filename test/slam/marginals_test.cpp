// Marginal covariances of pose-graph vertices against cases worked out by hand: one edge gives
// back its own covariance, two equal parallel edges halve it, a chain adds the variances and
// the rotation's lever arm, and a fixed vertex has none.

#include <gtest/gtest.h>

#include <cmath>

#include "common/geometry/se3.h"
#include "slam/posegraph/marginals.h"

namespace kestrel::slam {
namespace {

constexpr double kSigmaT = 0.1;   // m
constexpr double kSigmaR = 0.05;  // rad

// Information of an SE(3) edge with these standard deviations in g2o's error convention (the
// rotational error is half the angle).
Matrix6d information() {
  Matrix6d info = Matrix6d::Zero();
  info.diagonal().head<3>().setConstant(1.0 / (kSigmaT * kSigmaT));
  info.diagonal().tail<3>().setConstant(4.0 / (kSigmaR * kSigmaR));
  return info;
}

Eigen::Isometry3d step_x() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  return T;
}

PoseGraph3d chain(int vertices) {
  PoseGraph3d g;
  for (int k = 0; k < vertices; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(k, 0.0, 0.0);
    g.add_vertex(k, T, k == 0);
  }
  for (int k = 1; k < vertices; ++k) g.add_edge(k - 1, k, step_x(), information(), EdgeKind::kOdometry);
  return g;
}

TEST(MarginalCovariance, OneEdgeGivesItsOwnCovariance) {
  const auto cov = marginal_covariance(chain(2), 1);
  ASSERT_TRUE(cov);
  Matrix6d expected = Matrix6d::Zero();
  expected.diagonal() << Eigen::Vector3d::Constant(kSigmaT * kSigmaT), Eigen::Vector3d::Constant(kSigmaR * kSigmaR);
  EXPECT_LT((*cov - expected).cwiseAbs().maxCoeff(), 1e-12) << *cov;
}

TEST(MarginalCovariance, TwoParallelEdgesHalveIt) {
  PoseGraph3d g = chain(2);
  g.add_edge(0, 1, step_x(), information(), EdgeKind::kLoopClosure);
  const auto cov = marginal_covariance(g, 1);
  ASSERT_TRUE(cov);
  EXPECT_NEAR((*cov)(0, 0), 0.5 * kSigmaT * kSigmaT, 1e-12);
  EXPECT_NEAR((*cov)(5, 5), 0.5 * kSigmaR * kSigmaR, 1e-12);
}

TEST(MarginalCovariance, AChainAddsVariancesAndTheLeverArm) {
  const auto cov = marginal_covariance(chain(3), 2);
  ASSERT_TRUE(cov);
  const double t2 = kSigmaT * kSigmaT, r2 = kSigmaR * kSigmaR;
  EXPECT_NEAR((*cov)(0, 0), 2 * t2, 1e-12);            // along the chain: no lever arm
  EXPECT_NEAR((*cov)(1, 1), 2 * t2 + r2 * 1.0, 1e-12);  // vertex 1's yaw swings vertex 2 by 1 m
  EXPECT_NEAR((*cov)(2, 2), 2 * t2 + r2 * 1.0, 1e-12);  // and its pitch
  EXPECT_NEAR((*cov)(5, 5), 2 * r2, 1e-12);
  EXPECT_NEAR((*cov)(1, 5), r2, 1e-12);                // y and yaw of vertex 2 move together
}

TEST(MarginalCovariance, FixedAndUndeterminedVertices) {
  const PoseGraph3d g = chain(3);
  const auto fixed = marginal_covariance(g, 0);
  ASSERT_TRUE(fixed);
  EXPECT_TRUE(fixed->isZero(0.0));
  PoseGraph3d loose = g;
  loose.add_vertex(3, Eigen::Isometry3d::Identity());  // no edge: nothing determines it
  EXPECT_FALSE(marginal_covariance(loose, 3));
  EXPECT_THROW(marginal_covariance(g, 3), std::invalid_argument);
}

TEST(MarginalCovariance, PlanarGraphs) {
  PoseGraph2d g;
  g.add_vertex(0, Se2::identity(), true);
  g.add_vertex(1, Se2::identity());
  Se2::Matrix info = Se2::Matrix::Identity() * 100.0;
  g.add_edge(0, 1, Se2::identity(), info, EdgeKind::kOdometry);
  const auto cov = marginal_covariance(g, 1);
  ASSERT_TRUE(cov);
  EXPECT_LT((*cov - Se2::Matrix::Identity() * 0.01).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace kestrel::slam
