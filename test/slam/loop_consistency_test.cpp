// The odometry check of a verified loop (slam/backend/loop_consistency.h) on hand-built
// chains: a loop that agrees with the estimate passes, one off by a texture period over a
// short chain is refused, the same offset after a long chain (metres of possible drift) passes,
// and a rotation far outside the chain's uncertainty is refused.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "slam/backend/loop_consistency.h"

namespace kestrel::slam {
namespace {

// n odometry edges of `step_m` along x with the back-end's noise model at 0.25 m steps
// (sigma_t = 1 cm + 5 %, sigma_r = 0.005 + 0.02 rad/m).
PoseGraph3d straight_chain(int n, double step_m) {
  PoseGraph3d g;
  const double sigma_t = 0.01 + 0.05 * step_m, sigma_r = 0.005 + 0.02 * step_m;
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Zero();
  info.diagonal().head<3>().setConstant(1.0 / (sigma_t * sigma_t));
  info.diagonal().tail<3>().setConstant(4.0 / (sigma_r * sigma_r));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  g.add_vertex(0, T, true);
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation().x() = step_m;
  for (int i = 1; i <= n; ++i) {
    T = T * step;
    g.add_vertex(i, T, false);
    g.add_edge(i - 1, i, step, info, EdgeKind::kOdometry);
  }
  return g;
}

TEST(LoopConsistency, AgreeingLoopPasses) {
  const PoseGraph3d g = straight_chain(10, 0.25);
  Eigen::Isometry3d T = g.poses[2].inverse() * g.poses[10];
  T.translation() += Eigen::Vector3d(0.05, -0.03, 0.02);  // within the chain's few centimetres
  const LoopConsistency c = check_loop_against_odometry(g, 2, 10, T, {});
  EXPECT_TRUE(c.consistent) << c.translation_m << " allowed " << c.allowed_translation_m;
}

TEST(LoopConsistency, ShortChainAliasingIsRefused) {
  // 2.5 m of odometry says the keyframes are 2.5 m apart; the "loop" says they are the same place.
  const PoseGraph3d g = straight_chain(10, 0.25);
  const LoopConsistency c = check_loop_against_odometry(g, 0, 10, Eigen::Isometry3d::Identity(), {});
  EXPECT_FALSE(c.consistent);
  EXPECT_NEAR(c.translation_m, 2.5, 1e-12);
  EXPECT_GT(c.allowed_translation_m, 0.1);
  EXPECT_LT(c.allowed_translation_m, 1.0);
}

TEST(LoopConsistency, LongChainAllowsMetresOfDrift) {
  const PoseGraph3d g = straight_chain(600, 0.25);  // 150 m
  Eigen::Isometry3d T = g.poses[0].inverse() * g.poses[600];
  T.translation() += Eigen::Vector3d(0.0, 2.5, 0.0);
  const LoopConsistency c = check_loop_against_odometry(g, 0, 600, T, {});
  EXPECT_TRUE(c.consistent) << c.translation_m << " allowed " << c.allowed_translation_m;
  EXPECT_GT(c.allowed_translation_m, 10.0);
}

TEST(LoopConsistency, RotationOutsideTheChainsUncertaintyIsRefusedAndZeroSigmasDisables) {
  const PoseGraph3d g = straight_chain(4, 0.25);
  Eigen::Isometry3d T = g.poses[0].inverse() * g.poses[4];
  T.linear() = T.linear() * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_FALSE(check_loop_against_odometry(g, 0, 4, T, {}).consistent);
  LoopConsistencyOptions off;
  off.sigmas = 0.0;
  EXPECT_TRUE(check_loop_against_odometry(g, 0, 4, T, off).consistent);
}

TEST(LoopConsistency, TheGivenOdometryInformationReplacesTheGraphsForTheBound) {
  // The graph's odometry edges as tight as a good VO reports (1 mm, 0.001 rad): 25 cm off over
  // 2.5 m is refused against them, and passes against the constant model given per edge.
  PoseGraph3d g = straight_chain(10, 0.25);
  std::vector<Matrix6d> model;
  for (auto& e : g.edges) {
    model.push_back(e.information);
    e.information.diagonal().head<3>().setConstant(1e6);
    e.information.diagonal().tail<3>().setConstant(4e6);
  }
  Eigen::Isometry3d T = g.poses[0].inverse() * g.poses[10];
  T.translation() += Eigen::Vector3d(0.0, 0.25, 0.0);
  EXPECT_FALSE(check_loop_against_odometry(g, 0, 10, T, {}).consistent);
  const LoopConsistency c = check_loop_against_odometry(g, 0, 10, T, {}, &model);
  EXPECT_TRUE(c.consistent) << c.translation_m << " allowed " << c.allowed_translation_m;
}

}  // namespace
}  // namespace kestrel::slam
