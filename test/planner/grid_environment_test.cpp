// Collision checks and line of sight on a grid with known geometry.
#include <gtest/gtest.h>

#include "planner/grid_environment.h"

namespace kestrel::planner {
namespace {

// 10 x 6 m at 0.1 m; a 0.1 m wall along x = 5 from y = 0 to y = 4 (a 2 m gap above it).
GridEnvironment wall_world() {
  OccupancyGrid g = make_grid(100, 60, 0.1, 0.05, 0.05);
  fill_rect(g, 4.95, 0.0, 5.05, 4.0, OccupancyGrid::kOccupied);
  return GridEnvironment(g, 0.0, 3.0);
}

TEST(GridEnvironment, FreeSpaceRespectsClearanceRadiusAndHeight) {
  const GridEnvironment env = wall_world();
  EXPECT_TRUE(env.is_free({2.0, 2.0, 1.0}, 0.3));
  EXPECT_FALSE(env.is_free({4.75, 2.0, 1.0}, 0.3));  // 0.2 m from the wall's face
  EXPECT_TRUE(env.is_free({4.5, 2.0, 1.0}, 0.3));    // 0.45 m, conservative by half a cell
  EXPECT_FALSE(env.is_free({5.0, 2.0, 1.0}, 0.01));  // inside the wall
  EXPECT_TRUE(env.is_free({5.0, 5.0, 1.0}, 0.3));    // in the gap
  EXPECT_FALSE(env.is_free({2.0, 2.0, 0.2}, 0.3));   // floor
  EXPECT_FALSE(env.is_free({2.0, 2.0, 2.8}, 0.3));   // ceiling
  EXPECT_FALSE(env.is_free({-1.0, 2.0, 1.0}, 0.1));  // outside the map
  EXPECT_FALSE(env.is_free({0.05, 2.0, 1.0}, 0.1));  // map edge: beyond it is unknown
  EXPECT_FALSE(env.is_free({static_cast<double>(NAN), 2.0, 1.0}, 0.1));
  EXPECT_NEAR(env.clearance({3.0, 2.0, 1.0}), 1.9, 0.1);
}

TEST(GridEnvironment, SegmentsAndSightLinesAreBlockedByTheWall) {
  const GridEnvironment env = wall_world();
  EXPECT_FALSE(env.segment_is_free({3.0, 2.0, 1.0}, {7.0, 2.0, 1.0}, 0.2));
  EXPECT_TRUE(env.segment_is_free({3.0, 5.0, 1.0}, {7.0, 5.0, 1.0}, 0.2));
  EXPECT_TRUE(env.segment_is_free({3.0, 1.0, 1.0}, {3.0, 5.0, 1.5}, 0.2));
  EXPECT_FALSE(env.line_of_sight({3.0, 2.0, 1.0}, {7.0, 2.0, 1.0}));
  EXPECT_TRUE(env.line_of_sight({3.0, 5.0, 1.0}, {7.0, 5.0, 1.0}));
  EXPECT_TRUE(env.line_of_sight({3.0, 2.0, 1.0}, {4.95, 2.0, 1.0}));  // a point on the wall's face
}

TEST(GridEnvironment, WallFeaturesSitOnWallsFacingFreeSpace) {
  const GridEnvironment env = wall_world();
  const std::vector<Feature> features = env.wall_features(20.0, 2.0, 3);
  ASSERT_GT(features.size(), 100u);
  for (const Feature& f : features) {
    EXPECT_NEAR(f.normal.norm(), 1.0, 1e-12);
    EXPECT_FALSE(env.is_free(f.position - 0.06 * f.normal, 0.0));  // behind it: the wall
    EXPECT_TRUE(env.is_free(f.position + 0.06 * f.normal, 0.0));   // in front: free space
    EXPECT_GE(f.position.z(), 0.0);
    EXPECT_LE(f.position.z(), 3.0);
  }
  // The same seed gives the same features; another seed other ones.
  EXPECT_EQ(env.wall_features(20.0, 2.0, 3).size(), features.size());
  EXPECT_NE(env.wall_features(20.0, 2.0, 4).size(), features.size());
}

TEST(GridEnvironment, RejectsInconsistentGrids) {
  OccupancyGrid g = make_grid(10, 10, 0.1, 0.0, 0.0);
  g.cells.pop_back();
  EXPECT_THROW(GridEnvironment(g, 0.0, 3.0), std::invalid_argument);
  EXPECT_THROW(GridEnvironment(make_grid(10, 10, 0.1, 0.0, 0.0), 3.0, 3.0), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::planner
