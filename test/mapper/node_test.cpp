// The mapper process's logic on messages (MapNode), without LCM: ground-truth and SLAM pose
// sources, the published stream decodes to the map the library builds, the rate limit, a
// rebuild published at once, RESET, and bad messages rejected with the channel named.
#include <gtest/gtest.h>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/rgbd_codec.h"
#include "mapper/map_node.h"
#include "mapper/octree_io.h"
#include "test/mapper/scene.h"

namespace kestrel::mapper {
namespace {

Eigen::Isometry3d pose_at(double t_s) {
  return test::look_at({-1.2 + 0.2 * t_s, 0.013, 1.2}, {2.0, 0.5 - 0.5 * t_s, 0.7});
}

kestrel::rgbd_frame_t frame_message(const test::Scene& scene, int64_t utime) {
  return transport::encode_rgbd(scene.render(test::kinect_camera(160, 120), pose_at(1e-6 * utime), utime));
}

kestrel::ground_truth_t truth_message(int64_t utime) {
  kestrel::ground_truth_t m{};
  m.utime = utime;
  m.frame = kestrel::ground_truth_t::FRAME_CAMERA;
  m.T_world_frame = transport::to_message(pose_at(1e-6 * utime));
  return m;
}

VoxelMap decode(const kestrel::octomap_t& m) {
  return decode_octree(m.data.data(), m.data.size(),
                       m.format == kestrel::octomap_t::FORMAT_FULL ? OctreeFormat::kFull : OctreeFormat::kBinary,
                       "MAP_OCTOMAP");
}

TEST(MapNode, GroundTruthPosesGiveTheLibrarysMap) {
  const test::Scene scene = test::room_with_a_box();
  NodeOptions options;
  options.pose_source = PoseSource::kGroundTruth;
  options.full_format = true;
  options.publish_period_s = 0.5;
  MapNode node(options);
  Mapper reference(options.mapper);
  int published = 0;
  std::optional<kestrel::octomap_t> last;
  // Frames at 10 Hz, truth at 100 Hz; a frame waits for the pose of its own time.
  for (int64_t t = 0; t <= 2000000; t += 10000) {
    if (t > 0 && t % 100000 == 0) {
      EXPECT_FALSE(node.on_frame(frame_message(scene, t), "CAMERA_RGBD").has_value())
          << "no pose after the frame yet";
      reference.insert(scene.render(test::kinect_camera(160, 120), pose_at(1e-6 * t), t), pose_at(1e-6 * t));
    }
    if (auto m = node.on_ground_truth(truth_message(t), "GROUND_TRUTH")) {
      ++published;
      last = m;
    }
  }
  EXPECT_EQ(node.stats().frames_inserted, 20);
  EXPECT_EQ(node.stats().frames_without_pose, 0);
  EXPECT_GE(published, 3);
  EXPECT_LE(published, 5) << "one map per 0.5 s of sensor time";
  const VoxelMap now = decode(node.map_message());
  ASSERT_EQ(now.num_cells(), reference.map().num_cells());
  reference.map().for_each_cell([&](const Key& k, float v) { ASSERT_EQ(now.log_odds(k), v); });

  node.reset();
  EXPECT_EQ(node.mapper().map().num_cells(), 0u);
  EXPECT_EQ(node.stats().frames, 0);
}

TEST(MapNode, SlamGraphInsertsKeyframesAndPublishesRebuildsAtOnce) {
  const test::Scene scene = test::room_with_a_box();
  NodeOptions options;
  options.publish_period_s = 10.0;
  options.mapper.rebuild_interval_s = 0.0;
  MapNode node(options);
  kestrel::slam_graph_t graph{};
  for (int i = 0; i < 4; ++i) {
    const int64_t t = 100000 * (i + 1);
    node.on_frame(frame_message(scene, t), "CAMERA_RGBD");
    kestrel::slam_keyframe_t k{};
    k.id = i;
    k.utime = t;
    k.T_world_camera = transport::to_message(pose_at(1e-6 * t));
    k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
    graph.keyframes.push_back(k);
  }
  graph.num_keyframes = 4;
  graph.revision = 1;
  const auto first = node.on_graph(graph, "SLAM_GRAPH");
  ASSERT_TRUE(first.has_value()) << "the first map is published at once";
  EXPECT_EQ(first->revision, 1);
  EXPECT_GT(decode(*first).num_occupied(), 50u);
  graph.revision = 2;
  EXPECT_FALSE(node.on_graph(graph, "SLAM_GRAPH").has_value()) << "nothing moved, rate-limited";
  graph.revision = 3;
  graph.keyframes[2].T_world_camera.position[0] += 0.2;  // a loop closure moves a keyframe
  const auto rebuilt = node.on_graph(graph, "SLAM_GRAPH");
  ASSERT_TRUE(rebuilt.has_value());
  EXPECT_EQ(rebuilt->revision, 1000) << "a rebuild jumps to the next thousand";
  EXPECT_EQ(node.stats().rebuilds, 1);

  graph.revision = 2;
  EXPECT_THROW(node.on_graph(graph, "SLAM_GRAPH"), InputError);  // older revision
  graph.revision = 4;
  graph.num_keyframes = 5;
  EXPECT_THROW(node.on_graph(graph, "SLAM_GRAPH"), InputError);
  graph.num_keyframes = 4;
  graph.keyframes[0].T_world_camera.orientation[0] = NAN;
  EXPECT_THROW(node.on_graph(graph, "SLAM_GRAPH"), InputError);
}

// A SLAM process restarted in flight publishes a graph of its own keyframes only, with ids
// and revisions counted from its first keyframe's utime (slam/slam_messages.h): the map keeps
// the first session's keyframes where they were and adds the new session's, without a rebuild.
TEST(MapNode, ARestartedSlamAddsItsKeyframesAndKeepsTheEarlierOnes) {
  const test::Scene scene = test::room_with_a_box();
  NodeOptions options;
  options.mapper.rebuild_interval_s = 0.0;
  MapNode node(options);
  auto session = [&](int64_t first_utime, int64_t revision) {
    kestrel::slam_graph_t graph{};
    for (int i = 0; i < 3; ++i) {
      const int64_t t = first_utime + 100000 * i;
      node.on_frame(frame_message(scene, t), "CAMERA_RGBD");
      kestrel::slam_keyframe_t k{};
      k.id = first_utime + i;
      k.utime = t;
      k.T_world_camera = transport::to_message(pose_at(1e-6 * t));
      k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
      graph.keyframes.push_back(k);
    }
    graph.num_keyframes = 3;
    graph.revision = first_utime + revision;
    return graph;
  };
  node.on_graph(session(100000, 2), "SLAM_GRAPH");
  ASSERT_EQ(node.mapper().keyframes().size(), 3u);
  const size_t cells_before = node.mapper().map().num_cells();
  // The new session's graph lacks the first three keyframes and starts its revisions again.
  EXPECT_NO_THROW(node.on_graph(session(900000, 1), "SLAM_GRAPH"));
  EXPECT_EQ(node.mapper().keyframes().size(), 6u);
  EXPECT_EQ(node.stats().frames_inserted, 6);
  EXPECT_EQ(node.stats().rebuilds, 0) << "no keyframe of the first session moved";
  EXPECT_GT(node.mapper().map().num_cells(), cells_before) << "the new keyframes see more of the room";
}

TEST(MapNode, BadFramesAreRejectedNamingTheChannel) {
  const test::Scene scene = test::room_with_a_box();
  MapNode node(NodeOptions{});
  auto msg = frame_message(scene, 500000);
  node.on_frame(msg, "CAMERA_RGBD");
  try {
    node.on_frame(msg, "CAMERA_RGBD");  // same time again
    FAIL() << "an out-of-order frame must be rejected";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("CAMERA_RGBD"), std::string::npos) << e.what();
  }
  auto corrupt = frame_message(scene, 600000);
  corrupt.depth.resize(corrupt.depth.size() / 2);
  corrupt.depth_size = static_cast<int32_t>(corrupt.depth.size());
  EXPECT_THROW(node.on_frame(corrupt, "CAMERA_RGBD"), InputError);
  auto no_depth = frame_message(scene, 700000);
  no_depth.depth_encoding = kestrel::rgbd_frame_t::DEPTH_NONE;
  no_depth.depth.clear();
  no_depth.depth_size = 0;
  EXPECT_THROW(node.on_frame(no_depth, "CAMERA_RGBD"), InputError);
  EXPECT_EQ(node.stats().frames, 1);
}

}  // namespace
}  // namespace kestrel::mapper
