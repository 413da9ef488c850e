// The metrics against answers worked out by hand (each test says how).

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "test/eval/synthetic.h"
#include "metrics/evaluate.h"
#include "metrics/statistics.h"

namespace kestrel::eval {  // beside kestrel eval's other tests, whose helpers (test::) it shares
namespace {

using namespace kestrel::metrics;
using test::frame_times;
using test::helix;
using test::kFrame_us;
using test::map_poses;

constexpr double kTight = 1e-9;

TEST(EvalStatistics, KnownValuesAndEmpty) {
  const Summary s = summarize({3.0, 1.0, 4.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(summarize({5.0, 1.0, 2.0}).median, 2.0);
  const Summary none = summarize({});
  EXPECT_EQ(none.count, 0u);
  EXPECT_TRUE(std::isnan(none.rmse) && std::isnan(none.mean) && std::isnan(none.median));
}

TEST(EvalMetrics, TrajectoryAgainstItselfIsPerfect) {
  const auto times = frame_times(120);
  const Trajectory gt = helix(times);
  const Evaluation e = evaluate(times, gt, gt, EvalOptions{});
  EXPECT_EQ(e.association.scored, 120u);
  EXPECT_EQ(e.ate.alignment.kind, AlignmentKind::kRigid);
  EXPECT_LT(e.ate.error_m.max, kTight);
  EXPECT_GT(e.rpe.pairs, 80u);
  EXPECT_LT(e.rpe.translation_mps.max, kTight);
  EXPECT_LT(e.rpe.rotation_degps.max, 1e-5);  // acos-free angle: ~sqrt(eps) at worst
  EXPECT_EQ(e.velocity.error_mps.count, 119u);
  EXPECT_LT(e.velocity.error_mps.max, kTight);
  EXPECT_EQ(e.velocity.gross.total(), 0u);
}

// est = T * gt for a fixed T: a different world frame. Relative motions are unchanged, so RPE
// and velocity error are 0; the alignment recovers T^-1, so the ATE is 0.
TEST(EvalMetrics, RigidlyMovedEstimateAlignsToZero) {
  const auto times = frame_times(120);
  const Trajectory gt = helix(times);
  const Eigen::Isometry3d T =
      se3::make(so3::exp(Eigen::Vector3d(0.3, -1.2, 2.0)), Eigen::Vector3d(4.0, -2.0, 7.0));
  const Trajectory est = map_poses(gt, [&](int64_t, const Eigen::Isometry3d& P) { return T * P; });
  const Evaluation e = evaluate(times, est, gt, EvalOptions{});
  EXPECT_LT(e.ate.error_m.max, 1e-9);
  EXPECT_TRUE(e.ate.alignment.T_gt_est.isApprox(T.inverse(), 1e-9));
  EXPECT_LT(e.rpe.translation_mps.max, 1e-9);
  EXPECT_LT(e.velocity.error_mps.max, 1e-9);
}

// A pure shift by (1, 2, 2) m without alignment: every frame is |(1, 2, 2)| = 3 m off.
TEST(EvalMetrics, WithoutAlignmentTheShiftIsTheError) {
  const auto times = frame_times(60);
  const Trajectory gt = helix(times);
  const Trajectory est = map_poses(gt, [](int64_t, const Eigen::Isometry3d& P) {
    return Eigen::Translation3d(1.0, 2.0, 2.0) * P;
  });
  EvalOptions options;
  options.align = false;
  const Evaluation e = evaluate(times, est, gt, options);
  EXPECT_EQ(e.ate.alignment.kind, AlignmentKind::kNone);
  EXPECT_NEAR(e.ate.error_m.rmse, 3.0, kTight);
  EXPECT_NEAR(e.ate.error_m.max - e.ate.error_m.mean, 0.0, kTight);
  options.align = true;
  EXPECT_LT(evaluate(times, est, gt, options).ate.error_m.max, 1e-9);
}

// est = gt with the position drifting at a constant world velocity u (orientation exact).
// Frame k-1 to k: t_est - t_gt = R_{k-1}^T u dt, of norm |u| dt -> velocity error |u| exactly.
// RPE: trans(E) = R_j^T u (t_j - t_i), so |u| m/s for every pair, and 0 deg/s.
// ATE without alignment: |u| k dt at frame k, RMSE = |u| dt sqrt((N-1)(2N-1)/6).
TEST(EvalMetrics, ConstantVelocityOffsetGivesKnownErrors) {
  const int n = 91;  // 3 s at 30 Hz
  const auto times = frame_times(n);
  const Trajectory gt = helix(times);
  const Eigen::Vector3d u(0.06, -0.02, 0.03);  // |u| = 0.07 m/s
  const Trajectory est = map_poses(gt, [&](int64_t t, const Eigen::Isometry3d& P) {
    return Eigen::Translation3d(u * 1e-6 * static_cast<double>(t - times.front())) * P;
  });
  EvalOptions options;
  options.align = false;
  const Evaluation e = evaluate(times, est, gt, options);
  EXPECT_NEAR(e.velocity.error_mps.mean, 0.07, 1e-9);
  EXPECT_NEAR(e.velocity.error_mps.max, 0.07, 1e-9);
  EXPECT_NEAR(e.velocity.error_mps.rmse, 0.07, 1e-9);
  EXPECT_NEAR(e.rpe.translation_mps.rmse, 0.07, 1e-9);
  EXPECT_NEAR(e.rpe.translation_mps.max, 0.07, 1e-9);
  EXPECT_LT(e.rpe.rotation_degps.max, 1e-5);
  // Pairs: frames 0 .. 60 find a partner 30 frames (1.0 s) later; 61 and 62 pair with the last
  // frame (0.967 s and 0.933 s, within the 0.1 s tolerance); the last 28 frames have none.
  EXPECT_EQ(e.rpe.pairs, 63u);
  EXPECT_EQ(e.rpe.no_partner, 28u);
  const double dt = 1e-6 * kFrame_us;
  EXPECT_NEAR(e.ate.error_m.rmse, 0.07 * dt * std::sqrt((n - 1) * (2.0 * n - 1) / 6.0), 1e-9);
  EXPECT_NEAR(e.ate.error_m.max, 0.07 * dt * (n - 1), 1e-9);
}

// Along a straight line (gt at v t, estimate at (v + w) t, both on the x axis) the positions
// are collinear: the alignment may only slide along the line, leaving w (t_k - mean t).
// For N = 11 frames 0.1 s apart: RMSE = w * 0.1 * sqrt((N^2 - 1) / 12) = w * 0.1 * sqrt(10),
// mean = w * 0.1 * 30 / 11 (mean |k - 5|), max = w * 0.5.
TEST(EvalMetrics, CollinearAlignmentLeavesTheSpreadOfTheOffset) {
  const auto times = frame_times(11, 100000);
  const double v = 0.4, w = 0.1;
  Trajectory gt, est;
  for (size_t k = 0; k < times.size(); ++k) {
    const double t = 0.1 * static_cast<double>(k);
    gt.push_back(times[k], se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(v * t, 0, 0)));
    est.push_back(times[k],
                  se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d((v + w) * t, 0, 0)));
  }
  const Evaluation e = evaluate(times, est, gt, EvalOptions{});
  EXPECT_EQ(e.ate.alignment.kind, AlignmentKind::kCollinear);
  EXPECT_NEAR(e.ate.error_m.rmse, w * 0.1 * std::sqrt(10.0), 1e-12);
  EXPECT_NEAR(e.ate.error_m.mean, w * 0.1 * 30.0 / 11.0, 1e-12);
  EXPECT_NEAR(e.ate.error_m.max, w * 0.5, 1e-12);
  EXPECT_NEAR(e.velocity.error_mps.mean, w, 1e-9);
}

// A trajectory that never moves: the best alignment puts it at the centroid of the ground
// truth, so the ATE is the spread of the ground truth about its centroid. Positions on the
// helix at quarter turns (0, 0.5 s, ... ) with z = 0.2 t: the x-y spread is exactly 1 m.
TEST(EvalMetrics, NoMotionIsComparedWithTheCentroid) {
  const auto times = frame_times(4, 1000000);  // quarter turns at t = 0, 1, 2, 3 s
  const Trajectory gt = helix(times);
  const Trajectory est = map_poses(
      gt, [](int64_t, const Eigen::Isometry3d&) { return Eigen::Isometry3d::Identity(); });
  const Evaluation e = evaluate(times, est, gt, EvalOptions{});
  EXPECT_EQ(e.ate.alignment.kind, AlignmentKind::kTranslation);
  // z = 0, 0.2, 0.4, 0.6 about 0.3: squares 0.09, 0.01, 0.01, 0.09 -> mean 0.05.
  EXPECT_NEAR(e.ate.error_m.rmse, std::sqrt(1.0 + 0.05), 1e-12);
}

// 100 frames; the estimator missed 7 of them and jumped 10 cm (3 m/s over one frame) at one:
// 8 gross failures, 8 %. The frame after a missed one is not counted again.
TEST(EvalMetrics, MissingFramesAndJumpsAreGrossFailures) {
  const auto times = frame_times(100);
  const Trajectory gt = helix(times);
  const std::vector<size_t> missed = {0, 10, 11, 40, 41, 42, 99};
  const size_t jump = 70;
  Trajectory est;
  for (size_t k = 0; k < times.size(); ++k) {
    if (std::find(missed.begin(), missed.end(), k) != missed.end()) continue;
    Eigen::Isometry3d P = gt.poses()[k].T;
    if (k >= jump) P = Eigen::Translation3d(0.1, 0.0, 0.0) * P;
    est.push_back(times[k], P);
  }
  const Evaluation e = evaluate(times, est, gt, EvalOptions{});
  EXPECT_EQ(e.association.no_estimate, 7u);
  EXPECT_EQ(e.association.scored, 93u);
  const GrossFailures& g = e.velocity.gross;
  EXPECT_EQ(g.frames, 100u);
  EXPECT_EQ(g.no_estimate, 7u);
  EXPECT_EQ(g.too_fast, 1u);
  EXPECT_EQ(g.after_gt_gap, 0u);
  EXPECT_EQ(g.total(), 8u);
  EXPECT_DOUBLE_EQ(g.percent(), 8.0);
  EXPECT_EQ(e.velocity.verdicts[jump], Verdict::kTooFast);
  EXPECT_EQ(e.velocity.verdicts[12], Verdict::kNotChecked);  // after a missed frame
  EXPECT_EQ(e.velocity.verdicts[13], Verdict::kChecked);
  // 99 transitions minus the 9 that touch a missed frame: 90 velocity errors.
  EXPECT_EQ(e.velocity.error_mps.count, 90u);
  EXPECT_NEAR(e.velocity.error_mps.max, 0.1 / (1e-6 * kFrame_us), 1e-6);
  // The jump itself, in metres, and when: what a controller fed the estimate would see.
  EXPECT_EQ(e.velocity.step_error_m.count, 90u);
  EXPECT_NEAR(e.velocity.step_error_m.max, 0.1, 1e-9);
  EXPECT_EQ(e.velocity.largest_step_utime, times[jump]);
}

// Ground truth with a 0.11 s hole (as fr1_xyz has): frames with no sample within 20 ms on a
// side are unscored; the first scored frame after them is a gross failure by the baselines'
// convention, which the option turns off.
TEST(EvalMetrics, GroundTruthGapIsCountedOnceOrNotAtAll) {
  const auto times = frame_times(60);
  Trajectory gt;
  for (int64_t t = times.front() - 50000; t <= times.back() + 50000; t += 10000) {
    const int64_t gap_start = test::kStart_us + 1000000, gap_end = gap_start + 110000;
    if (t > gap_start && t < gap_end) continue;
    gt.push_back(t, test::helix_pose(t));
  }
  const Trajectory est = helix(times);
  EvalOptions options;
  const Evaluation e = evaluate(times, est, gt, options);
  // Frames 31, 32 and 33 (1.033, 1.067 and 1.100 s) lie in the hole between the samples at
  // 1.000 and 1.110 s, each more than 20 ms from one of them; frame 34 is the first after it.
  EXPECT_EQ(e.association.no_gt_in_gap, 3u);
  EXPECT_EQ(e.association.no_gt_before_start + e.association.no_gt_after_end, 0u);
  EXPECT_EQ(e.velocity.gross.after_gt_gap, 1u);
  EXPECT_EQ(e.velocity.gross.total(), 1u);
  EXPECT_EQ(e.velocity.verdicts[34], Verdict::kAfterGtGap);
  options.gross_after_gt_gap = false;
  EXPECT_EQ(evaluate(times, est, gt, options).velocity.gross.total(), 0u);
}

TEST(EvalMetrics, FramesOutsideTheGroundTruthAreCountedByReason) {
  const auto times = frame_times(30);
  const std::vector<int64_t> inner(times.begin() + 5, times.end() - 3);
  const Trajectory gt = helix(inner);
  const Evaluation e = evaluate(times, helix(times), gt, EvalOptions{});
  EXPECT_EQ(e.association.no_gt_before_start, 5u);
  EXPECT_EQ(e.association.no_gt_after_end, 3u);
  EXPECT_EQ(e.association.scored, 22u);
  EXPECT_EQ(e.velocity.gross.total(), 0u);  // the start of the ground truth is not a gap
}

// Frames at 0, 0.5, 1.02, 1.5 and 3 s, step 1 s, tolerance 0.1 s: 0 -> 1.02 and 0.5 -> 1.5
// pair up; 1.02 -> (1.5 or 3.0) and 1.5 -> 3.0 are too far from 1 s; 3.0 has nothing after.
TEST(EvalMetrics, RpePairsAreTheClosestWithinTheTolerance) {
  const std::vector<int64_t> times = {test::kStart_us, test::kStart_us + 500000,
                                      test::kStart_us + 1020000, test::kStart_us + 1500000,
                                      test::kStart_us + 3000000};
  const Trajectory gt = helix(times);
  const Eigen::Vector3d u(0.0, 0.0, 0.05);
  const Trajectory est = map_poses(gt, [&](int64_t t, const Eigen::Isometry3d& P) {
    return Eigen::Translation3d(u * 1e-6 * static_cast<double>(t - times.front())) * P;
  });
  const Evaluation e = evaluate(times, est, gt, EvalOptions{});
  EXPECT_EQ(e.rpe.pairs, 2u);
  EXPECT_EQ(e.rpe.no_partner, 3u);
  EXPECT_NEAR(e.rpe.translation_mps.rmse, 0.05, 1e-9);  // the rate, whatever the span
  EvalOptions wide;
  wide.rpe_tolerance_s = 0.6;  // now 1.02 -> 1.5 (0.48 s) and 1.5 -> 3.0 (1.5 s) count too
  EXPECT_EQ(evaluate(times, est, gt, wide).rpe.pairs, 4u);
}

TEST(EvalMetrics, NoOverlapIsAnError) {
  const Trajectory gt = helix(frame_times(30));
  std::vector<int64_t> shifted;
  for (int64_t t : frame_times(30)) shifted.push_back(t + 10000000);
  const Trajectory est = helix(shifted);
  EXPECT_THROW(evaluate(shifted, est, gt, EvalOptions{}), NoOverlapError);
}

TEST(EvalMetrics, BadArgumentsAreRejected) {
  const auto times = frame_times(10);
  const Trajectory gt = helix(times);
  EXPECT_THROW(evaluate({times[1], times[0]}, gt, gt, EvalOptions{}), std::invalid_argument);
  EvalOptions bad;
  bad.rpe_delta_s = 0.0;
  EXPECT_THROW(evaluate(times, gt, gt, bad), std::invalid_argument);
  bad = EvalOptions{};
  bad.rpe_delta_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(evaluate(times, gt, gt, bad), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::eval
