// Consistency: over seeded Monte-Carlo runs of the aggressive motion (noisy IMU with bias
// random walks, the synthetic VO with known noise), the filter's errors must match the
// covariance it reports: mean NEES of [p; v; theta] inside the 95 % chi-square band. The
// 50-run figure of the issue comes from kestrel-estimate monte-carlo; this is a smaller
// version that keeps the suite fast. Also the chi-square helpers themselves.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>
#include <iostream>

#include "estimator/eval/consistency.h"
#include "test/estimator/scenario.h"

namespace kestrel::estimator {
namespace {

TEST(Consistency, ChiSquareQuantilesMatchTables) {
  EXPECT_NEAR(normal_quantile(0.975), 1.959964, 1e-6);
  EXPECT_NEAR(normal_quantile(0.5), 0.0, 1e-12);
  // Exact 2.5 % and 97.5 % points (regularised incomplete gamma, solved independently with
  // mpmath to 12 digits); a Wilson-Hilferty approximation misses the k = 3 ones by 16 %.
  EXPECT_NEAR(chi2_quantile(0.025, 3), 0.215795282624, 1e-9);
  EXPECT_NEAR(chi2_quantile(0.975, 3), 9.348403604496, 1e-9);
  EXPECT_NEAR(chi2_quantile(0.025, 9), 2.700389499980, 1e-9);
  EXPECT_NEAR(chi2_quantile(0.975, 9), 19.022767798642, 1e-9);
  EXPECT_NEAR(chi2_quantile(0.025, 450), 393.117687849230, 1e-8);
  EXPECT_NEAR(chi2_quantile(0.975, 450), 510.669711324543, 1e-8);
  EXPECT_NEAR(chi2_quantile(0.5, 2), 2.0 * std::log(2.0), 1e-12);  // chi^2(2) is exponential
  EXPECT_THROW(chi2_quantile(0.0, 3), std::invalid_argument);
  EXPECT_THROW(chi2_quantile(0.5, 0), std::invalid_argument);
  const Band b = mean_nees_band(9, 50);
  EXPECT_NEAR(b.low, 393.117687849230 / 50, 1e-9);
  EXPECT_NEAR(b.high, 510.669711324543 / 50, 1e-9);
  EXPECT_THROW(normal_quantile(1.0), std::invalid_argument);
}

TEST(Consistency, NeesOfGaussianSamplesIsInTheBand) {
  // The accumulator on samples that are consistent by construction.
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd L(3, 3);
  L << 1, 0, 0, 0.5, 2, 0, -0.3, 0.1, 0.5;
  const Eigen::MatrixXd P = L * L.transpose();
  NeesAccumulator acc(3);
  for (int run = 0; run < 50; ++run)
    for (size_t k = 0; k < 100; ++k) acc.add(k, nees(L * Eigen::Vector3d(n(rng), n(rng), n(rng)), P));
  const auto s = acc.summary();
  EXPECT_TRUE(s.band.contains(s.mean)) << s.mean;
  EXPECT_GT(s.fraction_in_band, 0.85);
  // And an overconfident "filter" (covariance 4x too small) is caught.
  NeesAccumulator bad(3);
  for (int run = 0; run < 50; ++run)
    for (size_t k = 0; k < 100; ++k) bad.add(k, nees(L * Eigen::Vector3d(n(rng), n(rng), n(rng)), P / 4));
  EXPECT_FALSE(bad.summary().band.contains(bad.summary().mean));
}

// Runs and filters from the environment, so that the 50-run figure is measured by
// the same code: KESTREL_NEES_RUNS=50 KESTREL_NEES_UKF=1 estimator_consistency_test.
int nees_runs() {
  const char* v = std::getenv("KESTREL_NEES_RUNS");
  return v ? std::max(2, std::atoi(v)) : 12;
}

// Mean NEES of [p; v; theta] every 0.1 s over `runs` seeded runs of the aggressive motion with
// small constant biases, for the filter and VO that `options` and `scenario` set.
NeesAccumulator::Summary nees_over_runs(int runs, const EstimatorOptions& options,
                                        const test::ScenarioOptions& scenario) {
  NeesAccumulator pose_velocity(9);
  for (int run = 0; run < runs; ++run) {
    Estimator e(options);
    test::ScenarioOptions o = scenario;
    o.seed = 100 + static_cast<uint64_t>(run);
    o.imu.gyro_bias = {0.003, -0.002, 0.001};
    o.imu.accel_bias = {0.03, 0.05, -0.04};
    const auto steps = test::run_scenario(e, test::AnalyticMotion::aggressive(), o);
    for (size_t i = 0; i < steps.size(); i += 20) {  // every 0.1 s
      const auto& s = steps[i];
      pose_velocity.add(i / 20, nees(pose_velocity_error(s.truth, s.output.nav),
                                     s.output.covariance.topLeftCorner<9, 9>()));
    }
  }
  return pose_velocity.summary();
}

TEST(Consistency, FilterNeesIsInTheBandOverSeededRuns) {
  const int runs = nees_runs();
  std::vector<FilterKind> kinds{FilterKind::kEkf};
  if (std::getenv("KESTREL_NEES_UKF")) kinds.push_back(FilterKind::kUkf);
  for (FilterKind kind : kinds) {
    EstimatorOptions options;
    options.filter = kind;
    test::ScenarioOptions o;
    o.duration_s = 10.0;
    const auto s = nees_over_runs(runs, options, o);
    // The checkpoints of one run are correlated, so the pooled band (all samples as if
    // independent) is far too narrow to test against; the band of one checkpoint's mean over
    // the runs is the honest one for the overall mean, and the fraction of checkpoints inside
    // their own 95 % band must be near 95 %.
    const Band per_checkpoint = mean_nees_band(9, runs);
    EXPECT_TRUE(per_checkpoint.contains(s.mean)) << "mean NEES " << s.mean << " band ["
                                                 << per_checkpoint.low << ", " << per_checkpoint.high << "]";
    EXPECT_GT(s.fraction_in_band, 0.8) << "mean NEES " << s.mean;
    RecordProperty("mean_nees", std::to_string(s.mean));
    std::cout << (kind == FilterKind::kEkf ? "EKF" : "UKF") << " runs " << runs << ": mean NEES "
              << s.mean << " band [" << per_checkpoint.low << ", " << per_checkpoint.high
              << "], checkpoints in their band " << s.fraction_in_band << "\n";
  }
}

// A VO that holds its keyframes for tens of frames, whose updates share their keyframe's error
// (as the real VO's keyframe features and depths are shared): fused as independent
// measurements, the filter believes the keyframe once per update and is overconfident; with
// the common share added once to the keyframe's clone it is consistent.
TEST(Consistency, AKeyframeErrorSharedByItsUpdatesIsCountedOnce) {
  const int runs = nees_runs();
  test::ScenarioOptions o;
  o.duration_s = 10.0;
  o.vo.keyframe_distance_m = 1.0;
  o.vo.keyframe_angle_rad = 0.3;
  o.vo.keyframe_share = 0.6;
  const Band band = mean_nees_band(9, runs);
  EstimatorOptions options;
  options.vo_noise.keyframe_share = 0.6;
  NeesAccumulator::Summary once;
  for (FilterKind kind : {FilterKind::kUkf, FilterKind::kEkf}) {
    options.filter = kind;
    once = nees_over_runs(runs, options, o);
    EXPECT_TRUE(band.contains(once.mean)) << "fused once: mean NEES " << once.mean << " band ["
                                          << band.low << ", " << band.high << "]";
    // Looser than the independent VO's 0.8: the filter carries the common error as an error
    // of the keyframe's pose, mapped into each update through its own Jacobian, while this VO
    // draws it fixed in the update's coordinates, and the two part as the view turns from the
    // keyframe's (held to 0.6 rad: 79-88 % of checkpoints inside; to 0.3 rad: 85 % in the
    // clang sanitizer build, 97 % in GCC's Release).
    EXPECT_GT(once.fraction_in_band, 0.7) << "fused once: mean NEES " << once.mean;
    std::cout << (kind == FilterKind::kEkf ? "EKF" : "UKF") << " fused once: mean NEES " << once.mean
              << ", checkpoints in their band " << once.fraction_in_band << "\n";
  }
  options.vo_noise.keyframe_share = 0.0;
  const auto every_update = nees_over_runs(runs, options, o);
  EXPECT_GT(every_update.mean, band.high) << "fused per update";
  std::cout << "keyframes shared 0.6: mean NEES fused once " << once.mean << ", per update "
            << every_update.mean << " (band [" << band.low << ", " << band.high << "])\n";
}

}  // namespace
}  // namespace kestrel::estimator
