// The belief model of an edge: where the vehicle is and where it looks at each step, and how
// much process noise the edge adds — the same motion the follower (control/) flies.
#include <gtest/gtest.h>

#include <cmath>

#include "planner/roadmap.h"

namespace kestrel::planner {
namespace {

// Records the configuration each step's information is asked for.
struct Recorder {
  std::vector<Config> seen;
  BeliefModel model(MotionOptions motion = {}) {
    return BeliefModel(motion, [this](const Config& q) {
      seen.push_back(q);
      return Mat4::Zero().eval();
    });
  }
};

TEST(BeliefModel, TurnsFromTheStartYawToTheEndYawTheShortWayRound) {
  Recorder r;
  // 2 m along x while turning from 170 deg to -170 deg: 20 deg through +-180, not 340 back.
  const auto steps = r.model().steps(Config(0, 0, 1, 170 * M_PI / 180), Config(2, 0, 1, -170 * M_PI / 180));
  ASSERT_EQ(steps.size(), 8u);  // 2 m / 0.25 m; 20 deg needs fewer steps
  ASSERT_EQ(r.seen.size(), 8u);
  for (size_t k = 0; k < r.seen.size(); ++k) {
    const double f = (k + 1) / 8.0;
    EXPECT_NEAR(r.seen[k].x(), 2.0 * f, 1e-12);
    EXPECT_NEAR(std::remainder(r.seen[k][3] - (170.0 + 20.0 * f) * M_PI / 180, 2 * M_PI), 0.0, 1e-12) << k;
  }
  EXPECT_NEAR(std::remainder(r.seen.back()[3] + 170 * M_PI / 180, 2 * M_PI), 0.0, 1e-12);
}

TEST(BeliefModel, ALargeTurnOnAShortEdgeIsCutIntoYawSteps) {
  Recorder r;
  // 0.1 m and a half turn: one distance step, but pi / 0.25 rad -> 13 yaw steps, so the
  // sensor's view is sampled every 14 deg, under half the paper camera's 30 deg.
  const auto steps = r.model().steps(Config(0, 0, 1, 0), Config(0, 0.1, 1, M_PI));
  EXPECT_EQ(steps.size(), 13u);
  for (size_t k = 1; k < r.seen.size(); ++k)
    EXPECT_LE(std::abs(std::remainder(r.seen[k][3] - r.seen[k - 1][3], 2 * M_PI)), 0.25 + 1e-12);
}

TEST(BeliefModel, ProcessNoiseGrowsWithTheDistanceFlownNotWithTheSteps) {
  MotionOptions motion;
  motion.variance_per_m = Eigen::Vector4d(0.5, 0.4, 0.1, 0.05);
  Recorder r;
  // 3 m with a half turn (13 yaw steps > 12 distance steps): the noise still adds up to 3 m's.
  const auto steps = r.model(motion).steps(Config(1, 1, 1, 0), Config(1, 4, 1, M_PI));
  ASSERT_EQ(steps.size(), 13u);
  Mat4 total = Mat4::Zero();
  for (const BeliefStep& s : steps) {
    EXPECT_TRUE(s.G.isIdentity());
    total += s.R;
  }
  EXPECT_TRUE(total.isApprox(Mat4((3.0 * motion.variance_per_m).asDiagonal()), 1e-12)) << total;
}

TEST(BeliefModel, AZeroLengthEdgeHasNoSteps) {
  Recorder r;
  EXPECT_TRUE(r.model().steps(Config(1, 2, 1, 0), Config(1, 2, 1, 0)).empty());
}

}  // namespace
}  // namespace kestrel::planner
