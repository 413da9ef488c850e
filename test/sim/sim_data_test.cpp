// The synthetic world against the real data in ../shared/data (read in place; skipped when
// absent): the `stata` world extruded from the MIT Stata basement map and its loop flight,
// and image statistics side by side with the real Kinect frames of fr1_rpy.

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>

#include "drivers/sim/flights.h"
#include "drivers/sim/realism.h"
#include "drivers/sim/simulation.h"
#include "drivers/sim/world_catalog.h"
#include "drivers/tum/tum_sequence.h"
#include "test/support/test_support.h"

namespace kestrel::sim {
namespace {

TEST(StataTest, LoopThroughTheBasementIsLongCollisionFreeAndComesBack) {
  const auto data = kestrel::test::shared_data();
  const auto map = data / "maps" / "stata_basement.yaml";
  if (data.empty() || !std::filesystem::exists(map)) KESTREL_SKIP_ENVIRONMENT() << "../shared/data/maps/stata_basement.yaml is absent";
  const World world = load_world("stata", map.string());
  EXPECT_GT(world.surfaces().size(), 100u);
  EXPECT_GT(world.bounds().sizes().x(), 50.0);  // the map is 87 x 65 m
  const auto flight = make_flight("loop", world);
  const auto& tour = dynamic_cast<const SplineFlight&>(*flight);
  EXPECT_GT(tour.period_s(), 120.0);
  EXPECT_LT(first_collision(*flight, world, 0.35, flight->ramp_s() + tour.period_s()), 0.0);
  const double t0 = flight->ramp_s() + 1.0;
  double farthest = 0.0;
  for (double t = t0; t < t0 + tour.period_s(); t += 1.0)
    farthest = std::max(farthest, (flight->point(t).p - flight->point(t0).p).norm());
  EXPECT_GT(farthest, 20.0);
  Simulation sim(world, *flight, SimulationOptions{});
  for (int k : {0, 300, 900}) {
    const RgbdFrame frame = sim.render(k);
    EXPECT_GT(cv::countNonZero(frame.depth_mm), 0.2 * frame.depth_mm.total()) << "frame " << k;
  }
}

TEST(RealismTest, FloorFramesAreWithinAFactorOfTwoOfRealKinectFrames) {
  KESTREL_REQUIRE_TUM(folder, "rgbd_dataset_freiburg1_rpy");
  const tum::TumSequence sequence(folder.string(), tum::SequenceOptions{});
  std::vector<FrameStats> real, simulated;
  for (size_t i = 0; i < 30; ++i) real.push_back(frame_stats(sequence.frame(i * 6)));
  const World world = load_world("floor");
  const auto flight = make_flight("loop", world);
  Simulation sim(world, *flight, SimulationOptions{});
  for (int k = 0; k < 30; ++k) simulated.push_back(frame_stats(sim.render(k * 10)));
  const SequenceStats r = summarise(real), s = summarise(simulated);
  auto within_two = [](double a, double b) { return b > 0.5 * a && b < 2.0 * a; };
  EXPECT_TRUE(within_two(r.fast_corners_median, s.fast_corners_median)) << r.fast_corners_median << " vs " << s.fast_corners_median;
  EXPECT_TRUE(within_two(r.valid_depth_median, s.valid_depth_median)) << r.valid_depth_median << " vs " << s.valid_depth_median;
  EXPECT_TRUE(within_two(r.noise_k_median, s.noise_k_median)) << r.noise_k_median << " vs " << s.noise_k_median;
}

}  // namespace
}  // namespace kestrel::sim
