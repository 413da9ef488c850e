// Speed of the planner on the built-in floor (Release, one core): roadmap build with 100
// samples per sampler (BRM: with transfer functions), BRM search, and one edge transfer.
#include <benchmark/benchmark.h>

#include "planner/eval/experiment.h"
#include "planner/floor_plan.h"

namespace {

using namespace kestrel::planner;

struct Floor {
  GridEnvironment env{stata_like_floor(), 0.0, 3.0};
  Floor() { env.set_features(env.wall_features(4.0, 2.0, 1)); }
};
const Floor& floor_world() {
  static const Floor f;
  return f;
}

void BM_BuildBrm(benchmark::State& state, const char* sampler_name) {
  const auto& env = floor_world().env;
  const ConfigurationSpace space(env, {});
  const FeatureSensor sensor(env, FeatureSensorOptions::paper_camera());
  const BeliefModel model(MotionOptions{}, [&](const Config& q) { return sensor.information(q); });
  const auto pair = stata_like_pairs()[0];
  uint64_t seed = 1;
  for (auto _ : state) {
    Rng rng(seed++);
    auto sampler = eval::make_sampler(sampler_name, space, sensor, 0.1 * Mat4::Identity());
    benchmark::DoNotOptimize(build_roadmap(space, *sampler, pair.first, pair.second, {}, &model, rng));
  }
}
BENCHMARK_CAPTURE(BM_BuildBrm, su, "su")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BuildBrm, uniform, "uniform")->Unit(benchmark::kMillisecond);

void BM_SearchBrm(benchmark::State& state) {
  const auto& env = floor_world().env;
  const ConfigurationSpace space(env, {});
  const FeatureSensor sensor(env, FeatureSensorOptions::paper_camera());
  const BeliefModel model(MotionOptions{}, [&](const Config& q) { return sensor.information(q); });
  const auto pair = stata_like_pairs()[0];
  Rng rng(1);
  auto sampler = eval::make_sampler("su", space, sensor, 0.1 * Mat4::Identity());
  const Roadmap map = build_roadmap(space, *sampler, pair.first, pair.second, {}, &model, rng);
  BrmQuery q;
  q.start_covariance = 0.1 * Mat4::Identity();
  for (auto _ : state) benchmark::DoNotOptimize(belief_search(map, 0, 1, q));
}
BENCHMARK(BM_SearchBrm)->Unit(benchmark::kMicrosecond);

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
