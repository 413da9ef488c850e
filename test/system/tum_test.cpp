// A real recording through the processes, as a user replays one (README, "Running the
// system"): TUM's fr1_xyz written to a log by tum-play, then kestrel-vo, -estimator, -slam and
// -mapper under lock-step replay, none of them told what camera recorded it.
//
// The frames name their sensor (kinect1), so the odometry runs with the Kinect's profile: its
// chained VO_UPDATEs are the offline `kestrel vo --tum` trajectory of the same folder, pose for
// pose. (Before the frames carried the model, a replayed log ran with the simulator's profile:
// ATE 1.68 cm against 1.13.) SLAM closes the recording's loop, the mapper rebuilds its map from
// the moved keyframes, and that map is the map of the same frames at their true poses.
//
// TUM recorded the Kinect's accelerometer but no gyro: the estimator refuses every IMU sample
// and publishes no STATE, so SLAM keeps its map in the odometry's frame (nothing to anchor to).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <iostream>
#include <optional>
#include <string>

#include "common/trajectory.h"
#include "common/transport/channels.h"
#include "kestrel/slam_edge_t.hpp"
#include "tools/eval/evaluate.h"
#include "tools/eval/log_input.h"
#include "test/support/test_support.h"
#include "test/system/recording.h"

namespace kestrel {
namespace {

TEST(System, ReplayedTumRecordingRunsWithItsCamerasProfileAndMapsTheScene) {
  KESTREL_REQUIRE_TUM(folder, "rgbd_dataset_freiburg1_xyz");
  if (!test::can_isolate_network()) GTEST_SKIP() << "no network namespace available";
  test::TempDir dir;
  const std::string source = (dir / "source.lcmlog").string();
  const std::string recorded = (dir / "system.lcmlog").string();
  const std::string map_file = (dir / "map.bt").string();
  const std::string offline = (dir / "vo.txt").string();
  const auto play = test::run({test::tool("tum-play").string(), "-q", folder.string(), "--log", source}, 300.0);
  ASSERT_EQ(play.exit_code, 0) << play.err;
  const auto vo = test::run({test::tool("vo").string(), "-q", "--tum", folder.string(), "--out", offline}, 300.0);
  ASSERT_EQ(vo.exit_code, 0) << vo.err;

  const std::string script =
      test::tool("vo").string() + " -q & V=$!; " + test::tool("estimator").string() + " -q & E=$!; " +
      test::tool("slam").string() + " -q & S=$!; " + test::tool("mapper").string() + " -q --save " + map_file +
      " & M=$!; " + test::tool("replay").string() + " " + source +
      " --expect vo,estimator,slam,mapper --ack-timeout 60 --record " + recorded +
      "; R=$?; kill -INT $V $E $S $M; wait $V $E $S $M; exit $R";
  const auto r = test::run({test::tool("isolated").string(), "--", "sh", "-c", script}, 600.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // The odometry: the offline run's, so the Kinect's profile (timing, floors, dense weight).
  const Trajectory replayed = eval::read_log_input(recorded, {channel::kVoUpdate}).trajectory;
  const Trajectory expected = read_tum_trajectory(offline);
  ASSERT_EQ(replayed.size(), expected.size());
  ASSERT_GE(replayed.size(), 180u);
  double worst_m = 0.0, worst_rad = 0.0;
  for (size_t i = 0; i < replayed.size(); ++i) {
    const StampedPose &p = replayed.poses()[i], &q = expected.poses()[i];
    ASSERT_EQ(p.utime, q.utime);
    worst_m = std::max(worst_m, (p.T.translation() - q.T.translation()).norm());
    worst_rad = std::max(worst_rad, Eigen::AngleAxisd(p.T.linear().transpose() * q.T.linear()).angle());
  }
  EXPECT_LT(worst_m, 1e-6) << "the replayed odometry is not the offline run's";
  EXPECT_LT(worst_rad, 1e-6);
  // Scored as `kestrel eval --gt source --est recorded` scores it; every frame has its truth
  // (tum-play brackets the frames with the motion capture's samples).
  const Trajectory truth = eval::read_log_input(source, {channel::kGroundTruth}).trajectory;  // T_world_camera
  const eval::Evaluation scored = eval::evaluate(eval::frame_times(replayed), replayed, truth, eval::EvalOptions{});
  EXPECT_EQ(scored.association.no_gt_before_start + scored.association.no_gt_after_end, 0u);
  std::cout << "VO ATE " << scored.ate.error_m.rmse << " m over " << scored.ate.error_m.count << " frames (offline run's trajectory to "
            << worst_m << " m)\n";
  EXPECT_LT(scored.ate.error_m.rmse, 0.0125) << "the Kinect's profile gives 1.13 cm, the simulator's 1.68";

  const test::Recording rec = test::read_recording(recorded);
  EXPECT_TRUE(rec.states.empty()) << "no gyro in the recording: the estimator has nothing to propagate with";
  ASSERT_TRUE(rec.graph.has_value()) << "SLAM published no graph";
  const auto loops = std::count_if(rec.graph->edges.begin(), rec.graph->edges.end(),
                                   [](const auto& e) { return e.kind == kestrel::slam_edge_t::KIND_LOOP_CLOSURE; });
  EXPECT_GE(loops, 1) << "fr1_xyz returns over its start: SLAM closes a loop";
  EXPECT_GE(rec.last_map_revision, 1000) << "no MAP_OCTOMAP after a rebuild (the revision jumps then)";
  std::cout << "keyframes " << rec.graph->keyframes.size() << ", loop closures " << loops << "\n";
  // 0.936 measured (the synthetic flights give 0.95 or more: here the truth itself is a motion
  // capture's, synchronised and calibrated to the camera to a centimetre or so).
  test::expect_map_agrees_with_truth(*rec.graph, truth, source, map_file, 0.90);
}

}  // namespace
}  // namespace kestrel
