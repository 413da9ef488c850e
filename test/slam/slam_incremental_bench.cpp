// The SLAM back-end's re-optimisation after one new loop closure (issue 6: <= 10 ms for a
// 1000-keyframe graph): a noisy helix of 1000 keyframes with loop closures, already optimised,
// gets keyframe 1001 with its odometry edge and one loop closure, and is optimised again with
// the back-end's options (SlamOptions::default_optimizer: DCS kernel, chordal start tried and
// kept only if better), and without the chordal attempt. Processor time, single-threaded:
//
//   OMP_THREAD_LIMIT=1 taskset -c 0 build/<dir>/bench/slam_incremental_bench

#include <benchmark/benchmark.h>

#include <ctime>

#include "slam/backend/slam_options.h"
#include "test/slam/synthetic_graphs.h"

namespace {

using namespace kestrel::slam;

struct Scenario {
  PoseGraph3d before;                // 1001 vertices, optimised, the last one by odometry only
  std::vector<PoseGraph3d::Edge> new_loops;  // the closure(s) of the newest keyframe
};

Scenario make_scenario() {
  test::SyntheticOptions o;
  o.num_poses = 1001;
  o.poses_per_turn = 40;
  o.loop_stride = 4;
  o.translation_sigma = 0.01;
  o.rotation_sigma = 0.002;
  PoseGraph3d full = test::helix_graph(o);
  Scenario s;
  s.before = full;
  s.before.edges.clear();
  const int newest = full.num_vertices() - 1;
  for (const auto& e : full.edges) {
    const bool closes_newest = e.kind == EdgeKind::kLoopClosure && (e.from == newest || e.to == newest);
    (closes_newest ? s.new_loops : s.before.edges).push_back(e);
  }
  // Keep one closure: "one new loop closure".
  s.new_loops.resize(std::min<size_t>(s.new_loops.size(), 1));
  test::chain_odometry(s.before);
  optimize(s.before, SlamOptions::default_optimizer());
  return s;
}

void bench(benchmark::State& state, bool chordal) {
  static const Scenario scenario = make_scenario();
  if (scenario.new_loops.empty()) {
    state.SkipWithError("the scenario has no loop closure into the newest keyframe");
    return;
  }
  OptimizerOptions options = SlamOptions::default_optimizer();
  options.chordal_initialization = chordal;
  OptimizerSummary s;
  for (auto _ : state) {
    PoseGraph3d g = scenario.before;
    for (const auto& e : scenario.new_loops) g.edges.push_back(e);
    const std::clock_t start = std::clock();
    s = optimize(g, options);
    state.SetIterationTime(static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC);
  }
  state.counters["V"] = scenario.before.num_vertices();
  state.counters["E"] = scenario.before.num_edges() + 1;
  state.counters["iterations"] = s.iterations;
  state.counters["chi2_start"] = s.initial_chi2;
  state.counters["chi2"] = s.final_chi2;
  state.counters["chordal_used"] = s.used_chordal;
}

BENCHMARK_CAPTURE(bench, with_chordal_attempt, true)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(bench, warm_start_only, false)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
