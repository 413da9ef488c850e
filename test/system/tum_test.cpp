// A real recording through the processes, as a user replays one (README, "Running the
// system"): TUM's fr1_xyz written to a log by tum-play, then kestrel-vo, -estimator, -slam and
// -mapper under lock-step replay, none of them told what camera recorded it.
//
// The frames name their sensor (kinect1), so the odometry runs with the Kinect's profile: its
// chained VO_UPDATEs are the offline `kestrel vo --tum` trajectory of the same folder, pose for
// pose. (Before the frames carried the model, a replayed log ran with the built-in defaults:
// ATE 1.68 cm against 1.13.) SLAM closes the recording's loop, the mapper rebuilds its map from
// the moved keyframes, and that map is the map of the same frames at their true poses.
//
// TUM recorded the Kinect's accelerometer but no gyro: the estimator runs on the visual
// odometry alone (visual_only.h), its start levelled by the accelerometer, and publishes a
// STATE per frame, which SLAM anchors its map on and corrects after its loop closure. Its
// poses are the odometry's chain (ATE 1.09 cm against the VO's 1.13), its velocities the
// constant-velocity filter's (0.083 m/s RMS off the motion capture's, at 0.35 m/s RMS).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "common/geometry/align.h"
#include "common/numbers.h"
#include "common/trajectory.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "kestrel/slam_edge_t.hpp"
#include "kestrel/state_t.hpp"
#include "test/support/figures.h"
#include "test/support/test_support.h"
#include "test/system/recording.h"
#include "metrics/evaluate.h"
#include "tools/eval/log_input.h"

namespace kestrel {
namespace {

// The estimator without a gyro: a STATE for every VO frame with a motion, its pose the VO's
// (to the SLAM corrections), its world levelled by the accelerometer, and its velocity the
// motion capture's to within what the odometry's noise allows.
void expect_visual_only_state(const std::string& recorded, const Trajectory& truth, const Trajectory& vo) {
  const auto states = transport::read_messages<kestrel::state_t>(recorded, channel::kState);
  ASSERT_GE(states.size() + 1, vo.size()) << "a STATE per VO frame (the first is the origin)";
  std::vector<StampedPose> poses;
  for (const auto& s : states) {
    EXPECT_EQ(s.filter, kestrel::state_t::FILTER_VISUAL_ONLY);
    poses.push_back(StampedPose{s.utime, transport::from_message(s.T_world_body, "STATE")});
  }
  const Trajectory estimated(std::move(poses));
  const metrics::Evaluation scored = metrics::evaluate(metrics::frame_times(estimated), estimated, truth, metrics::EvalOptions{});
  EXPECT_TRUE(test::no_worse_than(scored.ate.error_m.rmse, test::figure("estimator.fr1_xyz.visual_only.state_ate")));

  // Velocity against the motion capture's, differenced over +-50 ms, in the estimate's world
  // (the rigid fit of the positions, as the ATE's).
  Eigen::Matrix3Xd est(3, 0), gt(3, 0);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> velocities;  // estimated, true (truth's world)
  for (const auto& s : states) {
    const auto a = truth.at(s.utime - 50000, 20000), b = truth.at(s.utime + 50000, 20000), c = truth.at(s.utime, 20000);
    if (!a || !b || !c) continue;
    est.conservativeResize(3, est.cols() + 1);
    gt.conservativeResize(3, gt.cols() + 1);
    est.col(est.cols() - 1) = Eigen::Vector3d(s.T_world_body.position[0], s.T_world_body.position[1], s.T_world_body.position[2]);
    gt.col(gt.cols() - 1) = c->translation();
    velocities.emplace_back(Eigen::Vector3d(s.velocity[0], s.velocity[1], s.velocity[2]),
                            (b->translation() - a->translation()) / 0.1);
  }
  const auto T_gt_est = align_rigid(est, gt);
  ASSERT_TRUE(T_gt_est);
  double sum_sq = 0.0, sum_sq_true = 0.0;
  for (const auto& [v_est, v_true] : velocities) {
    sum_sq += (T_gt_est->linear() * v_est - v_true).squaredNorm();
    sum_sq_true += v_true.squaredNorm();
  }
  const double rmse = std::sqrt(sum_sq / velocities.size()), speed = std::sqrt(sum_sq_true / velocities.size());
  std::cout << "visual-only STATE: ATE " << scored.ate.error_m.rmse << " m, velocity RMSE " << rmse << " m/s over "
            << velocities.size() << " states (RMS speed " << speed << " m/s)\n";
  EXPECT_LT(rmse, 0.3 * speed) << "the velocity does not follow the motion";  // 0.083 of 0.35 m/s measured

  // Levelled: the world's z is the motion capture's up (TUM's mocap frame has z up), to the
  // accelerometer's accuracy.
  const Eigen::Vector3d up = T_gt_est->linear() * Eigen::Vector3d::UnitZ();
  EXPECT_GT(up.z(), std::cos(5.0 * kPi / 180.0)) << "the estimator's world is not level: up = " << up.transpose();
}

TEST(System, ReplayedTumRecordingRunsWithItsCamerasProfileAndMapsTheScene) {
  KESTREL_REQUIRE_TUM(folder, "rgbd_dataset_freiburg1_xyz");
  if (!test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
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
  const auto r = test::run_isolated(script, 600.0);
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
  const metrics::Evaluation scored = metrics::evaluate(metrics::frame_times(replayed), replayed, truth, metrics::EvalOptions{});
  EXPECT_EQ(scored.association.no_gt_before_start + scored.association.no_gt_after_end, 0u);
  std::cout << "VO ATE " << scored.ate.error_m.rmse << " m over " << scored.ate.error_m.count << " frames (offline run's trajectory to "
            << worst_m << " m)\n";
  EXPECT_TRUE(test::no_worse_than(scored.ate.error_m.rmse, test::figure("vo.fr1_xyz.ate_rmse")))
      << "the Kinect's profile gives vo/README.md's figure, the built-in defaults 1.68 cm";

  const test::Recording rec = test::read_recording(recorded);
  expect_visual_only_state(recorded, truth, replayed);
  // fr1_xyz goes back and forth over the desk: SLAM locates the later frames in its first
  // keyframes (re-anchoring, slam.h) rather than making new ones, and each such frame, like a
  // loop closure, corrects the STATE (SLAM anchors its map on the visual-only STATE).
  ASSERT_TRUE(rec.graph.has_value()) << "SLAM published no graph";
  const auto loops = std::count_if(rec.graph->edges.begin(), rec.graph->edges.end(),
                                   [](const auto& e) { return e.kind == kestrel::slam_edge_t::KIND_LOOP_CLOSURE; });
  EXPECT_GE(rec.corrections, 1) << "fr1_xyz returns over its start: SLAM's map corrects the STATE";
  EXPECT_LE(rec.graph->keyframes.size(), 8u) << "keyframes made over ground the first ones cover";
  EXPECT_GE(rec.last_map_revision, 1000) << "no MAP_OCTOMAP after a rebuild (the revision jumps then)";
  std::cout << "keyframes " << rec.graph->keyframes.size() << ", loop closures " << loops << ", corrections "
            << rec.corrections << "\n";
  // 0.952 measured, each keyframe's depth at its own time in both maps (0.947 when the mapper
  // ignored the keyframes' T_camera_depth; the synthetic flights give 0.95 or more: here the
  // truth itself is a motion capture's, synchronised and calibrated to a centimetre or so).
  test::expect_map_agrees_with_truth(*rec.graph, truth, source, map_file, 0.93);
}

}  // namespace
}  // namespace kestrel
