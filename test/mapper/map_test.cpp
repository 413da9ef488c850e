// The map equals OctoMap's OcTree after the same scans (every log-odds value, and the .bt / .ot
// streams byte for byte); a known box scene gives the expected occupied, free and unknown
// cells; forgetting clears a moved obstacle; files round-trip; bad files are InputErrors.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "common/error.h"
#include "common/numbers.h"
#include "mapper/map_compare.h"
#include "mapper/octree_io.h"
#include "mapper/scan.h"
#include "mapper/scan_integrator.h"
#include "mapper/voxel_map.h"
#include "test/mapper/octomap_reference.h"
#include "test/mapper/scene.h"
#include "test/support/test_support.h"

namespace kestrel::mapper {
namespace {

using test::Scene;

// A 4 x 4 x 2.5 m room with a 0.6 m box on the floor; cameras circling the box.
Scene box_scene() {
  Scene scene(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(2.0, 2.0, 2.5));
  scene.add_box(Eigen::Vector3d(0.3, -0.3, 0.0), Eigen::Vector3d(0.9, 0.3, 0.6));
  return scene;
}

std::vector<Eigen::Isometry3d> circle_poses(int n, double radius, const Eigen::Vector3d& target) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * kPi * i / n;
    poses.push_back(test::look_at(
        target + Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), 0.0) +
            Eigen::Vector3d(0.013, 0.027, 0.6 + 0.011 * i),
        target));
  }
  return poses;
}

std::string octree_bytes(octomap::OcTree& tree, bool binary) {
  std::ostringstream out;
  if (binary) {
    tree.writeBinaryConst(out);
  } else {
    tree.write(out);
  }
  return out.str();
}

TEST(VoxelMap, EqualsOctomapInsertPointCloudValueForValue) {
  const Scene scene = box_scene();
  ScanOptions options;
  options.stride = 1;
  options.max_range_m = 3.0;
  ScanIntegrator integrator(0.1, options);
  VoxelMap map;
  octomap::OcTree reference(0.1);
  int64_t utime = 0;
  for (const auto& T : circle_poses(16, 1.6, {0.6, 0.0, 0.3})) {
    const Scan scan = make_scan(scene.render(test::kinect_camera(128, 96), T, utime), T,
                                options, "test");
    ScanUpdate update;
    integrator.compute(scan, update);
    map.integrate(update, utime);
    reference.insertPointCloud(scan.valid_points(), scan.origin, options.max_range_m);
    utime += 33333;
  }
  // Every leaf of OctoMap's tree, expanded to cells, has exactly our value, and vice versa.
  const size_t cells = test::expect_values_equal(map, reference);
  EXPECT_EQ(cells, map.num_cells());
  EXPECT_GT(map.num_occupied(), 50u);

  // The OcTree we build is OctoMap's, down to the bytes of both file formats.
  const auto mine = to_octree(map);
  EXPECT_EQ(mine->size(), reference.size());
  EXPECT_EQ(octree_bytes(*mine, true), octree_bytes(reference, true));
  EXPECT_EQ(octree_bytes(*mine, false), octree_bytes(reference, false));
}

TEST(VoxelMap, DiscretizedEqualsOctomapDiscretizedInsertPointCloudValueForValue) {
  const Scene scene = box_scene();
  ScanOptions options;
  options.stride = 2;
  options.max_range_m = 2.0;  // cuts the far walls' rays
  options.discretize = true;
  ScanIntegrator integrator(0.1, options);
  VoxelMap map;
  octomap::OcTree reference(0.1);
  int64_t utime = 0;
  for (const auto& T : circle_poses(12, 1.6, {0.6, 0.0, 0.3})) {
    const Scan scan = make_scan(decimate(scene.render(test::kinect_camera(), T, utime), options.stride), T,
                                options, "test");
    ScanUpdate update;
    integrator.compute(scan, update);
    map.integrate(update, utime);
    reference.insertPointCloud(scan.valid_points(), scan.origin, options.max_range_m, false, true);
    utime += 33333;
  }
  const size_t cells = test::expect_values_equal(map, reference);
  EXPECT_EQ(cells, map.num_cells());
  EXPECT_GT(map.num_occupied(), 50u);
  const auto mine = to_octree(map);
  EXPECT_EQ(octree_bytes(*mine, true), octree_bytes(reference, true));
}

TEST(MapCompare, CountsAgreementAndClassDifferences) {
  // a: two occupied cells side by side, one free cell, one free cell b does not know;
  // b: the first occupied cell, the second one free, the free cell occupied, and a cell of its
  // own one cell away from a's second occupied cell.
  VoxelMap a, b;
  const Key k1(100, 100, 100), k2(101, 100, 100), k3(100, 102, 100), k4(90, 90, 90), k5(102, 101, 100);
  a.set(k1, 2.0f);
  a.set(k2, 2.0f);
  a.set(k3, -1.0f);
  a.set(k4, -1.0f);
  b.set(k1, 2.0f);
  b.set(k2, -1.0f);
  b.set(k3, 2.0f);
  b.set(k5, 2.0f);
  const MapAgreement r = compare_maps(a, b);
  EXPECT_EQ(r.known_a, 4u);
  EXPECT_EQ(r.known_b, 4u);
  EXPECT_EQ(r.known_both, 3u);
  EXPECT_EQ(r.same_class, 1u);
  EXPECT_EQ(r.free_a_occupied_b, 1u);  // k3
  EXPECT_EQ(r.occupied_a_free_b, 1u);  // k2
  EXPECT_EQ(r.occupied_a, 2u);
  EXPECT_EQ(r.occupied_b, 3u);
  EXPECT_EQ(r.occupied_both, 1u);
  EXPECT_EQ(r.occupied_a_matched, 2u);  // k2 has k1 and k5 next to it
  EXPECT_EQ(r.occupied_b_matched, 2u);  // k1, and k5 next to k2; k3 is two cells from both
}

TEST(VoxelMap, KnownBoxSceneGivesExpectedCells) {
  const Scene scene = box_scene();
  ScanOptions options;
  options.stride = 1;
  ScanIntegrator integrator(0.1, options);
  VoxelMap map;
  int64_t utime = 0;
  for (const auto& T : circle_poses(24, 1.5, {0.6, 0.0, 0.3})) {
    ScanUpdate update;
    integrator.compute(make_scan(scene.render(test::kinect_camera(320, 240), T, utime), T,
                                 options, "test"),
                       update);
    map.integrate(update, utime += 33333);
  }
  const KeySpace& keys = map.keys();
  auto at = [&](double x, double y, double z) { return map.occupancy_at({x, y, z}); };
  // The box's top and visible sides are occupied; its inside was never seen: unknown.
  EXPECT_EQ(at(0.55, 0.05, 0.55), Occupancy::kOccupied);  // top layer
  EXPECT_EQ(at(0.35, 0.05, 0.35), Occupancy::kOccupied);  // -x face
  EXPECT_EQ(at(0.65, -0.25, 0.25), Occupancy::kOccupied); // -y face
  EXPECT_EQ(at(0.55, 0.05, 0.25), Occupancy::kUnknown);   // inside
  // The air around the box, between it and the cameras, is free.
  EXPECT_EQ(at(0.05, 0.05, 0.35), Occupancy::kFree);
  EXPECT_EQ(at(0.65, 0.55, 0.45), Occupancy::kFree);
  EXPECT_EQ(at(0.55, 0.05, 0.85), Occupancy::kFree);
  // Outside the room nothing is known.
  EXPECT_EQ(at(2.55, 0.05, 1.0), Occupancy::kUnknown);
  EXPECT_EQ(at(0.0, 0.0, -0.55), Occupancy::kUnknown);

  // Every cell strictly inside the box (more than a cell from its faces) is unknown, and no
  // free cell lies inside the box.
  size_t inside_known = 0, free_in_box = 0;
  map.for_each_cell([&](const Key& k, float v) {
    const Eigen::Vector3d c(keys.centre(k[0]), keys.centre(k[1]), keys.centre(k[2]));
    const bool in_box = c.x() > 0.3 && c.x() < 0.9 && c.y() > -0.3 && c.y() < 0.3 && c.z() < 0.6;
    const bool deep = c.x() > 0.4 && c.x() < 0.8 && c.y() > -0.2 && c.y() < 0.2 && c.z() < 0.5;
    inside_known += deep;
    free_in_box += in_box && map.occupancy(v) == Occupancy::kFree;
  });
  EXPECT_EQ(inside_known, 0u);
  EXPECT_EQ(free_in_box, 0u);
}

TEST(VoxelMap, UpdatesClampLikeOctomap) {
  VoxelMap map;
  octomap::OcTree tree(0.1);
  const Key k(32768, 32768, 32768);
  const float changes[] = {map.hit(), map.hit(), map.hit(), map.hit(), map.hit(), map.miss(),
                           map.miss(), map.miss(), map.miss(), map.miss(), map.miss(), map.miss(),
                           map.miss(), map.miss(), map.miss(), map.hit()};
  for (const float c : changes) {
    map.update(k, c);
    tree.updateNode(k, c);
    ASSERT_EQ(*map.log_odds(k), tree.search(k)->getLogOdds());
  }
  // 5 hits clamp at 3.5, 10 misses bring it to -0.55, the last hit to +0.30: occupied.
  EXPECT_EQ(map.occupancy(k), Occupancy::kOccupied);
  map.update(k, 100.0f);
  EXPECT_EQ(*map.log_odds(k), map.clamp_max());
  EXPECT_EQ(map.occupancy(Key(1, 2, 3)), Occupancy::kUnknown);
}

TEST(VoxelMap, CopiesAndMovesKeepTheirOwnCells) {
  // The brick cache in front of the hash table must never let one map reach another's bricks.
  VoxelMap a;
  for (uint16_t i = 0; i < 40; ++i) a.update(Key(32768 + i, 32768 + 2 * i, 32760), a.hit());
  VoxelMap copy = a;
  copy.update(Key(32768, 32768, 32760), copy.miss());
  EXPECT_EQ(*a.log_odds(Key(32768, 32768, 32760)), a.hit());
  VoxelMap moved = std::move(a);
  EXPECT_EQ(moved.num_cells(), 40u);
  EXPECT_EQ(a.num_cells(), 0u);  // NOLINT(bugprone-use-after-move): moves leave the source empty
  EXPECT_FALSE(a.log_odds(Key(32768, 32768, 32760)).has_value());
  a.update(Key(32768, 32768, 32760), a.miss());  // a new cell in the source, not in `moved`
  EXPECT_EQ(*a.log_odds(Key(32768, 32768, 32760)), a.miss());
  EXPECT_EQ(*moved.log_odds(Key(32768, 32768, 32760)), moved.hit());
  moved = std::move(copy);
  EXPECT_EQ(*moved.log_odds(Key(32768, 32768, 32760)), moved.hit() + moved.miss());
  EXPECT_EQ(copy.num_cells(), 0u);  // NOLINT(bugprone-use-after-move)
  moved.erase(Key(32768, 32768, 32760));
  EXPECT_FALSE(moved.log_odds(Key(32768, 32768, 32760)).has_value());
  moved.update(Key(32768, 32768, 32760), moved.hit());
  EXPECT_EQ(*moved.log_odds(Key(32768, 32768, 32760)), moved.hit());
}

TEST(VoxelMap, ForgettingClearsAMovedObstacle) {
  // A box is seen for a second, then moves out of the camera's view. Without forgetting its
  // cells stay occupied for ever; with a 1 s half-life they fade and become unknown.
  Scene before(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(4.0, 2.0, 2.5));
  before.add_box(Eigen::Vector3d(1.0, -0.2, 0.8), Eigen::Vector3d(1.3, 0.2, 1.2));
  Scene after(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(4.0, 2.0, 2.5));
  const Eigen::Isometry3d looking_at_box = test::look_at({-0.47, 0.03, 1.01}, {1.0, 0.0, 1.0});
  const Eigen::Isometry3d looking_away = test::look_at({-0.47, 0.03, 1.01}, {-1.0, -2.0, 1.0});
  ScanOptions options;
  options.stride = 1;
  const Eigen::Vector3d box_front(1.05, 0.05, 1.05);

  for (const double half_life : {0.0, 1.0}) {
    MapOptions map_options;
    map_options.decay_half_life_s = half_life;
    VoxelMap map(map_options);
    ScanIntegrator integrator(0.1, options);
    int64_t utime = 0;
    auto insert = [&](const Scene& scene, const Eigen::Isometry3d& T) {
      ScanUpdate update;
      integrator.compute(make_scan(scene.render(test::kinect_camera(128, 96), T, utime), T,
                                   options, "test"),
                         update);
      map.integrate(update, utime);
      utime += 100000;
    };
    for (int i = 0; i < 10; ++i) insert(before, looking_at_box);
    ASSERT_EQ(map.occupancy_at(box_front), Occupancy::kOccupied);
    for (int i = 0; i < 100; ++i) insert(after, looking_away);  // 10 s elsewhere
    if (half_life == 0.0) {
      EXPECT_EQ(map.occupancy_at(box_front), Occupancy::kOccupied) << "without forgetting";
    } else {
      EXPECT_EQ(map.occupancy_at(box_front), Occupancy::kUnknown) << "with forgetting";
    }
  }
}

TEST(VoxelMap, MovedObstacleClearsWhereRaysPassThrough) {
  // Seen through after it moved, the old cells turn free by misses alone, and faster with
  // forgetting (the occupied evidence has faded by the time the rays pass).
  Scene before(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(4.0, 2.0, 2.5));
  before.add_box(Eigen::Vector3d(1.0, -0.2, 0.8), Eigen::Vector3d(1.3, 0.2, 1.2));
  const Scene after(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(4.0, 2.0, 2.5));
  const Eigen::Isometry3d T = test::look_at({-0.47, 0.03, 1.01}, {1.0, 0.0, 1.0});
  const Eigen::Vector3d box_front(1.05, 0.05, 1.05);
  int frames_to_clear[2] = {0, 0};
  for (const int with_decay : {0, 1}) {
    MapOptions map_options;
    map_options.decay_half_life_s = with_decay ? 0.5 : 0.0;
    VoxelMap map(map_options);
    ScanOptions options;
    options.stride = 1;
    ScanIntegrator integrator(0.1, options);
    int64_t utime = 0;
    auto insert = [&](const Scene& scene) {
      ScanUpdate update;
      integrator.compute(make_scan(scene.render(test::kinect_camera(128, 96), T, utime), T,
                                   options, "test"),
                         update);
      map.integrate(update, utime);
      utime += 100000;
    };
    for (int i = 0; i < 30; ++i) insert(before);
    ASSERT_EQ(map.occupancy_at(box_front), Occupancy::kOccupied);
    int n = 0;
    while (map.occupancy_at(box_front) != Occupancy::kFree && n < 100) {
      insert(after);
      ++n;
    }
    frames_to_clear[with_decay] = n;
  }
  EXPECT_LT(frames_to_clear[0], 20) << "misses alone clear it (clamped at 3.5, 0.4 per miss)";
  EXPECT_LT(frames_to_clear[1], frames_to_clear[0]);
}

TEST(OctreeFiles, WrittenFilesReadBackIdentical) {
  const Scene scene = box_scene();
  ScanOptions options;
  options.stride = 1;
  ScanIntegrator integrator(0.1, options);
  VoxelMap map;
  int64_t utime = 0;
  for (const auto& T : circle_poses(6, 1.6, {0.6, 0.0, 0.3})) {
    ScanUpdate update;
    integrator.compute(make_scan(scene.render(test::kinect_camera(128, 96), T, utime), T,
                                 options, "test"),
                       update);
    map.integrate(update, utime += 33333);
  }
  kestrel::test::TempDir dir;
  write_map_file(map, (dir / "map.ot").string());
  ::testing::internal::CaptureStderr();
  write_map_file(map, (dir / "map.bt").string());
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << "OctoMap's writeBinary prints \" done.\"";

  // .ot keeps every value.
  const VoxelMap full = read_map_file((dir / "map.ot").string());
  EXPECT_EQ(full.num_cells(), map.num_cells());
  map.for_each_cell([&](const Key& k, float v) { ASSERT_EQ(full.log_odds(k), v); });

  // .bt keeps every cell's class, and writing what was read gives the same bytes.
  const VoxelMap binary = read_map_file((dir / "map.bt").string());
  EXPECT_EQ(binary.num_cells(), map.num_cells());
  map.for_each_cell([&](const Key& k, float v) { ASSERT_EQ(binary.occupancy(k), map.occupancy(v)); });
  write_map_file(binary, (dir / "again.bt").string());
  EXPECT_EQ(kestrel::test::read_file(dir / "again.bt"), kestrel::test::read_file(dir / "map.bt"));
  // The tree's data are OctoMap's writeBinary's to the byte (only the header's comments differ).
  std::ostringstream octomap_bt;
  to_octree(map)->writeBinary(octomap_bt);
  const std::string ours = kestrel::test::read_file(dir / "map.bt"), theirs = octomap_bt.str();
  ASSERT_NE(ours.find("\ndata\n"), std::string::npos);
  EXPECT_EQ(ours.substr(ours.find("\ndata\n")), theirs.substr(theirs.find("\ndata\n")));

  // The message form round-trips the same way.
  const auto stream = encode_octree(map, OctreeFormat::kFull);
  const VoxelMap decoded = decode_octree(stream.data(), stream.size(), OctreeFormat::kFull, "MAP");
  EXPECT_EQ(decoded.num_cells(), map.num_cells());
}

TEST(OctreeFiles, BadFilesAreInputErrors) {
  kestrel::test::TempDir dir;
  EXPECT_THROW(read_map_file((dir / "missing.bt").string()), InputError);
  EXPECT_THROW(read_map_file((dir / "map.png").string()), InputError);
  EXPECT_THROW(write_map_file(VoxelMap(), (dir / "map.txt").string()), InputError);
  EXPECT_THROW(write_map_file(VoxelMap(), (dir / "no/such/dir/map.bt").string()), InputError);
  std::ofstream(dir / "garbage.bt") << "this is not an octree";
  EXPECT_THROW(read_map_file((dir / "garbage.bt").string()), InputError);
  std::ofstream(dir / "garbage.ot") << "# Octomap OcTree file\nid NoSuchTree\nsize 1\nres 0.1\ndata\n";
  EXPECT_THROW(read_map_file((dir / "garbage.ot").string()), InputError);

  // A valid stream cut short or with flipped bytes never crashes: it reads or it throws.
  VoxelMap map;
  for (int i = 0; i < 200; ++i) map.update(Key(32768 + i % 7, 32768 + i % 5, 32768 + i % 3), map.hit());
  for (const OctreeFormat format : {OctreeFormat::kBinary, OctreeFormat::kFull}) {
    auto stream = encode_octree(map, format);
    for (size_t cut : {size_t{10}, stream.size() / 2, stream.size() - 3}) {
      try {
        decode_octree(stream.data(), cut, format, "cut");
      } catch (const InputError&) {
      }
    }
    for (size_t i = stream.size() / 3; i < stream.size(); i += 7) stream[i] ^= 0x5a;
    try {
      decode_octree(stream.data(), stream.size(), format, "flipped");
    } catch (const InputError&) {
    }
  }
}

}  // namespace
}  // namespace kestrel::mapper
