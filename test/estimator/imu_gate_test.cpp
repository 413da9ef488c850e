// The IMU's gates (estimator/input_gate.h) against known answers: a sample stamped an hour
// ahead (or seconds behind) is dropped and the filter runs on exactly as without it; a new time
// base that persists restarts the filter on it, ahead or back, while a gap ahead within the
// history is bridged; readings beyond the sensor's range (a 500 m/s^2 spike, a 1e300 rad/s
// gyro) leave every state as without them; StateEstimator reports a refusal for a second of
// sensor time, and after a restart on a new time base awaits SLAM's world again.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "estimator/estimator.h"
#include "estimator/state_estimator.h"
#include "test/estimator/scenario.h"

namespace kestrel::estimator::imu_gate_test {
namespace {

using test::AnalyticMotion;
using test::gentle_run;

// Bit for bit: an input the gates refused changed nothing.
void expect_same_outputs(const std::vector<test::ScenarioStep>& want, const std::vector<test::ScenarioStep>& got) {
  ASSERT_EQ(want.size(), got.size());
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(want[i].output.utime, got[i].output.utime) << "step " << i;
    ASSERT_EQ(want[i].output.nav.p_world_body, got[i].output.nav.p_world_body) << "at utime " << got[i].output.utime;
    ASSERT_EQ(want[i].output.status, got[i].output.status) << "at utime " << got[i].output.utime;
  }
  EXPECT_EQ(want.back().output.covariance, got.back().output.covariance);
}

ImuSample still_sample(int64_t utime) {
  ImuSample s;
  s.utime = utime;
  s.accel = {0.0, 0.0, kStandardGravity};
  return s;
}

TEST(ImuGate, ASampleStampedAnHourAheadOrSecondsBehindIsDroppedAndTheFilterRunsOnAsWithoutIt) {
  const EstimatorOptions options;
  Estimator clean(options);
  const auto expected = test::run_scenario(clean, AnalyticMotion::gentle(), gentle_run(3.0));
  for (const double offset_s : {3600.0, -2.0}) {
    SCOPED_TRACE(offset_s);
    Estimator e(options);
    Verdict verdict = Verdict::kAccepted;
    const auto steps = test::run_scenario(e, AnalyticMotion::gentle(), gentle_run(3.0), [&](size_t i) {
      if (i == 400) verdict = e.add_imu(still_sample(e.now_utime() + std::llround(offset_s * 1e6)));
    });
    EXPECT_EQ(verdict, Verdict::kTimeJump);
    EXPECT_EQ(e.counters().imu_time_jumps, 1);
    EXPECT_EQ(e.counters().imu_resyncs, 0);
    ASSERT_TRUE(e.last_rejection());
    EXPECT_NE(e.last_rejection()->what.find("--max-time-jump"), std::string::npos) << e.last_rejection()->what;
    EXPECT_EQ(steps.back().output.status, Status::kOk);
    expect_same_outputs(expected, steps);
  }
}

// A still IMU, one second on one time base and one on another (a driver restarted, a log
// replayed from its start): the filter restarts on the new base, from its first samples.
TEST(ImuGate, ANewTimeBaseThatPersistsRestartsTheFilterOnItAheadOrBack) {
  const auto imu = test::generate_imu(AnalyticMotion::still(), 200.0, 2.0, test::ImuNoiseTruth{}, 3, 0);
  constexpr int64_t kOldBase = 3'700'000'000;
  for (const int64_t new_base : {kOldBase + 3'600'000'000, kOldBase - 3'600'000'000}) {
    SCOPED_TRACE(new_base > kOldBase ? "an hour ahead" : "an hour back");
    const EstimatorOptions options;
    Estimator e(options);
    std::vector<Verdict> on_new_base;
    for (size_t k = 0; k < imu.samples.size(); ++k) {
      ImuSample s = imu.samples[k];
      s.utime += k < 200 ? kOldBase : new_base;
      const Verdict v = e.add_imu(s);
      if (k >= 200) on_new_base.push_back(v);
    }
    const int held = options.gates.resync_samples;
    for (int k = 0; k + 1 < held; ++k) EXPECT_EQ(on_new_base[k], Verdict::kTimeJump) << k;
    EXPECT_EQ(on_new_base[held - 1], Verdict::kAccepted);
    const EstimatorCounters c = e.counters();
    EXPECT_EQ(c.imu_resyncs, 1);
    EXPECT_EQ(c.imu_time_jumps, held);
    EXPECT_EQ(c.imu_accepted, static_cast<int64_t>(imu.samples.size()));  // the held ones too
    EXPECT_NE(e.last_resync().find("restarts"), std::string::npos) << e.last_resync();
    // Started still on the new base's samples: its prior and half a second without VO, not an
    // hour of a held reading's gap noise.
    const auto out = e.output();
    ASSERT_TRUE(out);
    EXPECT_EQ(out->utime, new_base + imu.samples.back().utime);
    EXPECT_LT(std::sqrt(out->covariance.block<3, 3>(idx::kP, idx::kP).trace()), 0.1);
    EXPECT_LT(out->nav.v_world_body.norm(), 0.05);
  }
}

// 1.5 s without IMU samples while standing still: beyond the jump bound, within the 3 s
// history. The samples after it are held, then taken as a gap (its noise added), not as a new
// base: the filter keeps its state and its VO.
TEST(ImuGate, AGapAheadWithinTheHistoryIsBridgedNotARestart) {
  const EstimatorOptions options;
  Estimator e(options);
  test::ScenarioOptions o;
  o.duration_s = 5.0;
  o.drop_imu = [](const ImuSample& s) { return s.utime > 3'000'000 && s.utime < 4'500'000; };
  const auto steps = test::run_scenario(e, AnalyticMotion::still(), o);
  const EstimatorCounters c = e.counters();
  EXPECT_EQ(c.imu_resyncs, 0);
  EXPECT_EQ(c.imu_time_jumps, options.gates.resync_samples);
  EXPECT_EQ(c.imu_gaps, 1);
  EXPECT_EQ(c.filter_failures, 0);
  EXPECT_GT(c.vo_applied, 100);
  ASSERT_FALSE(steps.empty());
  EXPECT_EQ(steps.back().output.utime, 1'000'000 + 5'000'000);
  EXPECT_EQ(steps.back().output.status, Status::kOk);
  EXPECT_LT((steps.back().output.nav.p_world_body - steps.back().truth.p_world_body).norm(), 0.02);
}

TEST(ImuGate, ReadingsBeyondTheSensorsRangeLeaveEveryStateAsWithoutThem) {
  const EstimatorOptions options;
  Estimator clean(options);
  const auto expected = test::run_scenario(clean, AnalyticMotion::gentle(), gentle_run(3.0));
  struct Case {
    const char* what;
    Eigen::Vector3d gyro, accel;
    int64_t EstimatorCounters::*counter;
  };
  const std::vector<Case> cases{
      {"a 500 m/s^2 accelerometer spike", Eigen::Vector3d::Zero(), {500.0, 0.0, kStandardGravity},
       &EstimatorCounters::imu_accel_range},
      {"a 1e300 rad/s gyro reading", {1e300, 0.0, 0.0}, {0.0, 0.0, kStandardGravity}, &EstimatorCounters::imu_gyro_range}};
  for (const Case& k : cases) {
    SCOPED_TRACE(k.what);
    Estimator e(options);
    Verdict verdict = Verdict::kAccepted;
    const auto steps = test::run_scenario(e, AnalyticMotion::gentle(), gentle_run(3.0), [&](size_t i) {
      if (i != 400) return;
      ImuSample s;  // between two samples of the stream
      s.utime = e.now_utime() + 2500;
      s.gyro = k.gyro;
      s.accel = k.accel;
      verdict = e.add_imu(s);
    });
    EXPECT_EQ(verdict, Verdict::kImplausible);
    EXPECT_EQ(e.counters().*k.counter, 1);
    EXPECT_EQ(e.counters().filter_failures, 0);
    ASSERT_TRUE(e.last_rejection());
    EXPECT_NE(e.last_rejection()->what.find("beyond the sensor's range"), std::string::npos) << e.last_rejection()->what;
    expect_same_outputs(expected, steps);
  }
}

ImuReading still_reading(int64_t utime, double accel_z = kStandardGravity) {
  ImuReading r;
  r.utime = utime;
  r.gyro = Eigen::Vector3d::Zero();
  r.accel = Eigen::Vector3d(0.0, 0.0, accel_z);
  return r;
}

TEST(ImuGate, ARefusalNamesItsReasonAndARestartAwaitsSlamsWorldAgain) {
  EstimatorOptions o;
  o.await_world_s = 1.0;
  StateEstimator e(o);
  int64_t t = 1'000'000;
  for (int i = 0; i < 400; ++i, t += 5000) e.add_imu(still_reading(t));  // 2 s: started, usable
  ASSERT_TRUE(e.output());
  EXPECT_NE(e.output()->status, Status::kInitializing);

  const int64_t spike = t;
  EXPECT_EQ(e.add_imu(still_reading(spike, 500.0)).verdict, Verdict::kImplausible);
  EXPECT_EQ(e.refusals(), 1);
  ASSERT_TRUE(e.last_rejection());
  EXPECT_EQ(e.last_rejection()->reason, Reason::kImuAccelRange);
  EXPECT_NE(e.last_rejection()->summary.find("--imu-max-accel"), std::string::npos) << e.last_rejection()->summary;
  for (t = spike + 5000; t <= spike + 1'000'000; t += 5000) e.add_imu(still_reading(t));

  // An hour ahead for good: a restart, whose first states await SLAM's world like a new start's.
  const int64_t base = t + 3'600'000'000;
  int64_t first = -1, usable = -1;
  for (int i = 0; i < 600; ++i) {
    const StepResult step = e.add_imu(still_reading(base + i * 5000));
    if (!step.state) continue;
    if (first < 0) first = step.state->utime;
    if (usable < 0 && step.state->status != Status::kInitializing) usable = step.state->utime;
  }
  EXPECT_EQ(e.resyncs(), 1);
  ASSERT_GE(first, base);
  EXPECT_EQ(usable - first, 1'000'000) << "the first usable state after the restart's first";
  ASSERT_TRUE(e.last_rejection());
  EXPECT_EQ(e.last_rejection()->reason, Reason::kImuResync);
}

}  // namespace
}  // namespace kestrel::estimator::imu_gate_test
