// Each sampler against its definition, on environments whose free space is known exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "common/numbers.h"
#include "planner/sampler.h"
#include "test_environments.h"

namespace kestrel::planner {
namespace {

using testing::PredicateEnvironment;

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

Eigen::AlignedBox3d box(double x0, double x1, double y0, double y1) {
  return {Eigen::Vector3d(x0, y0, 0.0), Eigen::Vector3d(x1, y1, 2.0)};
}

TEST(UniformSampler, KeepsValidCandidatesUniformly) {
  PredicateEnvironment env(box(-5, 5, -5, 5), [](const Eigen::Vector3d& p) { return p.x() > 0.0; });
  ConfigurationSpace space(env, {});
  auto sampler = make_uniform_sampler(space);
  Rng rng(7);
  const int n = 4000;
  long attempts = 0;
  double mean_x = 0.0;
  for (int i = 0; i < n; ++i) {
    SampleTrace trace;
    const auto q = sampler->sample(rng, &trace);
    ASSERT_TRUE(q && space.is_valid(*q));
    EXPECT_DOUBLE_EQ((*q)[2], 1.0);  // the flight band fixes the height
    attempts += trace.attempts;
    mean_x += (*q)[0] / n;
  }
  EXPECT_NEAR(static_cast<double>(n) / attempts, 0.5, 0.02);  // half the box is free
  EXPECT_NEAR(mean_x, 2.5, 0.1);                               // U(0, 5): sd 1.44 / sqrt(n)
}

TEST(GaussianSampler, ConcentratesNearObstaclesAsDefined) {
  // Obstacle x <= 0. A free point at distance d is kept when its partner falls in the
  // obstacle: probability 1 - Phi(d / sigma), so E[d | kept] = sigma sqrt(2 pi) / 4.
  const double sigma = 1.0;
  PredicateEnvironment env(box(-50, 50, -50, 50), [](const Eigen::Vector3d& p) { return p.x() > 0.0; });
  ConfigurationSpace space(env, {});
  auto sampler = make_gaussian_sampler(space, sigma);
  Rng rng(8);
  const int n = 4000;
  double mean_x = 0.0;
  for (int i = 0; i < n; ++i) {
    SampleTrace trace;
    const auto q = sampler->sample(rng, &trace);
    ASSERT_TRUE(q && space.is_valid(*q));
    ASSERT_EQ(trace.witnesses.size(), 1u);
    EXPECT_FALSE(space.is_valid(trace.witnesses[0]));
    mean_x += (*q)[0] / n;
  }
  EXPECT_NEAR(mean_x, sigma * std::sqrt(2.0 * kPi) / 4.0, 0.035);  // sd 0.52 / sqrt(n) = 0.008
}

TEST(BridgeSampler, KeepsFreeMidpointsOfBlockedPairs) {
  // A 1 m corridor 0 < x < 1 between two solid half-spaces.
  PredicateEnvironment env(box(-10, 11, -10, 10),
                           [](const Eigen::Vector3d& p) { return p.x() > 0.0 && p.x() < 1.0; });
  ConfigurationSpace space(env, {});
  auto sampler = make_bridge_sampler(space, 2.0);
  Rng rng(9);
  double mean_x = 0.0;
  const int n = 1000;
  for (int i = 0; i < n; ++i) {
    SampleTrace trace;
    const auto q = sampler->sample(rng, &trace);
    ASSERT_TRUE(q && space.is_valid(*q));
    ASSERT_EQ(trace.witnesses.size(), 2u);
    EXPECT_FALSE(space.is_valid(trace.witnesses[0]));
    EXPECT_FALSE(space.is_valid(trace.witnesses[1]));
    EXPECT_TRUE((0.5 * (trace.witnesses[0] + trace.witnesses[1])).head<2>().isApprox(q->head<2>()));
    // Both ends blocked and the midpoint free: the ends are on opposite sides of the corridor.
    const double x0 = trace.witnesses[0][0], x1 = trace.witnesses[1][0];
    EXPECT_TRUE((x0 <= 0.0 && x1 >= 1.0) || (x1 <= 0.0 && x0 >= 1.0)) << x0 << " " << x1;
    mean_x += (*q)[0] / n;
  }
  EXPECT_NEAR(mean_x, 0.5, 0.03);  // symmetric about the corridor's axis
}

TEST(RunningThreshold, AcceptsWithTheNormalProbabilityOfItsRunningStatistics) {
  // Weights U(0, 1): the running mean tends to 1/2, the variance to 1/12, and a weight w is
  // accepted with probability Phi((w - 1/2) / sqrt(1/12)).
  RunningThreshold threshold;
  Rng rng(10), draws(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int bins = 5;
  std::vector<int> seen(bins, 0), kept(bins, 0);
  for (int i = 0; i < 60000; ++i) {
    const double w = u(draws);
    const bool ok = threshold.accept(w, rng);
    if (i < 2000) continue;  // statistics still settling
    const int b = std::min(bins - 1, static_cast<int>(w * bins));
    ++seen[b];
    kept[b] += ok;
  }
  EXPECT_NEAR(threshold.mean(), 0.5, 0.01);
  EXPECT_NEAR(threshold.variance(), 1.0 / 12.0, 0.003);
  for (int b = 0; b < bins; ++b) {
    // Expected acceptance over the bin: average of Phi over its weights.
    double expected = 0.0;
    for (int k = 0; k < 100; ++k) {
      const double w = (b + (k + 0.5) / 100.0) / bins;
      expected += normal_cdf((w - 0.5) / std::sqrt(1.0 / 12.0)) / 100.0;
    }
    EXPECT_NEAR(static_cast<double>(kept[b]) / seen[b], expected, 0.02) << "bin " << b;
  }
}

TEST(RunningThreshold, WhileEveryWeightIsTheSameItAcceptsAsUniformWould) {
  // No feature anywhere: every weight 0. Nothing tells the candidates apart, so all are
  // accepted (a strict "exceeds" would accept none after the first two); a larger weight is
  // accepted too, a smaller one never.
  RunningThreshold threshold;
  Rng rng(3);
  for (int i = 0; i < 50; ++i) EXPECT_TRUE(threshold.accept(0.0, rng)) << "candidate " << i;
  EXPECT_EQ(threshold.variance(), 0.0);
  EXPECT_TRUE(threshold.accept(0.5, rng));
  RunningThreshold ones;
  for (int i = 0; i < 5; ++i) ones.accept(1.0, rng);
  EXPECT_FALSE(ones.accept(0.5, rng));
}

// Weight = x on free space 0 < x < 10: normalised weights w are U(0, 1), so past the
// threshold x has density proportional to Phi((w - 1/2) / sqrt(1/12)); Algorithm 2's line 12
// keeps it with probability w, giving density proportional to w Phi(...). Returns the mean x
// of 6000 samples and the one the density predicts.
std::pair<double, double> mean_accepted_x(SuAcceptance acceptance) {
  PredicateEnvironment env(box(0, 10, 0, 10), [](const Eigen::Vector3d& p) { return p.x() > 0.0; });
  ConfigurationSpace space(env, {});
  auto sampler = make_sensor_sampler(space, [](const Config& q) { return q[0]; }, "su", 100000, acceptance);
  Rng rng(12);
  double mean_x = 0.0;
  const int n = 6000;
  for (int i = 0; i < n; ++i) {
    const auto q = sampler->sample(rng);
    if (!q) return {-1.0, 0.0};
    mean_x += (*q)[0] / n;
  }
  double num = 0.0, den = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const double w = (k + 0.5) / 1000.0;
    const double p = normal_cdf((w - 0.5) / std::sqrt(1.0 / 12.0)) * (acceptance == SuAcceptance::kThreshold ? 1.0 : w);
    num += 10.0 * w * p;
    den += p;
  }
  return {mean_x, num / den};
}

TEST(SensorSampler, FavoursInformativeConfigurationsAsTheEkfParagraphDefines) {
  const auto [mean_x, expected] = mean_accepted_x(SuAcceptance::kThreshold);
  EXPECT_NEAR(mean_x, expected, 0.15);  // 6.78; the max normaliser settles near 10 within a few draws
  EXPECT_GT(mean_x, 5.5);               // clearly above the uniform sampler's 5
}

TEST(SensorSampler, Algorithm2AlsoKeepsWithProbabilityEqualToTheWeight) {
  const auto [mean_x, expected] = mean_accepted_x(SuAcceptance::kThresholdThenWeight);
  EXPECT_NEAR(mean_x, expected, 0.15);  // 7.54
  EXPECT_GT(mean_x, 7.0);               // far above the threshold alone's 6.78
}

TEST(SensorSampler, IsUniformWhileNoCandidateSeesAnything) {
  // Weight 0 everywhere (no feature in view anywhere): every valid candidate is added at
  // once, as the uniform sampler would (line 12's probability would be 0/0).
  PredicateEnvironment env(box(0, 10, 0, 10), [](const Eigen::Vector3d& p) { return p.x() > 0.0; });
  ConfigurationSpace space(env, {});
  auto sampler =
      make_sensor_sampler(space, [](const Config&) { return 0.0; }, "su", 100000, SuAcceptance::kThresholdThenWeight);
  Rng rng(5);
  for (int i = 0; i < 100; ++i) {
    SampleTrace trace;
    ASSERT_TRUE(sampler->sample(rng, &trace));
    EXPECT_EQ(trace.attempts, 1) << i;
  }
}

TEST(Samplers, RejectBadParameters) {
  PredicateEnvironment env(box(0, 1, 0, 1), [](const Eigen::Vector3d&) { return true; });
  ConfigurationSpace space(env, {});
  EXPECT_THROW(make_gaussian_sampler(space, 0.0), std::invalid_argument);
  EXPECT_THROW(make_bridge_sampler(space, -1.0), std::invalid_argument);
  EXPECT_THROW(ConfigurationSpace(env, SpaceOptions{0.0, 1.0, 1.0}), std::invalid_argument);
}

TEST(Samplers, GiveUpWhenNothingIsFree) {
  PredicateEnvironment env(box(0, 1, 0, 1), [](const Eigen::Vector3d&) { return false; });
  ConfigurationSpace space(env, {});
  Rng rng(13);
  EXPECT_FALSE(make_uniform_sampler(space, 100)->sample(rng));
  EXPECT_FALSE(make_gaussian_sampler(space, 1.0, 100)->sample(rng));
  EXPECT_FALSE(make_bridge_sampler(space, 1.0, 100)->sample(rng));
}

}  // namespace
}  // namespace kestrel::planner
