// The visual odometry blind for seconds (a blank wall), then back: the filter predicts on the
// IMU alone through the gap and must come back to the truth without a transient.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "estimator/estimator.h"
#include "test/estimator/scenario.h"

namespace kestrel::estimator {
namespace {

using test::AnalyticMotion;
using test::ScenarioOptions;

constexpr int64_t kT0 = 1000000;

ScenarioOptions blind_between(double from_s, double to_s, double duration_s) {
  ScenarioOptions o;
  o.duration_s = duration_s;
  o.imu.gyro_bias = {0.004, -0.003, 0.002};
  o.imu.accel_bias = {0.05, -0.04, 0.08};
  const int64_t a = kT0 + static_cast<int64_t>(from_s * 1e6), b = kT0 + static_cast<int64_t>(to_s * 1e6);
  o.vo.blind = [a, b](int64_t t) { return t >= a && t < b; };
  return o;
}

struct GapRun {
  double v_before = 0.0, p_before = 0.0;  // errors at the end of the blind stretch
  double worst_v_after = 0.0;             // STATE velocity error from 0.1 s after it to 2 s
  double worst_p_after = 0.0, p_end = 0.0;
};

GapRun fly_through_gap(const AnalyticMotion& motion) {
  Estimator e{EstimatorOptions{}};
  const auto steps = test::run_scenario(e, motion, blind_between(6.3, 11.0, 14.0));
  GapRun r;
  for (const auto& s : steps) {
    const double t = test::seconds(s.output.utime);
    const double ev = (s.output.nav.v_world_body - s.truth.v_world_body).norm();
    const double ep = (s.output.nav.p_world_body - s.truth.p_world_body).norm();
    if (t < 11.0) {
      r.v_before = ev;
      r.p_before = ep;
    } else if (t > 11.1 && t < 13.0) {
      r.worst_v_after = std::max(r.worst_v_after, ev);
      r.worst_p_after = std::max(r.worst_p_after, ep);
    }
    r.p_end = ep;
  }
  std::printf("end of gap: |dv| %.3f m/s |dp| %.3f m; after: worst |dv| %.3f, worst |dp| %.3f, "
              "final |dp| %.3f\n",
              r.v_before, r.p_before, r.worst_v_after, r.worst_p_after, r.p_end);
  return r;
}

// The VO keeps its keyframe through the blind stretch and matches it again (hovering): the
// pose cloned at that keyframe ties the position back, in one update; velocity has no
// transient.
TEST(VoGap, KeyframeSeenAgainTiesThePositionBack) {
  const GapRun r = fly_through_gap(AnalyticMotion::gentle());
  EXPECT_GT(r.p_before, 0.03);  // the gap mattered
  EXPECT_LT(r.worst_p_after, 0.01);
  EXPECT_LT(r.worst_v_after, 0.05);
}

// The camera has moved on (aggressive motion): the VO restarts from the first frame it sees
// again, so only relative motion comes back. Velocity is observed again and the position
// drift that came from the velocity error is partly undone (their errors are correlated);
// neither gets worse than at the end of the gap.
TEST(VoGap, RestartedVoBringsVelocityBackWithoutTransient) {
  const GapRun r = fly_through_gap(AnalyticMotion::aggressive());
  EXPECT_GT(r.p_before, 0.1);
  EXPECT_LT(r.worst_v_after, r.v_before + 0.01);
  EXPECT_LT(r.worst_p_after, r.p_before + 0.01);
  EXPECT_LT(r.p_end, r.p_before);
}

}  // namespace
}  // namespace kestrel::estimator
