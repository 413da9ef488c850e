// JumpSmoother (control/jump_smoother.h), hand-computed: a 0.45 m step in a straight flight at
// 0.5 m/s is taken out whole and let go at 0.1 m/s; what the previous velocity explains (a
// steady turn at 1 m/s^2), small steps and steps across a gap pass; bad options are refused.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "control/jump_smoother.h"

namespace kestrel::control {
namespace {

constexpr int64_t kStepUs = 5'000;  // 200 Hz, as STATE
constexpr double kDt = 5e-3;

TEST(JumpSmoother, AStepIsTakenOutWholeAndLetGoAtTheReleaseSpeed) {
  JumpSmoother smoother;  // 2 cm, 0.1 m/s
  const Eigen::Vector3d v(0.5, 0.0, 0.0), jump(0.0, 0.45, 0.0);
  Eigen::Vector3d previous_control = Eigen::Vector3d::Zero();
  for (int k = 0; k <= 2000; ++k) {  // 10 s; the correction at 1 s
    const double t = k * kDt;
    const Eigen::Vector3d p = t * v + (t >= 1.0 - 1e-9 ? jump : Eigen::Vector3d::Zero());
    const Eigen::Vector3d offset = smoother.update(k * kStepUs, p, v);
    const Eigen::Vector3d control = p - offset;
    if (k > 0) {
      // What the controller sees moves by the velocity's step plus at most the release.
      EXPECT_LE((control - previous_control - kDt * v).norm(), 0.1 * kDt + 1e-12) << "t " << t;
    }
    previous_control = control;
    if (k == 200) {
      EXPECT_LT((offset - jump).norm(), 1e-12) << "the step itself is all taken out";
    } else if (k == 600) {
      EXPECT_NEAR(offset.y(), 0.45 - 0.1 * 2.0, 1e-9) << "2 s later";
    } else if (k == 200 + 900 + 1) {
      EXPECT_EQ(offset.norm(), 0.0) << "4.5 s later, all let go";
    }
  }
  EXPECT_EQ(smoother.jumps(), 1);
  EXPECT_NEAR(smoother.largest_jump_m(), 0.45, 1e-12);
}

TEST(JumpSmoother, ASteadyTurnSmallStepsAndStepsAcrossAGapPass) {
  JumpSmoother smoother;
  // 1 m radius at 1 rad/s: 1 m/s^2 centripetal, which the mean of two velocities predicts to
  // within 1e-6 m per step.
  for (int k = 0; k <= 1000; ++k) {
    const double t = k * kDt;
    const Eigen::Vector3d p(std::cos(t), std::sin(t), 1.0), v(-std::sin(t), std::cos(t), 0.0);
    EXPECT_EQ(smoother.update(k * kStepUs, p, v).norm(), 0.0) << "t " << t;
  }
  JumpSmoother steps;
  const Eigen::Vector3d still = Eigen::Vector3d::Zero();
  steps.update(0, still, still);
  EXPECT_EQ(steps.update(kStepUs, Eigen::Vector3d(0.019, 0.0, 0.0), still).norm(), 0.0) << "1.9 cm: a VO update";
  // Half a second without states (an outage, a restart): the previous velocity explains
  // nothing across it, so nothing is taken out.
  EXPECT_EQ(steps.update(kStepUs + 500'000, Eigen::Vector3d(1.0, 0.0, 0.0), still).norm(), 0.0);
  EXPECT_EQ(steps.jumps(), 0);
  // A non-finite state or a repeated one changes nothing; one that goes back (a replay started
  // again) starts afresh.
  steps.update(kStepUs + 505'000, Eigen::Vector3d(1.3, 0.0, 0.0), still);
  ASSERT_NEAR(steps.offset().x(), 0.3, 1e-12);
  EXPECT_NEAR(steps.update(kStepUs + 510'000, Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0), still).x(), 0.3, 1e-12);
  EXPECT_NEAR(steps.update(kStepUs + 505'000, Eigen::Vector3d(9.0, 0.0, 0.0), still).x(), 0.3, 1e-12);
  EXPECT_EQ(steps.update(kStepUs, Eigen::Vector3d(5.0, 0.0, 0.0), still).norm(), 0.0);
  EXPECT_EQ(steps.update(2 * kStepUs, Eigen::Vector3d(5.0, 0.0, 0.0), still).norm(), 0.0) << "from 5 m on";
  steps.reset();
  EXPECT_EQ(steps.offset().norm(), 0.0);
  EXPECT_EQ(steps.jumps(), 0);
}

// At most 0.5 m is held out: the rest of a 1.5 m jump passes (the follower's off-path hold must
// see it), and a cleared offset keeps the last state (the next step is measured from it).
TEST(JumpSmoother, HoldsAtMostTheLargestOffsetAndClearsOnRequest) {
  JumpSmoother smoother;
  const Eigen::Vector3d still = Eigen::Vector3d::Zero();
  smoother.update(0, still, still);
  EXPECT_NEAR(smoother.update(kStepUs, Eigen::Vector3d(0.0, 1.5, 0.0), still).y(), 0.5, 1e-12);
  EXPECT_NEAR(smoother.last_jump_m(), 1.5, 1e-12);
  smoother.clear_offset();
  EXPECT_EQ(smoother.update(2 * kStepUs, Eigen::Vector3d(0.0, 1.5, 0.0), still).norm(), 0.0) << "no step since";
  EXPECT_NEAR(smoother.update(3 * kStepUs, Eigen::Vector3d(0.0, 1.6, 0.0), still).y(), 0.1, 1e-12);
}

TEST(JumpSmoother, RefusesOptionsThatCannotWork) {
  EXPECT_THROW(JumpSmoother(JumpSmoothingOptions{-0.01, 0.1, 0.1}), std::invalid_argument);
  EXPECT_THROW(JumpSmoother(JumpSmoothingOptions{0.02, 0.0, 0.1}), std::invalid_argument);
  EXPECT_THROW(JumpSmoother(JumpSmoothingOptions{0.02, 0.1, std::numeric_limits<double>::quiet_NaN()}), std::invalid_argument);
  EXPECT_THROW(JumpSmoother(JumpSmoothingOptions{0.02, 0.1, 0.1, 0.0}), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::control
