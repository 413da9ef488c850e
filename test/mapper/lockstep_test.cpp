// kestrel-mapper under lock-step replay, in a private network namespace: a log of synthetic
// frames and ground truth replayed twice through one running mapper (RESET between) gives
// byte-identical MAP_OCTOMAP recordings, and the last map is the library's map of the same
// frames. This is the whole process path: LCM decode, MapNode, rate limit, acks, RESET. In SLAM
// mode: frames SLAM located, and keyframes announced before a placement, reach the journal.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/octomap_t.hpp"
#include "kestrel/slam_correction_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "mapper/keyframe_journal.h"
#include "mapper/mapper.h"
#include "mapper/voxel_map.h"
#include "mapper/octree_io.h"
#include "test/mapper/scene.h"
#include "test/support/test_support.h"

namespace kestrel::mapper {
namespace {

Eigen::Isometry3d pose_at(int64_t utime) {
  const double t = 1e-6 * static_cast<double>(utime);
  return test::look_at({-1.2 + 0.2 * t, 0.013, 1.2}, {2.0, 0.5 - 0.5 * t, 0.7});
}

TEST(MapperProcess, LockStepReplayIsDeterministicAndResets) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  kestrel::test::TempDir dir;
  const test::Scene scene = test::room_with_a_box();
  {
    transport::LogWriter log((dir / "in.lcmlog").string());
    for (int64_t t = 0; t <= 1500000; t += 20000) {
      if (t > 0 && t % 100000 == 0) {
        const RgbdFrame f = scene.render(test::kinect_camera(160, 120), pose_at(t), t);
        log.write_message(channel::kCameraRgbd, t, transport::encode_rgbd(f));
      }
      kestrel::ground_truth_t gt{};
      gt.utime = t;
      gt.frame = kestrel::ground_truth_t::FRAME_CAMERA;
      gt.T_world_frame = transport::to_message(pose_at(t));
      log.write_message(channel::kGroundTruth, t, gt);
    }
  }
  const std::string mapper = kestrel::test::tool("mapper").string();
  const std::string replay = kestrel::test::tool("replay").string();
  const std::string in = (dir / "in.lcmlog").string();
  const std::string script =
      mapper + " --pose-source ground-truth --publish-period 0.4 --format full & P=$!; " + replay + " " + in +
      " --expect mapper --record " + (dir / "a.lcmlog").string() + " || exit 11; " + replay + " " + in +
      " --expect mapper --record " + (dir / "b.lcmlog").string() + " || exit 12; kill -INT $P; wait $P";
  const auto r = kestrel::test::run_isolated(script, 240.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string a = kestrel::test::read_file(dir / "a.lcmlog");
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, kestrel::test::read_file(dir / "b.lcmlog")) << "the second replay (after RESET) must publish the same maps";

  transport::LogReader recorded((dir / "a.lcmlog").string());
  std::optional<kestrel::octomap_t> last;
  int maps = 0;
  while (auto event = recorded.next()) {
    if (event->channel != channel::kMapOctomap) continue;
    last = transport::decode_message<kestrel::octomap_t>(event->data.data(), event->data.size(), "MAP_OCTOMAP");
    ++maps;
  }
  EXPECT_GE(maps, 3);  // 1.5 s at one map per 0.4 s
  ASSERT_TRUE(last.has_value());
  const VoxelMap map = decode_octree(last->data.data(), last->data.size(), OctreeFormat::kFull, "MAP_OCTOMAP");
  // The last map was published after the frame of 1.3 s: compare with the library's map up to
  // the frame it names.
  Mapper upto;
  for (int64_t t = 100000; t <= last->utime; t += 100000)
    upto.insert(scene.render(test::kinect_camera(160, 120), pose_at(t), t), pose_at(t));
  ASSERT_EQ(map.num_cells(), upto.map().num_cells());
  upto.map().for_each_cell([&](const Key& k, float v) { ASSERT_EQ(map.log_odds(k), v); });
}

// SLAM mode through the process, localising only: a graph of four keyframes, then corrections
// for three later frames SLAM located without a keyframe (--insert-located). The journal holds
// the four keyframes and the three located frames, and the mapper published a map after them.
TEST(MapperProcess, FramesSlamLocatedReachTheJournalThroughTheProcess) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  kestrel::test::TempDir dir;
  const test::Scene scene = test::room_with_a_box();
  {
    transport::LogWriter log((dir / "in.lcmlog").string());
    kestrel::slam_graph_t graph{};
    graph.revision = 1;
    for (int64_t t = 100000; t <= 1000000; t += 100000) {
      log.write_message(channel::kCameraRgbd, t, transport::encode_rgbd(scene.render(test::kinect_camera(160, 120), pose_at(t), t)));
      if (t <= 400000) {
        kestrel::slam_keyframe_t k{};
        k.id = t / 100000;
        k.utime = t;
        k.T_world_camera = transport::to_message(pose_at(t));
        k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
        graph.keyframes.push_back(k);
        graph.num_keyframes = static_cast<int32_t>(graph.keyframes.size());
        graph.utime = t;
        log.write_message(channel::kSlamGraph, t, graph);
      } else if (t >= 800000) {
        kestrel::slam_correction_t c{};
        c.utime = t;
        c.keyframe_id = 4;
        c.graph_revision = 1;
        c.T_world_body = transport::to_message(pose_at(t));
        log.write_message(channel::kSlamCorrection, t, c);
      }
    }
  }
  const std::string journal = (dir / "mapper.journal").string();
  const std::string script = kestrel::test::tool("mapper").string() + " --insert-located --journal " + journal +
                             " --publish-period 0.1 & P=$!; " + kestrel::test::tool("replay").string() + " " +
                             (dir / "in.lcmlog").string() + " --expect mapper --record " + (dir / "out.lcmlog").string() +
                             " || exit 11; kill -INT $P; wait $P";
  const auto r = kestrel::test::run_isolated(script, 240.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const JournalContents written = read_journal(journal);
  int keyframes = 0, located = 0;
  for (const JournalRecord& record : written.records) {
    if (record.kind != JournalRecord::Kind::kKeyframe) continue;
    (record.keyframe.id >= Mapper::kFirstLocatedId ? located : keyframes) += 1;
  }
  EXPECT_EQ(keyframes, 4);
  EXPECT_EQ(located, 3);
  transport::LogReader recorded((dir / "out.lcmlog").string());
  int64_t newest_map_utime = 0;
  while (auto event = recorded.next()) {
    if (event->channel != channel::kMapOctomap) continue;
    const auto m = transport::decode_message<kestrel::octomap_t>(event->data.data(), event->data.size(), "MAP_OCTOMAP");
    newest_map_utime = std::max(newest_map_utime, m.utime);
  }
  EXPECT_GE(newest_map_utime, 800000) << "no map after the located frames";
}

// SLAM on a saved map, through the process: three keyframes made before the placement are
// announced on SLAM_GRAPH_UNPLACED as they come; the graph that joins them comes 1.7 s later,
// far past the mapper's 0.5 s frame buffer. The journal holds all four keyframes (the three
// frames kept, and the newest), not only the newest.
TEST(MapperProcess, KeyframesAnnouncedBeforeThePlacementJoinThroughTheProcess) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  kestrel::test::TempDir dir;
  const test::Scene scene = test::room_with_a_box();
  const auto keyframe = [](int64_t t) {
    kestrel::slam_keyframe_t k{};
    k.id = t / 100000;
    k.utime = t;
    k.T_world_camera = transport::to_message(pose_at(t));
    k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
    return k;
  };
  {
    transport::LogWriter log((dir / "in.lcmlog").string());
    kestrel::slam_graph_t unplaced{};
    for (int64_t t = 100000; t <= 2000000; t += 100000) {
      log.write_message(channel::kCameraRgbd, t, transport::encode_rgbd(scene.render(test::kinect_camera(160, 120), pose_at(t), t)));
      if (t <= 300000) {
        unplaced.keyframes.push_back(keyframe(t));
        unplaced.num_keyframes = static_cast<int32_t>(unplaced.keyframes.size());
        unplaced.utime = t;
        log.write_message(channel::kSlamGraphUnplaced, t, unplaced);
      }
    }
    kestrel::slam_graph_t joined = unplaced;
    joined.keyframes.push_back(keyframe(2000000));
    joined.num_keyframes = 4;
    joined.utime = 2000000;
    joined.revision = 1;
    log.write_message(channel::kSlamGraph, 2000000, joined);
  }
  const std::string journal = (dir / "mapper.journal").string();
  const std::string script = kestrel::test::tool("mapper").string() + " --frame-buffer 0.5 --journal " + journal +
                             " & P=$!; " + kestrel::test::tool("replay").string() + " " + (dir / "in.lcmlog").string() +
                             " --expect mapper || exit 11; kill -INT $P; wait $P";
  const auto r = kestrel::test::run_isolated(script, 240.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int keyframes = 0;
  for (const JournalRecord& record : read_journal(journal).records)
    keyframes += record.kind == JournalRecord::Kind::kKeyframe;
  EXPECT_EQ(keyframes, 4) << r.err;
  EXPECT_NE(r.err.find("3 frames of keyframes SLAM made before placing the camera kept past the buffer, 3 of them joined"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace kestrel::mapper
