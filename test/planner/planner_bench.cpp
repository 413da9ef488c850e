// Speed of the planner in the sim's `floor` world (Release, one core): roadmap build with 100
// samples per sampler (BRM: with transfer functions; the paper camera and the Kinect model,
// whose 4 m range makes line of sight the cost), BRM search (Algorithm 1's trace rule and
// covariance dominance, exact and with 1 % slack), the two sensor-uncertainty
// weights per candidate (EKF tr(M), UKF I(x)), the Kinect's M at one pose, and one edge
// transfer.
#include <benchmark/benchmark.h>

#include "planner/eval/experiment.h"
#include "planner/samplers.h"
#include "planner/experiment_worlds.h"

namespace {

using namespace kestrel::planner;

const ExperimentWorld& floor() {
  static const ExperimentWorld w = floor_experiment_world({4.0, 1}, 0.3);
  return w;
}

void BM_BuildBrm(benchmark::State& state, const char* sampler_name, bool kinect) {
  const Environment& env = *floor().env;
  const ConfigurationSpace space(env, {});
  const FeatureSensor sensor(env, kinect ? FeatureSensorOptions::kinect() : FeatureSensorOptions::paper_camera());
  const BeliefModel model(MotionOptions{}, [&](const Config& q) { return sensor.information(q); });
  const auto pair = floor().pairs[0];
  uint64_t seed = 1;
  for (auto _ : state) {
    Rng rng(seed++);
    auto sampler = make_sampler(sampler_name, space, sensor, 0.1 * Mat4::Identity());
    benchmark::DoNotOptimize(build_roadmap(space, *sampler, pair.first, pair.second, RoadmapOptions::all_pairs(), &model, rng));
  }
}
BENCHMARK_CAPTURE(BM_BuildBrm, su, "su", false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BuildBrm, uniform, "uniform", false)->Unit(benchmark::kMillisecond);
// Fig. 13's build: BRM-SU, 100 samples, all pairs, the Kinect model.
BENCHMARK_CAPTURE(BM_BuildBrm, su_kinect, "su", true)->Unit(benchmark::kMillisecond);

void BM_SearchBrm(benchmark::State& state, BrmPruning pruning, double slack) {
  const Environment& env = *floor().env;
  const ConfigurationSpace space(env, {});
  const FeatureSensor sensor(env, FeatureSensorOptions::paper_camera());
  const BeliefModel model(MotionOptions{}, [&](const Config& q) { return sensor.information(q); });
  const auto pair = floor().pairs[0];
  Rng rng(1);
  auto sampler = make_sampler("su", space, sensor, 0.1 * Mat4::Identity());
  const Roadmap map = build_roadmap(space, *sampler, pair.first, pair.second, RoadmapOptions::all_pairs(), &model, rng);
  BrmQuery q;
  q.start_covariance = 0.1 * Mat4::Identity();
  q.pruning = pruning;
  q.dominance_slack = slack;
  for (auto _ : state) benchmark::DoNotOptimize(belief_search(map, 0, 1, q));
}
BENCHMARK_CAPTURE(BM_SearchBrm, trace, BrmPruning::kTrace, 0.0)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SearchBrm, dominance_exact, BrmPruning::kCovarianceDominance, 0.0)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SearchBrm, dominance_slack_1pct, BrmPruning::kCovarianceDominance, 0.01)
    ->Unit(benchmark::kMicrosecond);

// The sampler's weight at valid uniform candidates: tr(M) (EKF) and I(x) (UKF, eq. 27).
void BM_Weight(benchmark::State& state, bool ukf) {
  const Environment& env = *floor().env;
  const ConfigurationSpace space(env, {});
  const FeatureSensor sensor(env, FeatureSensorOptions::paper_camera());
  Rng rng(3);
  std::vector<Config> qs;
  while (qs.size() < 256) {
    const Config q = space.uniform(rng);
    if (space.is_valid(q)) qs.push_back(q);
  }
  const Mat4 prior = 0.1 * Mat4::Identity();
  size_t i = 0;
  for (auto _ : state) {
    const Config& q = qs[i++ % qs.size()];
    benchmark::DoNotOptimize(ukf ? sensor.ukf_information_gain(q, prior) : sensor.information(q).trace());
  }
}
BENCHMARK_CAPTURE(BM_Weight, ekf_trace, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Weight, ukf_gain, true)->Unit(benchmark::kMicrosecond);

// The Kinect's M(q) at valid uniform poses (what every edge step evaluates in Fig. 13).
void BM_KinectInformation(benchmark::State& state) {
  const Environment& env = *floor().env;
  const ConfigurationSpace space(env, {});
  const FeatureSensor sensor(env, FeatureSensorOptions::kinect());
  Rng rng(5);
  std::vector<Config> qs;
  while (qs.size() < 256) {
    const Config q = space.uniform(rng);
    if (space.is_valid(q)) qs.push_back(q);
  }
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(sensor.information(qs[i++ % qs.size()]));
}
BENCHMARK(BM_KinectInformation)->Unit(benchmark::kMicrosecond);

void BM_TransferApply(benchmark::State& state) {
  BeliefStep s;
  s.R = 0.01 * Mat4::Identity();
  s.M = Mat4::Identity();
  const ScatteringTransfer t = ScatteringTransfer::from_steps(std::vector<BeliefStep>(20, s));
  const Mat4 sigma = Mat4::Identity();
  for (auto _ : state) benchmark::DoNotOptimize(t.apply(sigma));
}
BENCHMARK(BM_TransferApply);

}  // namespace

BENCHMARK_MAIN();
