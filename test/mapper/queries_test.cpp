// The planner's queries on known geometry: a map with one occupied block, free space around
// it and unknown space beyond, where the exact answers follow from the cells' cubes.
#include <gtest/gtest.h>

#include <cmath>

#include "mapper/queries.h"
#include "mapper/voxel_map.h"

namespace kestrel::mapper {
namespace {

// Free cells fill [-1, 1]^3 m; the cells of [0.2, 0.4] x [-0.1, 0.1] x [-0.1, 0.1] m are occupied.
VoxelMap block_map() {
  VoxelMap map;
  const KeySpace& keys = map.keys();
  for (double z = -0.95; z < 1.0; z += 0.1)
    for (double y = -0.95; y < 1.0; y += 0.1)
      for (double x = -0.95; x < 1.0; x += 0.1) {
        Key k;
        EXPECT_TRUE(keys.key(x, y, z, k));
        const bool in_block = x > 0.2 && x < 0.4 && y > -0.1 && y < 0.1 && z > -0.1 && z < 0.1;
        map.update(k, in_block ? map.hit() : map.miss());
      }
  return map;
}

TEST(MapQueries, SphereAgainstTheBlockFaces) {
  const VoxelMap map = block_map();
  const MapQueries q(map);
  EXPECT_EQ(map.num_occupied(), 8u);
  // The block's -x face is at x = 0.2: a sphere at x = 0 touches it for r >= 0.2.
  EXPECT_TRUE(q.sphere_free({0.0, 0.0, 0.0}, 0.19));
  EXPECT_FALSE(q.sphere_free({0.0, 0.0, 0.0}, 0.21));
  // Diagonally off the corner (0.2, 0.1, 0.1): distance sqrt(0.1^2 + 0.1^2 + 0.1^2) from
  // (0.1, 0.2, 0.2); centre-distance bounds alone would get this wrong.
  const double corner = std::sqrt(0.03);
  EXPECT_TRUE(q.sphere_free({0.1, 0.2, 0.2}, corner - 0.005));
  EXPECT_FALSE(q.sphere_free({0.1, 0.2, 0.2}, corner + 0.005));
  EXPECT_THROW(q.sphere_free({0.0, 0.0, 0.0}, -1.0), std::invalid_argument);
}

TEST(MapQueries, SegmentsPassingTheBlock) {
  const VoxelMap map = block_map();
  const MapQueries q(map);
  // A segment at y = 0.3 along x passes 0.2 m from the block's +y face (y = 0.1).
  EXPECT_TRUE(q.segment_free({-0.5, 0.3, 0.0}, {0.8, 0.3, 0.0}, 0.18));
  EXPECT_FALSE(q.segment_free({-0.5, 0.3, 0.0}, {0.8, 0.3, 0.0}, 0.22));
  // The same segment stopped before the block's x range only meets it at the end's distance.
  EXPECT_TRUE(q.segment_free({-0.5, 0.3, 0.0}, {0.0, 0.3, 0.0}, 0.25));  // 0.2828 to the corner edge
  EXPECT_FALSE(q.segment_free({-0.5, 0.3, 0.0}, {0.0, 0.3, 0.0}, 0.30));
  // Straight through the block.
  EXPECT_FALSE(q.segment_free({-0.5, 0.0, 0.0}, {0.8, 0.0, 0.0}, 0.0));
  // NaN endpoints are never free.
  EXPECT_FALSE(q.segment_free({static_cast<double>(NAN), 0.0, 0.0}, {0.0, 0.0, 0.0}, 0.1));
}

TEST(MapQueries, UnknownBlocksUnlessToldOtherwise) {
  const VoxelMap map = block_map();
  // Free space ends at x = 1: beyond it is unknown.
  const Eigen::Vector3d a(0.5, -0.6, 0.5), b(1.5, -0.6, 0.5);
  EXPECT_FALSE(MapQueries(map).segment_free(a, b, 0.05));
  QueryOptions optimistic;
  optimistic.unknown_is_free = true;
  EXPECT_TRUE(MapQueries(map, optimistic).segment_free(a, b, 0.05));
  EXPECT_TRUE(MapQueries(map).segment_free({0.5, -0.6, 0.5}, {0.9, -0.6, 0.5}, 0.05));
}

TEST(MapQueries, DistanceToTheNearestOccupiedCell) {
  const VoxelMap map = block_map();
  const MapQueries q(map);
  EXPECT_NEAR(q.distance_to_occupied({0.0, 0.0, 0.0}, 2.0), 0.2, 1e-9);
  EXPECT_NEAR(q.distance_to_occupied({0.3, 0.0, 0.55}, 2.0), 0.45, 1e-9);
  EXPECT_NEAR(q.distance_to_occupied({0.1, 0.2, 0.2}, 2.0), std::sqrt(0.03), 1e-9);
  EXPECT_EQ(q.distance_to_occupied({0.25, 0.05, 0.05}, 2.0), 0.0);  // inside
  EXPECT_TRUE(std::isinf(q.distance_to_occupied({-0.8, 0.0, 0.0}, 0.5)));  // 1.0 away
  EXPECT_NEAR(q.distance_to_occupied({-0.8, 0.0, 0.0}, 1.5), 1.0, 1e-9);
}

}  // namespace
}  // namespace kestrel::mapper
