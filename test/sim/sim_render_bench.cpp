// Rendering speed of the synthetic Kinect (one core, Release): one 640x480 RGB-D frame with
// the full sensor models, along each world's `loop` flight. The issue asks for <= 10 ms per
// frame and `kestrel sim --world stata --flight loop` at >= 3x real time.
//   ./kestrel bench Sim     (stata needs ../shared/data/maps/stata_basement.yaml)

#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <memory>

#include "drivers/sim/flights.h"
#include "drivers/sim/simulation.h"
#include "drivers/sim/world_catalog.h"

namespace {

using namespace kestrel::sim;

const World* world_named(const std::string& name) {
  static std::map<std::string, std::unique_ptr<World>> worlds;
  auto& w = worlds[name];
  if (!w) {
    const std::string map = std::string(KESTREL_SHARED_DATA) + "/maps/stata_basement.yaml";
    if (name == "stata" && !std::filesystem::exists(map)) return nullptr;
    w = std::make_unique<World>(load_world(name, name == "stata" ? map : ""));
  }
  return w.get();
}

// Frames along the loop flight, one per iteration (30 Hz flight time).
void BM_RenderLoop(benchmark::State& state, const std::string& name) {
  const World* world = world_named(name);
  if (!world) {
    state.SkipWithError("../shared/data/maps/stata_basement.yaml is absent");
    return;
  }
  const auto flight = make_flight("loop", *world);
  Simulation sim(*world, *flight, SimulationOptions{});
  int64_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(sim.render(k++ % 1800));
  state.SetItemsProcessed(state.iterations());
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

// One simulated second: 30 frames and 200 IMU samples (the tool's work without encoding).
void BM_SimulateSecond(benchmark::State& state, const std::string& name) {
  const World* world = world_named(name);
  if (!world) {
    state.SkipWithError("../shared/data/maps/stata_basement.yaml is absent");
    return;
  }
  const auto flight = make_flight("loop", *world);
  Simulation sim(*world, *flight, SimulationOptions{});
  for (auto _ : state)
    for (int i = 0; i < 230; ++i) benchmark::DoNotOptimize(sim.next());
  state.counters["times_real_time"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_RenderLoop, room, std::string("room"))->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_RenderLoop, floor, std::string("floor"))->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_RenderLoop, stata, std::string("stata"))->Unit(benchmark::kMillisecond)->MinTime(2.0);
// The first 30 frames of room's loop, exactly: for instruction counts that repeat
// (valgrind --tool=callgrind --toggle-collect='kestrel::sim::Renderer::render*' ... --benchmark_filter=frames30).
BENCHMARK_CAPTURE(BM_RenderLoop, room_frames30, std::string("room"))->Unit(benchmark::kMillisecond)->Iterations(30);
BENCHMARK_CAPTURE(BM_SimulateSecond, stata, std::string("stata"))->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK_CAPTURE(BM_SimulateSecond, floor, std::string("floor"))->Unit(benchmark::kMillisecond)->MinTime(3.0);

}  // namespace

BENCHMARK_MAIN();
