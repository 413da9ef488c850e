// The gates on VO updates and SLAM corrections (estimator/input_gate.h), in both estimators,
// against known answers: an update against a frame the estimator cannot place, one moving
// 1e6 m or turning 3 rad in a millisecond, one stamped an hour ahead, a correction 1e6 m away,
// one stamped an hour ahead, one with an indefinite covariance: each is refused, counted by its
// reason, and every state after it is what it would have been without it. A visual-only chain
// on a new time base restarts on it.

#include <gtest/gtest.h>

#include <vector>

#include "common/geometry/so3.h"
#include "estimator/estimator.h"
#include "estimator/visual_only.h"
#include "test/estimator/scenario.h"

namespace kestrel::estimator::vo_gate_test {
namespace {

using test::AnalyticMotion;
using test::gentle_run;

VoUpdate motion_update(int64_t utime, int64_t reference, const Eigen::Isometry3d& T_refcam_curcam) {
  VoUpdate u;
  u.utime = utime;
  u.reference_utime = reference;
  u.ok = true;
  u.T_refcam_curcam = T_refcam_curcam;
  u.covariance = Matrix6d::Identity() * 1e-5;
  return u;
}

// Runs the gentle scenario for 5 s; at 3.5 s `inject` gets the estimator, the utime and the
// reference of the newest update delivered (updates stamped just after it keep the real ones
// that follow in order). Returns the outputs, the estimator's counters and the verdicts.
struct Injected {
  std::vector<test::ScenarioStep> steps;
  EstimatorCounters counters;
  std::vector<Verdict> verdicts;
};
template <class Inject>
Injected run_with(const Inject& inject) {
  Estimator e{EstimatorOptions{}};
  test::ScenarioOptions o = gentle_run(5.0);
  int64_t last_utime = -1, last_reference = -1;
  o.alter_vo = [&](VoUpdate& u) {
    last_utime = u.utime;
    last_reference = u.reference_utime;
  };
  Injected r;
  r.steps = test::run_scenario(e, AnalyticMotion::gentle(), o, [&](size_t i) {
    if (i == 500) inject(e, last_utime, last_reference, r.verdicts);
  });
  r.counters = e.counters();
  return r;
}

void expect_same_outputs(const std::vector<test::ScenarioStep>& want, const std::vector<test::ScenarioStep>& got) {
  ASSERT_EQ(want.size(), got.size());
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(want[i].output.utime, got[i].output.utime) << "step " << i;
    ASSERT_EQ(want[i].output.nav.p_world_body, got[i].output.nav.p_world_body) << "at utime " << got[i].output.utime;
    ASSERT_EQ(want[i].output.status, got[i].output.status) << "at utime " << got[i].output.utime;
  }
}

const Injected& clean_run() {
  static const Injected r = run_with([](Estimator&, int64_t, int64_t, std::vector<Verdict>&) {});
  return r;
}

TEST(VoGate, UpdatesAgainstFramesTheFilterCannotPlaceAreRefusedAndItsKeyframeStaysInUse) {
  // Frames at utimes 1, 2, 3: older than the history, never referenced, and the VO has long
  // been on frames of this estimator's. Taken as anchors, three of them would have pushed the
  // keyframe's clone out of the state, and the real updates after them would find no clone.
  const Injected r = run_with([](Estimator& e, int64_t last, int64_t, std::vector<Verdict>& v) {
    for (int64_t k = 1; k <= 3; ++k) v.push_back(e.add_vo(motion_update(last + k, k, Eigen::Isometry3d::Identity())));
  });
  ASSERT_EQ(r.verdicts.size(), 3u);
  for (const Verdict v : r.verdicts) EXPECT_EQ(v, Verdict::kUnknownReference);
  EXPECT_EQ(r.counters.vo_unknown_reference, 3);
  EXPECT_EQ(r.counters.vo_anchors, 0);
  EXPECT_EQ(r.counters.vo_unreferenced, 0);
  EXPECT_EQ(r.steps.back().output.status, Status::kOk);
  expect_same_outputs(clean_run().steps, r.steps);
}

TEST(VoGate, MotionsNoVehicleMakesAreRefusedNotGatedAndNeverForced) {
  // Twelve updates 1e6 m from the keyframe (the chi^2 gate refuses ten in a row, then fuses the
  // next), and one turning 3 rad in a millisecond against the newest frame.
  const Eigen::Isometry3d far = se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1e6, 0, 0));
  const Eigen::Isometry3d turned = se3::make(so3::exp(Eigen::Vector3d(0, 0, 3.0)), Eigen::Vector3d::Zero());
  const Injected r = run_with([&](Estimator& e, int64_t last, int64_t reference, std::vector<Verdict>& v) {
    for (int k = 1; k <= 12; ++k) v.push_back(e.add_vo(motion_update(last + k, reference, far)));
    v.push_back(e.add_vo(motion_update(last + 1000, last, turned)));
  });
  ASSERT_EQ(r.verdicts.size(), 13u);
  for (const Verdict v : r.verdicts) EXPECT_EQ(v, Verdict::kImplausible);
  EXPECT_EQ(r.counters.vo_implausible, 13);
  EXPECT_EQ(r.counters.vo_forced, 0);
  expect_same_outputs(clean_run().steps, r.steps);
}

TEST(VoGate, AnUpdateStampedAnHourAheadOfTheImuIsRefusedAndTheVoGoesOn) {
  // Taken, it would have waited an hour for the IMU, and every real update after it would have
  // been out of order against it: the state DEGRADED for good.
  const Injected r = run_with([](Estimator& e, int64_t, int64_t, std::vector<Verdict>& v) {
    const int64_t ahead = e.now_utime() + 3'600'000'000;
    v.push_back(e.add_vo(motion_update(ahead, ahead - 33'333, Eigen::Isometry3d::Identity())));
  });
  ASSERT_EQ(r.verdicts.size(), 1u);
  EXPECT_EQ(r.verdicts[0], Verdict::kTimeJump);
  EXPECT_EQ(r.counters.vo_time_jumps, 1);
  EXPECT_EQ(r.counters.vo_out_of_order, 0);
  EXPECT_EQ(r.steps.back().output.status, Status::kOk);
  expect_same_outputs(clean_run().steps, r.steps);
}

bool same_state(const FilterState& a, const FilterState& b) {
  return a.mean.utime == b.mean.utime && a.mean.dim() == b.mean.dim() &&
         boxminus(a.mean.nav, b.mean.nav).norm() == 0.0 && Eigen::MatrixXd(a.P) == Eigen::MatrixXd(b.P);
}

TEST(VoGate, CorrectionsAFarWorldAwayAheadOfTimeOrWithAnIndefiniteCovarianceAreRefused) {
  Estimator e{EstimatorOptions{}};
  const auto steps = test::run_scenario(e, AnalyticMotion::gentle(), gentle_run(3.0));
  const FilterState before = *e.filter_state();
  const test::ScenarioStep& then = steps[steps.size() - 21];  // 100 ms ago
  PoseCorrection c;
  c.utime = then.output.utime;
  c.T_world_body = then.truth.T_world_body();
  c.covariance = Matrix6d::Identity() * 1e-4;

  PoseCorrection ahead = c;
  ahead.utime = e.now_utime() + 3'600'000'000;
  EXPECT_EQ(e.add_correction(ahead), Verdict::kTimeJump);
  PoseCorrection indefinite = c;
  indefinite.covariance(5, 5) = -1e-4;
  EXPECT_EQ(e.add_correction(indefinite), Verdict::kInvalid);
  EXPECT_TRUE(same_state(before, *e.filter_state()));
  // The true one is still the first after the start: fused, not a change of world.
  EXPECT_EQ(e.add_correction(c), Verdict::kAccepted);
  EXPECT_EQ(e.counters().world_alignments, 0);
  EXPECT_EQ(e.counters().corrections_applied, 1);
  // Once in SLAM's world, a correction 1e6 m from the state is no SLAM this vehicle runs.
  PoseCorrection far = c;
  far.revision = c.revision + 1;
  far.T_world_body.translation().x() += 1e6;
  EXPECT_EQ(e.add_correction(far), Verdict::kImplausible);
  const EstimatorCounters counts = e.counters();
  EXPECT_EQ(counts.corrections_implausible, 1);
  EXPECT_EQ(counts.corrections_time_jumps, 1);
  EXPECT_EQ(counts.corrections_bad_covariance, 1);
  EXPECT_EQ(counts.corrections_invalid, 1);
  EXPECT_EQ(counts.world_alignments, 0);
}

// A filter restarted in flight meets SLAM's world in its first correction, which in a large map
// (stata: 100 m across) is far beyond --correction-max-jump from the filter's own origin: it
// moves onto it instead of refusing every correction for good.
TEST(VoGate, TheFirstCorrectionAfterAStartMovesTheWorldHoweverFarItIs) {
  Estimator e{EstimatorOptions{}};
  const auto steps = test::run_scenario(e, AnalyticMotion::gentle(), gentle_run(3.0));
  const test::ScenarioStep& then = steps[steps.size() - 21];
  PoseCorrection c;
  c.utime = then.output.utime;
  c.T_world_body = then.truth.T_world_body();
  c.T_world_body.translation().x() += 300.0;
  c.covariance = Matrix6d::Identity() * 1e-4;
  EXPECT_EQ(e.add_correction(c), Verdict::kAccepted);
  EXPECT_EQ(e.counters().world_alignments, 1);
  EXPECT_EQ(e.counters().corrections_implausible, 0);
  EXPECT_NEAR(e.output()->nav.p_world_body.x() - steps.back().truth.T_world_body().translation().x(), 300.0, 0.05);
}

// The visual-only estimator on TUM-like stamps (seconds since 1970), moving 1 cm along x per
// frame (body = camera, no accelerometer: level, at the origin).
constexpr int64_t kTum = 1'305'031'102'175'304;
constexpr int64_t kFrameUs = 33'333;
VoUpdate tum_step(int64_t base, int k) {
  return motion_update(base + k * kFrameUs, base + (k - 1) * kFrameUs,
                       se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.01, 0, 0)));
}

TEST(VoGate, AVisualOnlyUpdateAgainstAFrameOlderThanAllKeptIsRefusedNotExtrapolated) {
  // Predicting the pose of a frame at utime 1 from the estimator's velocity (0.3 m/s) over
  // 1.3e9 s put STATE 4e8 m away.
  VisualOnlyEstimator e{EstimatorOptions{}};
  for (int k = 1; k <= 30; ++k) ASSERT_EQ(e.add_vo(tum_step(kTum, k)), Verdict::kAccepted);
  const EstimatorOutput before = *e.output();
  VoUpdate stray = tum_step(kTum, 31);
  stray.reference_utime = 1;
  EXPECT_EQ(e.add_vo(stray), Verdict::kUnknownReference);
  EXPECT_EQ(e.counters().vo_unknown_reference, 1);
  EXPECT_EQ(e.output()->utime, before.utime);
  EXPECT_EQ(e.output()->nav.p_world_body, before.nav.p_world_body);
  // The next frame's update goes on against frame 31 (predicted from frame 30, 33 ms back).
  EXPECT_EQ(e.add_vo(tum_step(kTum, 32)), Verdict::kAccepted);
  EXPECT_NEAR(e.output()->nav.p_world_body.x(), 0.32, 5e-3);
}

TEST(VoGate, VisualOnlyMotionsAndCorrectionsNoVehicleMakesAreRefused) {
  VisualOnlyEstimator e{EstimatorOptions{}};
  for (int k = 1; k <= 30; ++k) ASSERT_EQ(e.add_vo(tum_step(kTum, k)), Verdict::kAccepted);
  const EstimatorOutput before = *e.output();
  VoUpdate jump = tum_step(kTum, 31);
  jump.T_refcam_curcam.translation().x() = 1e6;
  EXPECT_EQ(e.add_vo(jump), Verdict::kImplausible);
  EXPECT_EQ(e.output()->utime, before.utime);
  EXPECT_EQ(e.output()->nav.p_world_body, before.nav.p_world_body);
  // The first correction brings SLAM's world (here the filter's own); a later one 1e6 m away
  // is refused.
  PoseCorrection truth;
  truth.utime = kTum + 20 * kFrameUs;
  truth.T_world_body.translation() << 0.20, 0, 0;
  truth.covariance = Matrix6d::Identity() * 1e-4;
  EXPECT_EQ(e.add_correction(truth), Verdict::kAccepted);
  PoseCorrection far = truth;
  far.utime = kTum + 25 * kFrameUs;
  far.T_world_body.translation() << 1e6, 0, 0;
  EXPECT_EQ(e.add_correction(far), Verdict::kImplausible);
  EXPECT_EQ(e.counters().vo_implausible, 1);
  EXPECT_EQ(e.counters().corrections_implausible, 1);
  EXPECT_EQ(e.counters().world_alignments, 0);
}

TEST(VoGate, AVisualOnlyChainDropsAnHourAheadAndRestartsOnANewTimeBase) {
  VisualOnlyEstimator e{EstimatorOptions{}};
  for (int k = 1; k <= 30; ++k) ASSERT_EQ(e.add_vo(tum_step(kTum, k)), Verdict::kAccepted);
  // One update an hour ahead: dropped, the chain goes on.
  EXPECT_EQ(e.add_vo(tum_step(kTum + 3'600'000'000, 31)), Verdict::kTimeJump);
  EXPECT_EQ(e.add_vo(tum_step(kTum, 31)), Verdict::kAccepted);
  EXPECT_NEAR(e.output()->nav.p_world_body.x(), 0.31, 1e-9);
  // The VO restarted an hour back, for good: held, then a new chain from the options' origin.
  const int64_t back = kTum - 3'600'000'000;
  const int held = EstimatorOptions{}.gates.resync_samples;
  for (int k = 1; k < held; ++k) EXPECT_EQ(e.add_vo(tum_step(back, k)), Verdict::kTimeJump) << k;
  EXPECT_EQ(e.add_vo(tum_step(back, held)), Verdict::kAccepted);
  EXPECT_EQ(e.add_vo(tum_step(back, held + 1)), Verdict::kAccepted);
  EXPECT_EQ(e.counters().vo_resyncs, 1);
  EXPECT_EQ(e.output()->utime, back + (held + 1) * kFrameUs);
  EXPECT_NEAR(e.output()->nav.p_world_body.x(), 0.01 * (held + 1), 1e-9);
  EXPECT_NE(e.last_resync().find("restarts"), std::string::npos) << e.last_resync();
}

}  // namespace
}  // namespace kestrel::estimator::vo_gate_test
