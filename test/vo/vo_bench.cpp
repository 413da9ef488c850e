// Speed of VisualOdometry::process() on the real fr1_xyz and fr1_rpy frames (decoded before
// timing), one thread: the median and p95 of the per-frame times of a whole-sequence run,
// reported as counters. Run: build/<dir>/bench/vo_bench (Release). Skips without the data.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "vo/sequence_run.h"
#include "vo/variants.h"

namespace {

using namespace kestrel;

void run(benchmark::State& state, const std::string& name, const std::string& variant) {
  const std::filesystem::path folder = std::filesystem::path(KESTREL_SHARED_DATA) / "tum" / name;
  if (!std::filesystem::exists(folder)) {
    state.SkipWithError(("absent: " + folder.string()).c_str());
    return;
  }
  static std::map<std::string, vo::LoadedSequence> cache;
  if (!cache.count(name)) cache.emplace(name, vo::load_tum_sequence(folder.string()));
  const vo::LoadedSequence& sequence = cache.at(name);
  const vo::VoOptions options = vo::with_tum_sensor(folder.string(), vo::variant(variant).options);
  std::vector<double> medians, p95s;
  for (auto _ : state) {
    const vo::SequenceRun r = vo::run_sequence(sequence.frames, options);
    const vo::RunFigures f = vo::score(r, Trajectory());
    medians.push_back(f.median_ms);
    p95s.push_back(f.p95_ms);
  }
  std::sort(medians.begin(), medians.end());
  std::sort(p95s.begin(), p95s.end());
  state.counters["median_ms"] = medians[medians.size() / 2];
  state.counters["p95_ms"] = p95s[p95s.size() / 2];
  state.counters["frames"] = double(sequence.frames.size());
}

}  // namespace

BENCHMARK_CAPTURE(run, fr1_xyz, std::string("rgbd_dataset_freiburg1_xyz"), std::string("default"))
    ->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(run, fr1_rpy, std::string("rgbd_dataset_freiburg1_rpy"), std::string("default"))
    ->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
