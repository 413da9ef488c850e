// The sim's worlds as planner environments: collision and line of sight against the shipped
// `floor` world's known walls, features following the walls' textures, the experiment pairs,
// and the stata world skipped without its map and named in errors with a bad one.
#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "common/numbers.h"
#include "planner/configuration_space.h"
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
  for (int i : camera.visible(Config(8.7, 9.0, 1.0, kPi))) EXPECT_GT(dense.features()[i].position.x(), 7.5);
}

// line_of_sight (the fine grid and the sim's ray tests, stopping at the first hit) and
// lines_of_sight (all rays from one point against the obstacles gathered once) against the
// sim's ray cast, from poses all over `env`'s world to every feature within 6 m, to random
// points, along and across the axes (rays in one fine column), onto the walls' corners.
void expect_fast_sight_equals_raycast(const WorldEnvironment& env, int poses, uint64_t seed) {
  Rng rng(seed);
  const Eigen::AlignedBox3d b = env.bounds();
  std::uniform_real_distribution<double> ux(b.min().x(), b.max().x()), uy(b.min().y(), b.max().y()), uz(0.1, 2.9);
  std::vector<Eigen::Vector3d> corners;
  for (const sim::Surface& s : env.world().surfaces())
    if (s.is_vertical())
      for (const auto& c : s.corners()) corners.push_back(c);
  int clear = 0, blocked = 0;
  std::vector<Eigen::Vector3d> targets;
  std::vector<char> expected, batch;
  const auto check = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& p) {
    const bool fast = env.line_of_sight(a, p), plain = env.line_of_sight_by_raycast(a, p);
    ASSERT_EQ(fast, plain) << a.transpose() << " -> " << p.transpose();
    ++(fast ? clear : blocked);
    targets.push_back(p);
    expected.push_back(plain ? 1 : 0);
  };
  for (int k = 0; k < poses; ++k) {
    targets.clear();
    expected.clear();
    Eigen::Vector3d a(ux(rng), uy(rng), 1.0);
    if (k % 3 == 0) a.z() = uz(rng);
    if (k % 7 == 0) a.x() = std::round(a.x() * 2.0) / 2.0;  // on a fine cell's edge
    for (const Feature& f : env.features())
      if ((f.position - a).norm() < 6.0) check(a, f.position);
    for (int i = 0; i < 40; ++i) check(a, Eigen::Vector3d(ux(rng), uy(rng), uz(rng)));
    for (const Eigen::Vector3d& step : {Eigen::Vector3d(3, 0, 0), Eigen::Vector3d(0, 3, 0), Eigen::Vector3d(0, -4, 0),
                                        Eigen::Vector3d(-4, 0, 0), Eigen::Vector3d(1e-4, 3, 0), Eigen::Vector3d(0, 0, 1.5),
                                        Eigen::Vector3d(2e-3, 4, 0.2)})
      check(a, a + step);
    for (int i = 0; i < 20; ++i) check(a, corners[static_cast<size_t>(rng() % corners.size())]);
    env.lines_of_sight(a, targets, batch);
    ASSERT_EQ(batch, expected) << "from " << a.transpose();
    // Only the features: a smaller gathering box.
    const size_t n_features = targets.size() - 40 - 7 - 20;
    targets.resize(n_features);
    env.lines_of_sight(a, targets, batch);
    ASSERT_EQ(batch, std::vector<char>(expected.begin(), expected.begin() + static_cast<long>(n_features)));
  }
  EXPECT_GT(clear, 100);
  EXPECT_GT(blocked, 100);
}

TEST(WorldEnvironment, FastLineOfSightEqualsTheSimsRaycast) {
  expect_fast_sight_equals_raycast(*floor_experiment().env, 300, 21);
  // And the Kinect's visibility through it equals the definition's (features and M).
  const ExperimentWorld& w = floor_experiment();
  const FeatureSensor kinect(*w.env, FeatureSensorOptions::kinect());
  const ConfigurationSpace space(*w.env, {});
  Rng rng(4);
  size_t seen = 0;
  for (int k = 0; k < 200; ++k) {
    const Config q = space.uniform(rng);
    if (!space.is_valid(q)) continue;
    const std::vector<int> fast = kinect.visible(q);
    ASSERT_EQ(fast, kinect.visible_reference(q));
    seen += fast.size();
  }
  EXPECT_GT(seen, 1000u);
}

TEST(WorldEnvironment, FastLineOfSightEqualsTheSimsRaycastInStata) {
  const auto map = kestrel::test::shared_data() / "maps" / "stata_basement.yaml";
  auto stata = stata_experiment_world(map.string(), {4.0, 1}, 0.3);
  if (!stata) KESTREL_SKIP_ENVIRONMENT() << map << " is absent";
  expect_fast_sight_equals_raycast(*stata->env, 300, 22);
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
