// The sim's worlds as planner environments: collision and line of sight against the shipped
// `floor` world's known walls, features following the walls' textures, the experiment pairs,
// and the stata world skipped without its map and named in errors with a bad one.
#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "planner/experiment_worlds.h"
#include "planner/sensor_model.h"
#include "test/support/test_support.h"

namespace kestrel::planner {
namespace {

// Building a world generates its textures (seconds): one load serves every test here.
const ExperimentWorld& floor_experiment() {
  static const ExperimentWorld w = floor_experiment_world({4.0, 1}, 0.3);
  return w;
}
const sim::World& floor_world() { return *floor_experiment().world; }

TEST(WorldEnvironment, CollisionsSightAndPairsFollowTheFloorsWalls) {
  // floor.world: corridor walls at x = 5.5 and 7.5 (0.15 m thick); the west one is solid for
  // y in [0, 4], with a door gap for y in (4, 5).
  const WorldEnvironment env(floor_world());
  EXPECT_TRUE(env.is_free({6.5, 2.0, 1.0}, 0.3));    // mid-corridor
  EXPECT_FALSE(env.is_free({5.5, 2.0, 1.0}, 0.05));  // in the wall
  EXPECT_FALSE(env.is_free({5.8, 2.0, 1.0}, 0.3));   // 0.22 m from its face
  EXPECT_FALSE(env.is_free({6.5, 2.0, 2.9}, 0.3));   // touching the ceiling
  EXPECT_TRUE(env.segment_is_free({6.5, 1.0, 1.0}, {6.5, 9.0, 1.0}, 0.3));   // along the corridor
  EXPECT_FALSE(env.segment_is_free({3.0, 2.0, 1.0}, {6.5, 2.0, 1.0}, 0.3));  // through the wall
  EXPECT_TRUE(env.segment_is_free({3.0, 4.5, 1.0}, {6.5, 4.5, 1.0}, 0.3));   // through the door
  EXPECT_FALSE(env.line_of_sight({3.0, 2.0, 1.0}, {6.5, 2.0, 1.0}));
  EXPECT_TRUE(env.line_of_sight({6.5, 2.0, 1.0}, {6.5, 8.0, 1.0}));
  // A point on the wall's corridor face is seen from the corridor.
  EXPECT_TRUE(env.line_of_sight({6.5, 2.0, 1.0}, {5.575, 2.0, 1.0}));

  // The experiment's start/goal pairs are free and far apart.
  const ExperimentWorld& w = floor_experiment();
  ASSERT_EQ(w.pairs.size(), 5u);
  for (const auto& [a, b] : w.pairs) {
    EXPECT_GE((b - a).head<3>().norm(), 8.53);
    EXPECT_TRUE(w.env->is_free(position(a), 0.3));
    EXPECT_TRUE(w.env->is_free(position(b), 0.3));
  }
  EXPECT_FALSE(w.env->features().empty());
}

TEST(WorldEnvironment, FeaturesFollowTheWallsTexturesAndAreSeenFromTheirSide) {
  WorldEnvironment env(floor_world());
  const size_t n = env.place_features({4.0, 7});
  double area = 0.0;
  for (const sim::Surface& s : floor_world().surfaces())
    if (s.is_vertical()) area += s.area();
  // Poisson counts: the total is within 5 standard deviations of its mean.
  EXPECT_NEAR(static_cast<double>(n), 4.0 * area, 5.0 * std::sqrt(4.0 * area));
  // Per square metre of the east corridor wall's face (x = 7.425, facing -x): concrete for
  // y in [7, 10.5] against blank plaster (texture 0.03) for y in [12.5, 19].
  int blank = 0, textured = 0;
  Eigen::AlignedBox3d bounds = floor_world().bounds();
  bounds.extend(bounds.min() - Eigen::Vector3d::Constant(1e-9)).extend(bounds.max() + Eigen::Vector3d::Constant(1e-9));
  for (const Feature& f : env.features()) {
    EXPECT_NEAR(f.normal.z(), 0.0, 1e-12);
    EXPECT_TRUE(bounds.contains(f.position));
    if (std::abs(f.position.x() - 7.425) > 1e-6 || f.normal.x() > -0.5) continue;
    if (f.position.y() > 12.6 && f.position.y() < 18.9) ++blank;
    if (f.position.y() > 7.1 && f.position.y() < 10.4) ++textured;
  }
  EXPECT_GT(textured / 3.3, 10.0 * std::max(0.1, blank / 6.3)) << blank << " blank, " << textured << " textured";
  // Deterministic for the seed.
  WorldEnvironment again(floor_world());
  again.place_features({4.0, 7});
  ASSERT_EQ(again.features().size(), n);
  EXPECT_EQ(again.features()[n / 2].position, env.features()[n / 2].position);

  // The camera sees wall features only from their side (in this test: each ctest process
  // loads the world again). Facing the concrete corridor wall at x = 7.5 from 1.2 m: features
  // seen, all on that face; from the far side of that wall (the east room) none of them.
  WorldEnvironment dense(floor_world());
  dense.place_features({20.0, 1});
  const FeatureSensor camera(dense, FeatureSensorOptions::paper_camera());
  const std::vector<int> seen = camera.visible(Config(6.2, 9.0, 1.0, 0.0));
  ASSERT_FALSE(seen.empty());
  for (int i : seen) EXPECT_NEAR(dense.features()[i].position.x(), 7.425, 1e-6);
  EXPECT_GT(camera.information(Config(6.2, 9.0, 1.0, 0.0)).trace(), 0.0);
  for (int i : camera.visible(Config(8.7, 9.0, 1.0, M_PI))) EXPECT_GT(dense.features()[i].position.x(), 7.5);
}

TEST(ExperimentWorlds, StataIsSkippedWithoutItsMapAndBadMapsAreNamed) {
  kestrel::test::TempDir dir;
  EXPECT_FALSE(stata_experiment_world((dir / "absent.yaml").string(), {}, 0.3).has_value());
  const std::string bad = (dir / "bad.yaml").string();
  std::ofstream(bad) << "image: missing.png\nresolution: 0.05\norigin: [0, 0, 0]\n";
  try {
    stata_experiment_world(bad, {}, 0.3);
    FAIL() << "a map whose image is missing was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kestrel::planner
