// The shipped `atrium` world as a planner environment (drivers/sim/worlds/atrium.world): the
// core blocks the straight lines through the middle, the outer walls carry the densities the
// file gives them, and the experiment's pairs are free and far apart.
#include <gtest/gtest.h>

#include "planner/experiment_worlds.h"

namespace kestrel::planner {
namespace {

TEST(AtriumWorld, CoreBlocksTheMiddleWallsKeepTheirDensitiesPairsAreFree) {
  const ExperimentWorld w = atrium_experiment_world({4.0, 1}, 0.3);
  const WorldEnvironment& env = *w.env;
  // The core is the box x in [5, 8], y in [9.5, 13.5], floor to ceiling.
  EXPECT_FALSE(env.is_free({6.5, 11.5, 1.0}, 0.05));
  EXPECT_TRUE(env.is_free({6.5, 8.5, 1.0}, 0.3));
  EXPECT_FALSE(env.segment_is_free({6.5, 1.5, 1.0}, {6.5, 21.5, 1.0}, 0.3));
  EXPECT_FALSE(env.line_of_sight({1.5, 11.5, 1.0}, {11.5, 11.5, 1.0}));
  EXPECT_TRUE(env.segment_is_free({1.0, 21.0, 1.0}, {12.0, 21.0, 1.0}, 0.3));  // the open north

  // Per square metre: the brick south wall (y = 0, 13 x 3 m) against the nearly blank east
  // wall (x = 13, texture 0.05, 23 x 3 m).
  double south = 0.0, east = 0.0;
  for (const Feature& f : env.features()) {
    if (std::abs(f.position.y()) < 1e-6 && f.normal.y() > 0.5) south += 1.0;
    if (std::abs(f.position.x() - 13.0) < 1e-6 && f.normal.x() < -0.5) east += 1.0;
  }
  EXPECT_GT(south / 39.0, 10.0 * std::max(0.05, east / 69.0)) << south << " south, " << east << " east";

  ASSERT_EQ(w.pairs.size(), 5u);
  double mean = 0.0;
  for (const auto& [a, b] : w.pairs) {
    const double d = (b - a).head<3>().norm();
    EXPECT_GE(d, 8.53);
    mean += d / 5.0;
    EXPECT_TRUE(env.is_free(position(a), 0.3));
    EXPECT_TRUE(env.is_free(position(b), 0.3));
  }
  EXPECT_NEAR(mean, 14.2, 0.1);
}

}  // namespace
}  // namespace kestrel::planner
