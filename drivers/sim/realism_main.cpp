// kestrel-sim-realism: the same image statistics (realism.h) of a real TUM RGB-D sequence and
// of a simulated flight, side by side, with their ratio: FAST corners per frame, valid depth
// fraction, depth noise at 1-3 m.

#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>

#include "common/cli.h"
#include "common/error.h"
#include "drivers/sim/flights.h"
#include "drivers/sim/realism.h"
#include "drivers/sim/simulation.h"
#include "drivers/sim/world_catalog.h"
#include "drivers/tum/tum_sequence.h"

namespace {

using namespace kestrel;

struct Options {
  std::string tum;
  std::string world = "room";
  std::string map;
  std::string flight = "aggressive";
  int frames = 200;
  uint64_t seed = 1;
};

int run(const Options& o) {
  // What the command line chose is checked before any input is read: a world or flight there
  // is not is a usage error (exit 2), as in `kestrel sim`; a bad folder or file is input (3).
  if (const std::string problem = sim::world_choice_error(o.world, o.map); !problem.empty())
    throw CLI::ValidationError("--world", problem);
  const sim::World world = sim::load_world(o.world, o.map);
  std::unique_ptr<sim::Flight> flight;
  try {
    flight = sim::make_flight(o.flight, world);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--flight", e.what());
  }
  std::vector<sim::FrameStats> real, simulated;
  const tum::TumSequence sequence(o.tum, tum::SequenceOptions{});
  for (size_t i = 0; i < sequence.size() && static_cast<int>(i) < o.frames; ++i)
    real.push_back(sim::frame_stats(sequence.frame(i)));
  sim::SimulationOptions so;
  so.seed = o.seed;
  sim::Simulation simulation(world, *flight, so);
  for (int k = 0; k < static_cast<int>(real.size()); ++k) simulated.push_back(sim::frame_stats(simulation.render(k)));
  const sim::SequenceStats r = sim::summarise(real), s = sim::summarise(simulated);
  std::printf("%-34s %14s %14s %8s\n", "median per frame", "real", "sim", "sim/real");
  auto row = [](const char* name, double a, double b) {
    const double ratio = a > 0 ? b / a : std::numeric_limits<double>::quiet_NaN();
    std::printf("%-34s %14.4g %14.4g %8.2f\n", name, a, b, ratio);
  };
  row("FAST corners (threshold 20)", r.fast_corners_median, s.fast_corners_median);
  row("valid depth fraction", r.valid_depth_median, s.valid_depth_median);
  row("depth noise k = sigma/z^2 (1/m)", r.noise_k_median, s.noise_k_median);
  row("mean grey", r.mean_grey_median, s.mean_grey_median);
  row("mean grey, 95th percentile", r.mean_grey_p95, s.mean_grey_p95);
  row("mean grey, brightest frame", r.mean_grey_max, s.mean_grey_max);
  row("pixels at 250+ (fraction)", r.saturated_median, s.saturated_median);
  row("pixels at 250+, most in a frame", r.saturated_max, s.saturated_max);
  row("frames with > 10 % at 250+", r.frames_over_a_tenth_saturated, s.frames_over_a_tenth_saturated);
  std::printf("frames: %d real (%s), %d sim (%s, %s, seed %llu); plane blocks: %d real, %d sim\n", r.frames,
              o.tum.c_str(), s.frames, world.name().c_str(), flight->name().c_str(),
              static_cast<unsigned long long>(o.seed), r.noise_blocks, s.noise_blocks);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("sim-realism", "Image statistics of a real TUM sequence and of a simulated flight, side by side");
  Options o;
  app.add_option("--tum", o.tum, "Real TUM RGB-D folder, e.g. ../shared/data/tum/rgbd_dataset_freiburg1_rpy")->required();
  app.add_option("--world", o.world, "Simulated world")->capture_default_str();
  app.add_option("--map", o.map, "Occupancy map for --world stata");
  app.add_option("--flight", o.flight, "Simulated flight")->capture_default_str();
  app.add_option("--frames", o.frames, "Frames of each")->check(CLI::Range(1, 100000))->capture_default_str();
  app.add_option("--seed", o.seed, "Sensor noise seed")->capture_default_str();
  return app.run(argc, argv, [&] { return run(o); });
}
