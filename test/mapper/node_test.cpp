// The mapper process's logic on messages (MapNode), without LCM: ground-truth and SLAM pose
// sources, the published stream decodes to the map the library builds, the rate limit, a
// rebuild published at once, RESET, bad messages rejected with the channel named, and the
// journal a restarted mapper gets its map back from (whole, after a full disk, not a journal;
// damaged journals: journal_test.cpp), which a RESET starts again without destroying it, keeping
// only the newest journals set aside, and which is compacted past twice the store; a journal
// that cannot be continued at start is given up (DEGRADED, with why), never the map.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/rgbd_codec.h"
#include "mapper/map_node.h"
#include "mapper/octree_io.h"
#include "mapper/scan.h"
#include "test/mapper/scene.h"
#include "test/support/test_support.h"

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

// SLAM_GRAPH's entry for a keyframe made from the frame at time t (along pose_at()).
kestrel::slam_keyframe_t keyframe_message(int64_t id, int64_t t) {
  kestrel::slam_keyframe_t k{};
  k.id = id;
  k.utime = t;
  k.T_world_camera = transport::to_message(pose_at(1e-6 * t));
  k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
  return k;
}

// Keyframes `first`..`last` (ids = their index) of the slow pan pose_at() describes, 0.1 s
// apart: their frames go to the node, and the graph holds keyframes 0..last.
kestrel::slam_graph_t feed_keyframes(MapNode& node, const test::Scene& scene, int first, int last,
                                     int64_t revision) {
  kestrel::slam_graph_t graph{};
  for (int i = 0; i <= last; ++i) {
    const int64_t t = 100000 * (i + 1);
    if (i >= first) node.on_frame(frame_message(scene, t), "CAMERA_RGBD");
    graph.keyframes.push_back(keyframe_message(i, t));
  }
  graph.num_keyframes = static_cast<int32_t>(graph.keyframes.size());
  graph.revision = revision;
  return graph;
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
  kestrel::slam_graph_t graph = feed_keyframes(node, scene, 0, 3, 1);
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
  graph.keyframes[0].T_world_camera.orientation[0] = static_cast<double>(NAN);
  EXPECT_THROW(node.on_graph(graph, "SLAM_GRAPH"), InputError);
}

// A hovering vehicle makes no keyframes, so the map stops changing: the last map goes out
// again each publish period of frames, unchanged (revision and bytes), so that a process
// started since (a restarted planner) gets it; never before the first map, never after RESET.
TEST(MapNode, WithoutNewKeyframesTheLastMapIsSentAgainEachPeriodOfFrames) {
  const test::Scene scene = test::room_with_a_box();
  NodeOptions options;
  options.publish_period_s = 0.5;
  MapNode node(options);
  for (int64_t t = 100000; t <= 1000000; t += 100000)
    EXPECT_FALSE(node.on_frame(frame_message(scene, t), "CAMERA_RGBD").has_value()) << "no map yet at " << t;
  kestrel::slam_graph_t graph{};
  graph.keyframes = {keyframe_message(0, 1000000)};
  graph.num_keyframes = 1;
  graph.revision = 1;
  const auto first = node.on_graph(graph, "SLAM_GRAPH");
  ASSERT_TRUE(first.has_value());
  std::vector<int64_t> sent_at;
  for (int64_t t = 1100000; t <= 2600000; t += 100000) {
    if (const auto again = node.on_frame(frame_message(scene, t), "CAMERA_RGBD")) {
      sent_at.push_back(t);
      EXPECT_EQ(again->revision, first->revision);
      EXPECT_EQ(again->utime, first->utime);
      EXPECT_EQ(again->data, first->data);
    }
  }
  EXPECT_EQ(sent_at, (std::vector<int64_t>{1500000, 2000000, 2500000})) << "0.5 s of frames after the last";
  EXPECT_EQ(node.stats().published, 1);
  EXPECT_EQ(node.stats().repeated, 3);
  node.reset();
  for (int64_t t = 100000; t <= 1000000; t += 100000)
    EXPECT_FALSE(node.on_frame(frame_message(scene, t), "CAMERA_RGBD").has_value()) << "a map sent after RESET";
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
      graph.keyframes.push_back(keyframe_message(first_utime + i, t));
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

// Frames as the simulator and the link send them (JPEG colour): a keyframe's colour is
// decoded when the graph takes its frame and is the decoded image; one whose JPEG scan is
// damaged is kept with its depth, its colour counted as lost; a damaged frame no keyframe
// takes is never decoded, so costs nothing.
TEST(MapNode, JpegColourIsDecodedForKeyframesOnlyAndADamagedOneCostsOnlyTheColour) {
  const test::Scene scene = test::room_with_a_box();
  MapNode node(NodeOptions{});
  transport::RgbdEncoding jpeg;
  jpeg.rgb = kestrel::rgbd_frame_t::RGB_JPEG;
  kestrel::slam_graph_t graph{};
  std::vector<RgbdFrame> decoded;
  for (int i = 0; i < 5; ++i) {
    const int64_t t = 100000 * (i + 1);
    RgbdFrame frame = scene.render(test::kinect_camera(160, 120), pose_at(1e-6 * t), t);
    frame.rgb.create(frame.depth_mm.size(), CV_8UC3);  // the scene renders depth only
    cv::randu(frame.rgb, cv::Scalar::all(0), cv::Scalar::all(256));
    kestrel::rgbd_frame_t m = transport::encode_rgbd(frame, jpeg);
    if (i == 2 || i == 3) {  // the scan cut short: the header reads, the image does not
      m.rgb.resize(m.rgb.size() * 2 / 3);
      m.rgb_size = static_cast<int32_t>(m.rgb.size());
      EXPECT_THROW(transport::decode_rgbd(m, "CAMERA_RGBD"), InputError);
    } else {
      decoded.push_back(transport::decode_rgbd(m, "CAMERA_RGBD"));
    }
    node.on_frame(m, "CAMERA_RGBD");
    if (i < 3) graph.keyframes.push_back(keyframe_message(i, t));  // frame 3: no keyframe; 4: pinned
  }
  // Frame 4 pinned for a keyframe SLAM has not placed yet: kept with its colour.
  kestrel::slam_graph_t unplaced{};
  unplaced.keyframes = {keyframe_message(9, 500000)};
  unplaced.num_keyframes = 1;
  node.on_unplaced_graph(unplaced, "SLAM_GRAPH_UNPLACED");
  ASSERT_EQ(node.mapper().pinned_frames().size(), 1u);
  const RgbdFrame pinned_expected = decimate(decoded[2], node.mapper().options().scan.stride);
  ASSERT_FALSE(node.mapper().pinned_frames()[0]->rgb.empty());
  EXPECT_EQ(cv::norm(node.mapper().pinned_frames()[0]->rgb, pinned_expected.rgb, cv::NORM_INF), 0.0);
  graph.num_keyframes = 3;
  graph.revision = 1;
  node.on_graph(graph, "SLAM_GRAPH");
  ASSERT_EQ(node.mapper().keyframes().size(), 3u);
  for (int i = 0; i < 2; ++i) {
    const RgbdFrame expected = decimate(decoded[static_cast<size_t>(i)], node.mapper().options().scan.stride);
    const RgbdFrame& kept = node.mapper().keyframes().find(i)->frame;
    ASSERT_FALSE(kept.rgb.empty()) << i;
    EXPECT_EQ(cv::norm(kept.rgb, expected.rgb, cv::NORM_INF), 0.0) << i;
  }
  EXPECT_TRUE(node.mapper().keyframes().find(2)->frame.rgb.empty());
  EXPECT_FALSE(node.mapper().keyframes().find(2)->frame.depth_mm.empty());
  EXPECT_EQ(node.mapper().colour_lost(), 1u) << "frame 3's damage is never decoded";
  EXPECT_EQ(node.stats().frames, 5);
  EXPECT_NE(node.mapper().colour_lost_reason().find("CAMERA_RGBD: corrupt JPEG"), std::string::npos)
      << node.mapper().colour_lost_reason();
}

void expect_same_keyframes(const Mapper& a, const Mapper& b) {
  const auto ka = a.keyframes().in_stored_order();
  const auto kb = b.keyframes().in_stored_order();
  ASSERT_EQ(ka.size(), kb.size());
  for (size_t i = 0; i < ka.size(); ++i) {
    EXPECT_EQ(ka[i]->id, kb[i]->id);
    EXPECT_EQ(ka[i]->utime, kb[i]->utime);
    EXPECT_TRUE(ka[i]->T_world_camera.matrix() == kb[i]->T_world_camera.matrix()) << "keyframe " << ka[i]->id;
    EXPECT_EQ(cv::norm(ka[i]->frame.depth_mm, kb[i]->frame.depth_mm, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(ka[i]->frame.rgb, kb[i]->frame.rgb, cv::NORM_INF), 0.0);
  }
}

void expect_same_map(const VoxelMap& a, const VoxelMap& b) {
  ASSERT_EQ(a.num_cells(), b.num_cells());
  a.for_each_cell([&](const Key& k, float v) { ASSERT_EQ(b.log_odds(k), v); });
}

// Keyframes SLAM made before it placed the camera in its saved map join the map only at the
// placement, maybe long after their frames left the buffer: announced on SLAM_GRAPH_UNPLACED,
// their frames are kept (up to max_pinned_frames, the oldest let go), and the graph that joins
// them puts them in. Announced again with the next one, nothing is counted twice; a list that
// leaves one out, a whole graph and a reset let the pins go.
TEST(MapNode, KeyframesSlamHasNotPlacedYetKeepTheirFramesUntilTheyJoin) {
  const test::Scene scene = test::room_with_a_box();
  const auto fly = [&](bool announce, int max_pinned) {
    NodeOptions options;
    options.mapper.frame_buffer_s = 0.5;
    options.mapper.max_pinned_frames = max_pinned;
    auto node = std::make_unique<MapNode>(options);
    kestrel::slam_graph_t unplaced{};
    for (int i = 0; i < 20; ++i) {  // frames every 0.1 s; keyframes at the first three
      const int64_t t = 100000 * (i + 1);
      node->on_frame(frame_message(scene, t), "CAMERA_RGBD");
      if (i < 3 && announce) {
        unplaced.keyframes.push_back(keyframe_message(i, t));
        unplaced.num_keyframes = static_cast<int32_t>(unplaced.keyframes.size());
        node->on_unplaced_graph(unplaced, "SLAM_GRAPH_UNPLACED");
      }
    }
    // 1.7 s after the last of them, far beyond the 0.5 s buffer: the placement joins them.
    kestrel::slam_graph_t joined{};
    for (int i = 0; i < 3; ++i) joined.keyframes.push_back(keyframe_message(i, 100000 * (i + 1)));
    joined.keyframes.push_back(keyframe_message(19, 2000000));
    joined.num_keyframes = 4;
    joined.revision = 1;
    node->on_graph(joined, "SLAM_GRAPH");
    return node;
  };
  const auto kept = fly(true, 300);
  EXPECT_EQ(kept->stats().frames_inserted, 4);
  EXPECT_EQ(kept->stats().unplaced_pinned, 3);
  EXPECT_EQ(kept->stats().unplaced_joined, 3);
  EXPECT_EQ(kept->mapper().pinned(), 0u) << "inserted: no longer kept";
  const auto lost = fly(false, 300);
  EXPECT_EQ(lost->stats().frames_inserted, 1) << "without the announcement their frames are gone";
  const auto bounded = fly(true, 2);
  EXPECT_EQ(bounded->stats().frames_inserted, 3);
  EXPECT_EQ(bounded->mapper().keyframes().find(0), nullptr) << "the oldest is let go beyond the bound";
  EXPECT_NE(bounded->mapper().keyframes().find(2), nullptr);

  // A list that leaves a keyframe out lets its frame go (that SLAM will not join it); a whole
  // graph lets all go (SLAM sends one only once placed); so does a reset. A bad count is refused.
  MapNode node{NodeOptions{}};
  for (int i = 0; i < 3; ++i) node.on_frame(frame_message(scene, 100000 * (i + 1)), "CAMERA_RGBD");
  kestrel::slam_graph_t list{};
  list.keyframes = {keyframe_message(0, 100000), keyframe_message(1, 200000)};
  list.num_keyframes = 2;
  node.on_unplaced_graph(list, "SLAM_GRAPH_UNPLACED");
  node.on_unplaced_graph(list, "SLAM_GRAPH_UNPLACED");
  EXPECT_EQ(node.stats().unplaced_pinned, 2) << "announced twice, pinned once";
  list.keyframes = {keyframe_message(1, 200000)};
  list.num_keyframes = 1;
  node.on_unplaced_graph(list, "SLAM_GRAPH_UNPLACED");
  EXPECT_EQ(node.mapper().pinned(), 1u);
  list.num_keyframes = 2;
  EXPECT_THROW(node.on_unplaced_graph(list, "SLAM_GRAPH_UNPLACED"), InputError);
  kestrel::slam_graph_t other{};
  other.keyframes = {keyframe_message(7, 300000)};
  other.num_keyframes = 1;
  other.revision = 1;
  node.on_graph(other, "SLAM_GRAPH");
  EXPECT_EQ(node.mapper().pinned(), 0u) << "a whole graph: placed";
  list.num_keyframes = 1;
  node.on_unplaced_graph(list, "SLAM_GRAPH_UNPLACED");
  ASSERT_EQ(node.mapper().pinned(), 1u);
  node.reset();
  EXPECT_EQ(node.mapper().pinned(), 0u);
}

// The pinned frames are journaled: a mapper restarted (its buffer empty) before SLAM places
// the camera pins them again, and the placement joins them as if it had not restarted. A frame
// whose keyframe joined before the restart is not pinned again (compaction and damage:
// KeyframeJournal.PinnedFramesAreJournaledAndPinnedAgainUnlessTheirKeyframeJoined).
TEST(MapNode, ARestartedMapperKeepsTheFramesOfKeyframesSlamHasNotPlacedYet) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.mapper.frame_buffer_s = 0.5;
  options.journal_path = (dir / "mapper.journal").string();
  const auto announce = [&](MapNode& node, int first, int last) {
    kestrel::slam_graph_t unplaced{};
    for (int i = first; i <= last; ++i) {
      const int64_t t = 100000 * (i + 1);
      node.on_frame(frame_message(scene, t), "CAMERA_RGBD");
      unplaced.keyframes.push_back(keyframe_message(i, t));
    }
    unplaced.num_keyframes = static_cast<int32_t>(unplaced.keyframes.size());
    node.on_unplaced_graph(unplaced, "SLAM_GRAPH_UNPLACED");
  };
  const auto placement = [&](int last, int64_t revision) {
    kestrel::slam_graph_t joined{};
    for (int i = 0; i <= last; ++i) joined.keyframes.push_back(keyframe_message(i, 100000 * (i + 1)));
    joined.num_keyframes = static_cast<int32_t>(joined.keyframes.size());
    joined.revision = revision;
    return joined;
  };
  {
    MapNode first(options);
    announce(first, 0, 3);
    ASSERT_EQ(first.stats().unplaced_pinned, 4);
    // SLAM's next list leaves keyframe 0 out (it will not join): its frame is let go.
    kestrel::slam_graph_t fewer{};
    for (int i = 1; i <= 3; ++i) fewer.keyframes.push_back(keyframe_message(i, 100000 * (i + 1)));
    fewer.num_keyframes = 3;
    first.on_unplaced_graph(fewer, "SLAM_GRAPH_UNPLACED");
    ASSERT_EQ(first.mapper().pinned(), 3u);
  }
  MapNode restarted(options);
  EXPECT_EQ(restarted.stats().pinned_restored, 3) << "the one let go stays gone";
  EXPECT_EQ(restarted.mapper().buffered(100000), nullptr);
  restarted.on_frame(frame_message(scene, 2000000), "CAMERA_RGBD");  // no earlier frame is buffered
  kestrel::slam_graph_t joined = placement(3, 1);
  joined.keyframes.erase(joined.keyframes.begin());
  joined.num_keyframes = 3;
  restarted.on_graph(joined, "SLAM_GRAPH");
  EXPECT_EQ(restarted.stats().frames_inserted, 3) << "the three keyframes joined from the journal's frames";
  EXPECT_EQ(restarted.stats().unplaced_joined, 3);
  for (int i = 1; i <= 3; ++i) EXPECT_NE(restarted.mapper().keyframes().find(i), nullptr) << i;
  // Joined before this restart: stored, not pinned again.
  MapNode again(options);
  EXPECT_EQ(again.stats().keyframes_restored, 3);
  EXPECT_EQ(again.stats().pinned_restored, 0);
  expect_same_map(restarted.mapper().map(), again.mapper().map());
}

// SLAM_CORRECTION for a frame SLAM located on its map without a keyframe (a localisation-only
// flight): with insert_located, the frame goes into the map at the corrected pose. Here a box
// has appeared in front of the camera since the keyframes were made (a door closed): the map
// gets it, the journal keeps it, and a loop closure that moves the keyframes leaves it where
// it was put. Corrections for a keyframe, or for a frame no longer buffered, add nothing;
// without the option nothing at all.
TEST(MapNode, AFrameSlamLocatedWithoutAKeyframeUpdatesTheMapWhenAsked) {
  const test::Scene before = test::room_with_a_box();
  test::Scene after = before;
  after.add_box(Eigen::Vector3d(0.0, -0.2, 0.6), Eigen::Vector3d(0.3, 0.6, 1.3));
  const Eigen::Vector3d box_face(0.02, 0.2, 1.0);  // on the new box's face towards the camera
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.mapper.rebuild_interval_s = 0.0;
  options.insert_located = true;
  options.journal_path = (dir / "mapper.journal").string();
  MapNode node(options);
  NodeOptions plain_options = options;
  plain_options.insert_located = false;
  plain_options.journal_path.clear();
  MapNode plain(plain_options);
  for (MapNode* n : {&node, &plain}) n->on_graph(feed_keyframes(*n, before, 0, 3, 1), "SLAM_GRAPH");
  ASSERT_EQ(node.mapper().map().occupancy_at(box_face), Occupancy::kFree) << "the keyframes saw through it";
  // These frames come from a camera mounted off the body (a correction is the body's pose).
  const Eigen::Isometry3d T_body_camera = test::look_at({0.1, 0.0, -0.05}, {1.1, 0.0, -0.2});
  const auto correction = [&](int64_t t, int64_t keyframe_id) {
    kestrel::slam_correction_t c{};
    c.utime = t;
    c.keyframe_id = keyframe_id;
    c.graph_revision = 1;
    c.T_world_body = transport::to_message(pose_at(1e-6 * t) * T_body_camera.inverse());
    return c;
  };
  // Three located frames (one hit does not outweigh the four keyframes' misses: log-odds).
  for (MapNode* n : {&node, &plain}) {
    for (const int64_t t : {600000, 700000, 800000}) {
      kestrel::rgbd_frame_t m = frame_message(after, t);
      m.camera.T_body_camera = transport::to_message(T_body_camera);
      n->on_frame(m, "CAMERA_RGBD");
      n->on_correction(correction(t, 2), "SLAM_CORRECTION");  // located in keyframe 2
    }
    n->on_correction(correction(300000, 2), "SLAM_CORRECTION");  // keyframe 2's own: the graph placed it
    n->on_correction(correction(550000, 2), "SLAM_CORRECTION");  // no such frame
  }
  EXPECT_EQ(node.stats().located, 3);
  EXPECT_EQ(node.stats().located_missing, 1);
  EXPECT_EQ(node.mapper().keyframes().size(), 7u);
  ASSERT_NE(node.mapper().keyframes().find(Mapper::kFirstLocatedId), nullptr);
  EXPECT_TRUE(node.mapper().keyframes().find(Mapper::kFirstLocatedId)->T_world_camera.isApprox(pose_at(0.6), 1e-9))
      << "the camera's pose is the corrected body's composed with its mounting";
  EXPECT_EQ(node.mapper().map().occupancy_at(box_face), Occupancy::kOccupied);
  EXPECT_EQ(plain.stats().located, 0);
  EXPECT_EQ(plain.mapper().keyframes().size(), 4u);
  EXPECT_EQ(plain.mapper().map().occupancy_at(box_face), Occupancy::kFree);

  // A loop closure moves keyframe 1 (a rebuild): the located frame stays where it was put.
  kestrel::slam_graph_t closed = feed_keyframes(node, before, 4, 3, 2);
  closed.keyframes[1].T_world_camera.position[1] += 0.05;
  node.on_graph(closed, "SLAM_GRAPH");
  ASSERT_EQ(node.stats().rebuilds, 1);
  EXPECT_TRUE(node.mapper().keyframes().find(Mapper::kFirstLocatedId)->T_world_camera.isApprox(pose_at(0.6), 1e-9));
  EXPECT_EQ(node.mapper().map().occupancy_at(box_face), Occupancy::kOccupied);
  // A restarted mapper gets it back from the journal, with the same map.
  MapNode restarted(options);
  expect_same_keyframes(node.mapper(), restarted.mapper());
  expect_same_map(node.mapper().map(), restarted.mapper().map());

  // Bad corrections are refused naming the channel; nothing changes.
  kestrel::slam_correction_t bad = correction(600000, 2);
  bad.T_world_body.orientation[0] = static_cast<double>(NAN);
  EXPECT_THROW(node.on_correction(bad, "SLAM_CORRECTION"), InputError);
  bad = correction(600000, 2);
  bad.utime = -5;
  try {
    node.on_correction(bad, "SLAM_CORRECTION");
    FAIL() << "a correction at no time must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("SLAM_CORRECTION"), std::string::npos) << e.what();
  }
  EXPECT_EQ(node.mapper().keyframes().size(), 7u);
}

// A mapper killed in flight and started again on its journal: the keyframes it had, at the
// poses a loop closure moved them to, and the same map, cell for cell; then it carries on.
TEST(MapNode, ARestartedMapperRestoresItsKeyframesAndMapFromTheJournal) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.mapper.rebuild_interval_s = 0.0;
  options.journal_path = (dir / "mapper.journal").string();
  MapNode before(options);
  before.on_graph(feed_keyframes(before, scene, 0, 3, 1), "SLAM_GRAPH");
  // A loop closure moves keyframe 1 by 5 cm (beyond the 2 cm threshold) and keyframe 2 by
  // 1 cm (below it: the store keeps its old pose), and keyframes 4 and 5 arrive with it.
  kestrel::slam_graph_t closed = feed_keyframes(before, scene, 4, 5, 2);
  closed.keyframes[1].T_world_camera.position[1] += 0.05;
  closed.keyframes[2].T_world_camera.position[1] += 0.01;
  before.on_graph(closed, "SLAM_GRAPH");
  ASSERT_EQ(before.stats().rebuilds, 1);
  ASSERT_EQ(before.mapper().keyframes().size(), 6u);
  // The journal's graph record holds the keyframe that moved, and only it.
  const JournalContents written = read_journal(options.journal_path);
  const auto graph = std::find_if(written.records.begin(), written.records.end(), [](const JournalRecord& r) {
    return r.kind == JournalRecord::Kind::kGraph;
  });
  ASSERT_NE(graph, written.records.end());
  ASSERT_EQ(graph->graph.keyframes.size(), 1u);
  EXPECT_EQ(graph->graph.keyframes[0].id, closed.keyframes[1].id);
  EXPECT_EQ(graph->graph.num_edges, 0);

  MapNode after(options);
  EXPECT_EQ(after.stats().keyframes_restored, 6);
  EXPECT_EQ(after.journal_damage(), "");
  expect_same_keyframes(before.mapper(), after.mapper());
  expect_same_map(before.mapper().map(), after.mapper().map());

  // It carries on: a new keyframe goes into the map and the journal.
  kestrel::slam_graph_t next = closed;
  const kestrel::slam_graph_t more = feed_keyframes(after, scene, 6, 6, 3);
  next.keyframes.push_back(more.keyframes.back());
  next.num_keyframes = 7;
  next.revision = 3;
  after.on_graph(next, "SLAM_GRAPH");
  EXPECT_EQ(after.mapper().keyframes().size(), 7u);
  EXPECT_EQ(MapNode(options).stats().keyframes_restored, 7);

  // Without a journal the restarted mapper would have nothing: the frames are gone.
  NodeOptions plain = options;
  plain.journal_path.clear();
  MapNode forgetful(plain);
  forgetful.on_graph(next, "SLAM_GRAPH");
  EXPECT_EQ(forgetful.mapper().keyframes().size(), 0u);

}

// A journal grows with every keyframe stored and every pose moved, the store only to its
// budget. Past twice the store (plus journal_compact_mb) the journal is replaced by the store's
// own records: after every graph it is within that bound, and a mapper restarted on it holds
// what one restarted on the whole journal holds (the same keyframes at the same poses, the same
// map) and still refuses an older graph.
TEST(MapNode, AJournalPastTwiceTheStoreIsCompactedAndRestoresTheSameMapper) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.mapper.rebuild_interval_s = 0.0;
  options.mapper.keyframes.max_megabytes = 0.02;  // about five keyframes
  options.journal_compact_mb = 1e-6;
  options.journal_path = (dir / "compacted.journal").string();
  NodeOptions whole = options;
  whole.journal_compact_mb = 1e6;
  whole.journal_path = (dir / "whole.journal").string();
  const auto fly = [&](const NodeOptions& o) {
    auto node = std::make_unique<MapNode>(o);
    kestrel::slam_graph_t graph;
    for (int i = 0; i < 25; ++i) {
      graph = feed_keyframes(*node, scene, i, i, i + 1);
      // A loop closure at every sixth keyframe moves them all 3 cm more; the graphs between
      // move nothing (the last, 25, included).
      for (auto& k : graph.keyframes) k.T_world_camera.position[2] += 0.03 * ((i + 1) / 6);
      node->on_graph(graph, "SLAM_GRAPH");
      const uint64_t bytes = std::filesystem::file_size(o.journal_path);
      if (o.journal_compact_mb < 1.0) {
        EXPECT_LE(bytes, 2 * node->mapper().keyframes().bytes() + 1) << "after keyframe " << i;
      }
    }
    EXPECT_EQ(node->journal_error(), "");
    return node;
  };
  const auto flown = fly(options);
  const auto reference = fly(whole);
  EXPECT_GT(flown->mapper().keyframes().dropped(), 0u) << "the store's budget is what makes compaction pay";
  EXPECT_GT(flown->journal_compactions(), 1);
  EXPECT_EQ(reference->journal_compactions(), 0);
  EXPECT_LT(std::filesystem::file_size(options.journal_path), std::filesystem::file_size(whole.journal_path) / 2);
  EXPECT_EQ(flown->journal_compaction_error(), "");

  MapNode restarted(options), restarted_whole(whole);
  EXPECT_EQ(restarted.journal_damage(), "");
  expect_same_keyframes(flown->mapper(), restarted.mapper());
  expect_same_keyframes(restarted_whole.mapper(), restarted.mapper());
  expect_same_map(restarted_whole.mapper().map(), restarted.mapper().map());
  // Both refuse a graph older than the last loop closure's (revision 24; the compacted
  // journal's revision record itself: KeyframeJournal.CompactionKeepsTheKeyframesAsPlaced...).
  EXPECT_THROW(restarted.on_graph(feed_keyframes(restarted, scene, 25, 25, 23), "SLAM_GRAPH"), InputError);
  EXPECT_THROW(restarted_whole.on_graph(feed_keyframes(restarted_whole, scene, 25, 25, 23), "SLAM_GRAPH"), InputError);
}

// RESET (a lock-step replay starting again) starts the journal again with the map, and keeps
// the journal it ends whole beside it: a replay never destroys a flight's journal.
TEST(MapNode, AResetStartsTheJournalAgainAndKeepsTheOldOneWhole) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.journal_path = (dir / "mapper.journal").string();
  const auto files = [&] {
    return std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator());
  };
  {
    MapNode flight(options);
    flight.on_graph(feed_keyframes(flight, scene, 0, 2, 1), "SLAM_GRAPH");
  }
  const std::string flown = kestrel::test::read_file(options.journal_path);
  ASSERT_EQ(read_journal(options.journal_path).records.size(), 3u);

  MapNode node(options);  // a replay's mapper, started on the flight's journal
  ASSERT_EQ(node.stats().keyframes_restored, 3);
  node.reset();
  EXPECT_EQ(node.mapper().keyframes().size(), 0u) << "RESET forgets the map";
  const JournalContents started_again = read_journal(options.journal_path);
  EXPECT_TRUE(started_again.records.empty());
  EXPECT_EQ(started_again.damage, "");
  const std::string kept = node.journal_kept_aside();
  ASSERT_NE(kept, "");
  EXPECT_EQ(std::filesystem::path(kept).filename().string().rfind("mapper.journal.reset-", 0), 0u) << kept;
  EXPECT_TRUE(kestrel::test::read_file(kept) == flown) << "the flight's journal, byte for byte";
  EXPECT_EQ(files(), 2);

  // A reset with nothing journalled since keeps nothing more; the next map is journalled, and
  // the next reset keeps that too, apart from the first.
  node.reset();
  EXPECT_EQ(node.journal_kept_aside(), "");
  EXPECT_EQ(files(), 2);
  node.on_graph(feed_keyframes(node, scene, 0, 1, 1), "SLAM_GRAPH");
  EXPECT_EQ(read_journal(options.journal_path).records.size(), 2u);
  EXPECT_TRUE(kestrel::test::read_file(kept) == flown) << "the kept journal is not appended to";
  node.reset();
  ASSERT_NE(node.journal_kept_aside(), "");
  EXPECT_NE(node.journal_kept_aside(), kept);
  EXPECT_EQ(read_journal(node.journal_kept_aside()).records.size(), 2u);
  EXPECT_EQ(files(), 3);
  EXPECT_EQ(node.journal_error(), "");
  EXPECT_EQ(MapNode(options).stats().keyframes_restored, 0) << "a restart after the reset has the reset's map";
}

// A journal that is a building's saved map (kestrel launch --map): the RESET a lock-step session
// sends before its first event keeps the map restored from it; a later one forgets it.
TEST(MapNode, ASavedMapsJournalSurvivesTheResetBeforeAnyInput) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.journal_path = (dir / "mapper.journal").string();
  {
    MapNode flight(options);
    flight.on_graph(feed_keyframes(flight, scene, 0, 2, 1), "SLAM_GRAPH");
  }
  options.journal_is_map = true;
  MapNode node(options);
  ASSERT_EQ(node.stats().keyframes_restored, 3);
  node.reset();
  EXPECT_EQ(node.mapper().keyframes().size(), 3u) << "the saved map is where the new flight begins";
  EXPECT_EQ(node.journal_kept_aside(), "") << "nothing set aside";
  EXPECT_EQ(read_journal(options.journal_path).records.size(), 3u);
  node.on_graph(feed_keyframes(node, scene, 3, 3, 2), "SLAM_GRAPH");
  node.reset();
  EXPECT_EQ(node.mapper().keyframes().size(), 0u) << "after input, a RESET forgets as always";
  EXPECT_NE(node.journal_kept_aside(), "");
}

// A disk that fills up in flight: the journal is given up with the reason, the map goes on.
TEST(MapNode, AJournalThatCannotBeWrittenIsGivenUpAndTheMapGoesOn) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.journal_path = (dir / "mapper.journal").string();
  MapNode node(options);
  node.on_graph(feed_keyframes(node, scene, 0, 0, 1), "SLAM_GRAPH");
  const uintmax_t written = std::filesystem::file_size(options.journal_path);
  // The file-size limit stands in for a full disk: a write past it fails (EFBIG).
  rlimit old_limit{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limit = old_limit;
  limit.rlim_cur = static_cast<rlim_t>(written + 1000);
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  node.on_graph(feed_keyframes(node, scene, 1, 1, 2), "SLAM_GRAPH");
  node.on_graph(feed_keyframes(node, scene, 2, 2, 3), "SLAM_GRAPH");
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(node.journal_error().find("mapper.journal: writing the mapper journal failed"), std::string::npos)
      << node.journal_error();
  EXPECT_EQ(node.mapper().keyframes().size(), 3u) << "the map went on";
  EXPECT_EQ(node.stats().frames_inserted, 3);
  // What was written before the failure is read; the partial record after it is damage.
  const JournalContents journal = read_journal(options.journal_path);
  EXPECT_EQ(journal.records.size(), 1u);
  EXPECT_NE(journal.damage, "");
}

// Repeated RESETs do not fill the disk: the newest journal_keep journals set aside stay, and
// each older one deleted is reported by name.
TEST(MapNode, RepeatedResetsKeepOnlyTheNewestJournalsSetAside) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.journal_path = (dir / "mapper.journal").string();
  options.journal_keep = 2;
  MapNode node(options);
  std::vector<std::string> kept;
  for (int round = 0; round < 3; ++round) {
    node.on_graph(feed_keyframes(node, scene, 0, 0, 1), "SLAM_GRAPH");
    node.reset();
    kept.push_back(node.journal_kept_aside());
    ASSERT_NE(kept.back(), "") << "round " << round;
    EXPECT_EQ(node.journal_pruned().removed, round < 2 ? std::vector<std::string>{} : std::vector<std::string>{kept[0]})
        << "round " << round;
  }
  EXPECT_FALSE(std::filesystem::exists(kept[0]));
  EXPECT_EQ(kept_journals(options.journal_path, "reset"), (std::vector<std::string>{kept[1], kept[2]}));
  EXPECT_EQ(node.journal_error(), "");
  EXPECT_EQ(node.health().state, kestrel::process_status_t::STATE_RUNNING);
  // Keeping none would delete the journal a reset has just set aside: not an option.
  options.journal_keep = 0;
  EXPECT_THROW(MapNode{options}, std::invalid_argument);
}

// A journal that cannot be started (its folder is a regular file: ENOTDIR, which stops root
// too) is given up at once: the process reports DEGRADED with why, and the map goes on.
TEST(MapNode, AJournalThatCannotBeStartedIsGivenUpAndTheMapGoesOn) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  const std::string not_a_folder = (dir / "notes.txt").string();
  std::ofstream(not_a_folder) << "my notes\n";
  NodeOptions options;
  options.journal_path = not_a_folder + "/mapper.journal";
  MapNode node(options);
  EXPECT_NE(node.journal_error().find(options.journal_path + ": cannot write in"), std::string::npos)
      << node.journal_error();
  const MapNode::Health health = node.health();
  EXPECT_EQ(health.state, kestrel::process_status_t::STATE_DEGRADED);
  EXPECT_EQ(health.message, "journal stopped: " + node.journal_error());

  node.on_graph(feed_keyframes(node, scene, 0, 2, 1), "SLAM_GRAPH");
  EXPECT_EQ(node.mapper().keyframes().size(), 3u) << "the map goes on";
  EXPECT_EQ(node.stats().frames_inserted, 3);
  EXPECT_GT(node.mapper().map().num_cells(), 0u);
  node.reset();  // nothing to set aside, and still no journal
  EXPECT_EQ(node.journal_kept_aside(), "");
  EXPECT_EQ(node.health().state, kestrel::process_status_t::STATE_DEGRADED);
  EXPECT_EQ(kestrel::test::read_file(not_a_folder), "my notes\n") << "the file in the way is left alone";
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
}

// A damaged journal whose fresh copy cannot be written (the file-size limit stands in for a
// full disk, the usual cause of the damage): the restored map is kept and goes on, the process
// reports DEGRADED, and the damaged journal stays as it was.
TEST(MapNode, ADamagedJournalThatCannotBeContinuedKeepsTheRestoredMapAndTheFile) {
  const test::Scene scene = test::room_with_a_box();
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.journal_path = (dir / "mapper.journal").string();
  {
    MapNode flight(options);
    flight.on_graph(feed_keyframes(flight, scene, 0, 2, 1), "SLAM_GRAPH");
  }
  std::filesystem::resize_file(options.journal_path, std::filesystem::file_size(options.journal_path) - 1);
  const std::string damaged = kestrel::test::read_file(options.journal_path);

  rlimit old_limit{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limit = old_limit;
  limit.rlim_cur = 100;  // the header fits, no keyframe does
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  std::unique_ptr<MapNode> node;
  try {
    node = std::make_unique<MapNode>(options);
  } catch (...) {
    ADD_FAILURE() << "a journal that cannot be continued must not stop the mapper";
  }
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  ASSERT_TRUE(node);

  EXPECT_EQ(node->stats().keyframes_restored, 2);
  EXPECT_NE(node->journal_damage(), "");
  EXPECT_NE(node->journal_error().find(options.journal_path + ": write failed"), std::string::npos)
      << node->journal_error();
  EXPECT_EQ(node->health().state, kestrel::process_status_t::STATE_DEGRADED);
  EXPECT_TRUE(kestrel::test::read_file(options.journal_path) == damaged) << "the journal is as it was";
  node->on_graph(feed_keyframes(*node, scene, 3, 3, 2), "SLAM_GRAPH");
  EXPECT_EQ(node->mapper().keyframes().size(), 3u) << "the restored map goes on";
  EXPECT_TRUE(kestrel::test::read_file(options.journal_path) == damaged) << "and is not journalled";
}

TEST(MapNode, AFileThatIsNotAJournalIsAnErrorNamingItAndIsLeftAlone) {
  kestrel::test::TempDir dir;
  NodeOptions options;
  options.journal_path = (dir / "notes.txt").string();
  std::ofstream(options.journal_path) << "my notes\n";
  try {
    MapNode node(options);
    FAIL() << "a file that is not a journal must not be taken, nor overwritten";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("notes.txt: not a kestrel mapper journal"), std::string::npos) << e.what();
  }
  EXPECT_EQ(kestrel::test::read_file(options.journal_path), "my notes\n");
  // A journal that does not exist yet is a new map; ground-truth poses have no journal.
  options.journal_path = (dir / "new.journal").string();
  EXPECT_EQ(MapNode(options).stats().keyframes_restored, 0);
  EXPECT_TRUE(std::filesystem::exists(options.journal_path));
  options.pose_source = PoseSource::kGroundTruth;
  EXPECT_THROW(MapNode{options}, std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::mapper
