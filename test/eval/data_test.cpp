// The evaluation on the real TUM ground truth (../shared/data, read in place): the "no motion"
// rows of ../shared/BASELINES.md, and a seeded-noise estimate whose errors are known from
// statistics alone.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "common/numbers.h"
#include "test/support/figures.h"
#include "test/support/test_support.h"
#include "metrics/evaluate.h"
#include "tools/eval/trajectory_input.h"

namespace kestrel::eval {
namespace {

struct Sequence {
  std::vector<int64_t> frames;  // rgb.txt
  Trajectory gt;
};

Sequence load(const std::filesystem::path& dir) {
  return {read_frame_list(dir / "rgb.txt"), read_tum_trajectory(dir / "groundtruth.txt")};
}

// The first ground-truth pose held at every frame: a trajectory that never moves.
Trajectory no_motion(const Sequence& s) {
  Trajectory t;
  for (int64_t u : s.frames) t.push_back(u, s.gt.poses().front().T);
  return t;
}

// Each "no motion" figure within its limit in results/figures.json: BASELINES.md's value
// +-3 %, since BASELINES.md prints 2-3 significant digits and the association differs slightly
// (tools/eval/README.md, about 1 %).
void expect_baseline(double value_si, const std::string& id) {
  EXPECT_TRUE(test::within_limit(value_si, test::figure(id)));
}

void expect_baselines(const metrics::Evaluation& e, const std::string& sequence) {
  const std::string id = "eval." + sequence + ".no_motion.";
  expect_baseline(e.ate.error_m.rmse, id + "ate_rmse");
  expect_baseline(e.rpe.translation_mps.rmse, id + "rpe_translation");
  expect_baseline(e.rpe.rotation_degps.rmse * kDegree, id + "rpe_rotation");
  expect_baseline(e.velocity.error_mps.mean, id + "velocity_error");
  expect_baseline(0.01 * e.velocity.gross.percent(), id + "gross_failures");
}

TEST(EvalData, NoMotionReproducesTheBaselineOnFr1Xyz) {
  KESTREL_REQUIRE_TUM(dir, "rgbd_dataset_freiburg1_xyz");
  const Sequence s = load(dir);
  const metrics::Evaluation e = metrics::evaluate(s.frames, no_motion(s), s.gt, metrics::EvalOptions{});
  EXPECT_EQ(e.association.frames.size(), 190u);
  // Kept frames 125-128 have no sample within 20 ms on one side (0.11 s mocap gap).
  EXPECT_EQ(e.association.no_gt_in_gap, 4u);
  expect_baselines(e, "fr1_xyz");
  EXPECT_EQ(e.velocity.gross.total(), 1u);  // 0.53 %: the first frame after the gap
  EXPECT_EQ(e.velocity.gross.after_gt_gap, 1u);
}

TEST(EvalData, NoMotionReproducesTheBaselineOnFr1Rpy) {
  KESTREL_REQUIRE_TUM(dir, "rgbd_dataset_freiburg1_rpy");
  const Sequence s = load(dir);
  const metrics::Evaluation e = metrics::evaluate(s.frames, no_motion(s), s.gt, metrics::EvalOptions{});
  EXPECT_EQ(e.association.scored, 200u);
  expect_baselines(e, "fr1_rpy");
  EXPECT_EQ(e.velocity.gross.total(), 0u);
}

// The true camera poses of fr1_xyz at the frames, positions perturbed by i.i.d. N(0, s^2 I3),
// rotations exact, 25 seeds. Known answers, independent of the implementation:
//  * RPE: trans(E) = R^T (n_j - n_i), so E|trans(E)|^2 = 6 s^2 and the RMSE over 1 s pairs
//    is sqrt(6) s / 1 s;
//  * velocity error: |n_k - n_{k-1}| / dt_k, the norm of a 3-D normal of per-axis deviation
//    sqrt(2) s, mean 2 sqrt(2) s sqrt(2 / pi) = 4 s / sqrt(pi); averaged over the frame pairs
//    with their own dt_k (from rgb.txt);
//  * ATE after alignment: 3 s^2 per point, less the 6 degrees of freedom the alignment takes
//    out of 3 N: RMSE = sqrt(3) s sqrt(1 - 2 / N);
//  * gross failures: the 4 frames without ground truth have no estimate here; a pair is too
//    fast when |n_k - n_{k-1}| > 1 m/s * dt_k, i.e. a chi-3 variable above x = dt_k / (sqrt(2) s),
//    of probability erfc(x / sqrt(2)) + sqrt(2 / pi) x exp(-x^2 / 2).
// Pooled over 25 seeds the statistical spread of each figure is about 1 % (relative standard
// deviation 0.5 / sqrt(25 x ~160 pairs) for the RPE RMSE, smaller for the others); 4 %
// is four standard deviations or more. The count of too-fast frames (about 25 x 25) is
// binomial: its deviation is 4 %, so 15 % is over three deviations.
TEST(EvalData, GaussianPositionNoiseGivesTheExpectedErrors) {
  KESTREL_REQUIRE_TUM(dir, "rgbd_dataset_freiburg1_xyz");
  const Sequence s = load(dir);
  const double sigma = 0.01;
  metrics::EvalOptions options;

  // The frames with ground truth and the pairs of consecutive ones, from the data alone.
  Trajectory truth;
  std::vector<bool> has_truth;
  for (int64_t u : s.frames) {
    const auto T = s.gt.at(u, options.gt_max_gap_us);
    has_truth.push_back(T.has_value());
    if (T) truth.push_back(u, *T);
  }
  double sum_inverse_dt = 0.0, expected_too_fast = 0.0;
  int pairs = 0;
  for (size_t k = 1; k < s.frames.size(); ++k) {
    if (!has_truth[k] || !has_truth[k - 1]) continue;
    const double dt = 1e-6 * static_cast<double>(s.frames[k] - s.frames[k - 1]);
    sum_inverse_dt += 1.0 / dt;
    const double x = dt / (std::sqrt(2.0) * sigma);
    expected_too_fast +=
        std::erfc(x / std::sqrt(2.0)) + std::sqrt(2.0 / kPi) * x * std::exp(-0.5 * x * x);
    ++pairs;
  }
  const double n = static_cast<double>(truth.size());

  double rpe_sq = 0.0, ate_sq = 0.0, velocity = 0.0;
  size_t rpe_n = 0, ate_n = 0, velocity_n = 0, too_fast = 0;
  for (unsigned seed = 0; seed < 25; ++seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    Trajectory est;
    for (const StampedPose& p : truth.poses()) {
      const Eigen::Vector3d n_k(noise(rng), noise(rng), noise(rng));
      est.push_back(p.utime, Eigen::Translation3d(n_k) * p.T);
    }
    const metrics::Evaluation e = metrics::evaluate(s.frames, est, s.gt, options);
    EXPECT_EQ(e.velocity.gross.no_estimate, 4u);
    EXPECT_EQ(e.velocity.gross.after_gt_gap, 0u);  // the frame before it has no estimate
    too_fast += e.velocity.gross.too_fast;
    rpe_sq += std::pow(e.rpe.translation_mps.rmse, 2) * e.rpe.pairs;
    rpe_n += e.rpe.pairs;
    ate_sq += std::pow(e.ate.error_m.rmse, 2) * e.ate.error_m.count;
    ate_n += e.ate.error_m.count;
    velocity += e.velocity.error_mps.mean * e.velocity.error_mps.count;
    velocity_n += e.velocity.error_mps.count;
    EXPECT_EQ(e.velocity.error_mps.count, static_cast<size_t>(pairs));
  }
  EXPECT_NEAR(std::sqrt(rpe_sq / rpe_n), std::sqrt(6.0) * sigma, 0.04 * std::sqrt(6.0) * sigma);
  const double ate = std::sqrt(3.0 * (1.0 - 2.0 / n)) * sigma;
  EXPECT_NEAR(std::sqrt(ate_sq / ate_n), ate, 0.04 * ate);
  const double mean_velocity = 4.0 * sigma / std::sqrt(kPi) * sum_inverse_dt / pairs;
  EXPECT_NEAR(velocity / velocity_n, mean_velocity, 0.04 * mean_velocity);
  EXPECT_NEAR(static_cast<double>(too_fast), 25.0 * expected_too_fast,
              0.15 * 25.0 * expected_too_fast);
}

}  // namespace
}  // namespace kestrel::eval
