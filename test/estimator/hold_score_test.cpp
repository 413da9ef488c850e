// score_hold against hand-computed figures: the deviation of the truth from the target, the
// estimate's error matched by time stamp, the window, and its bad inputs.

#include <gtest/gtest.h>

#include <stdexcept>

#include "common/numbers.h"
#include "estimator/eval/hold_score.h"

namespace kestrel::estimator {
namespace {

TimedPosition at(int64_t utime, double x, double y, double z, double yaw = 0.0) {
  return {utime, Eigen::Vector3d(x, y, z), yaw};
}

TEST(HoldScore, TruthFromTargetAndEstimateFromTruth) {
  const Eigen::Vector3d target(1, 2, 3);
  // 3-4-5 triangles: horizontal 0.05 m, vertical 0.12 m -> 3D 0.13 m.
  const std::vector<TimedPosition> truth{at(0, 1, 2, 3), at(5000, 1.03, 2.04, 3),
                                         at(10000, 1.03, 2.04, 3.12)};
  const std::vector<TimedPosition> estimate{at(0, 1, 2, 3, 0.1), at(5000, 1, 2, 3, -0.1),
                                            at(10000, 1.03, 2.04, 3.12, 6.2)};
  const HoldScore s = score_hold(truth, estimate, target, 0.0);
  EXPECT_EQ(s.truth_horizontal.samples, 3);
  EXPECT_NEAR(s.truth_horizontal.mean, 0.10 / 3, 1e-12);
  EXPECT_NEAR(s.truth_horizontal.max, 0.05, 1e-12);
  EXPECT_NEAR(s.truth_3d.mean, (0.05 + 0.13) / 3, 1e-12);
  EXPECT_NEAR(s.truth_3d.max, 0.13, 1e-12);
  EXPECT_EQ(s.error_3d.samples, 3);
  EXPECT_NEAR(s.error_3d.mean, 0.05 / 3, 1e-12);
  EXPECT_NEAR(s.error_horizontal.max, 0.05, 1e-12);
  // Yaw errors 0.1, 0.1 and 2 pi - 6.2 (wrapped, not 6.2).
  EXPECT_NEAR(s.error_yaw.max, 0.1, 1e-12);
  EXPECT_NEAR(s.error_yaw.mean, (0.2 + 2 * kPi - 6.2) / 3, 1e-12);
  EXPECT_NEAR(s.scored_to_s, 0.01, 1e-12);
}

TEST(HoldScore, WindowAndMatchingByNearestTime) {
  const Eigen::Vector3d target(0, 0, 0);
  const std::vector<TimedPosition> truth{at(1000000, 1, 0, 0), at(2000000, 0.1, 0, 0),
                                         at(3000000, 0.2, 0, 0)};
  // Before the window (left out), 1 ms from a truth sample (matched), 10 ms from any (unmatched).
  const std::vector<TimedPosition> estimate{at(1000000, 0, 0, 0), at(2001000, 0.1, 0.01, 0),
                                            at(2500000, 0, 0, 0), at(2999000, 0.2, 0, 0.02)};
  const HoldScore s = score_hold(truth, estimate, target, 0.5);
  EXPECT_EQ(s.truth_3d.samples, 2);  // from 1.5 s after the first truth sample
  EXPECT_NEAR(s.truth_3d.mean, 0.15, 1e-12);
  EXPECT_NEAR(s.truth_3d.max, 0.2, 1e-12);
  EXPECT_EQ(s.error_3d.samples, 2);
  EXPECT_EQ(s.unmatched_estimates, 1);
  EXPECT_NEAR(s.error_horizontal.max, 0.01, 1e-12);
  EXPECT_NEAR(s.error_horizontal.mean, 0.005, 1e-12);
  EXPECT_NEAR(s.error_3d.max, 0.02, 1e-12);
}

TEST(HoldScore, RefusesWhatCannotBeScored) {
  const Eigen::Vector3d target(0, 0, 0);
  EXPECT_THROW(score_hold({}, {}, target, 0.0), std::invalid_argument);
  EXPECT_THROW(score_hold({at(2, 0, 0, 0), at(1, 0, 0, 0)}, {}, target, 0.0), std::invalid_argument);
  EXPECT_THROW(score_hold({at(0, 0, 0, 0)}, {at(2, 0, 0, 0), at(1, 0, 0, 0)}, target, 0.0),
               std::invalid_argument);
  EXPECT_THROW(score_hold({at(0, 0, 0, 0), at(1000, 0, 0, 0)}, {}, target, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::estimator
