// Trajectories from LCM logs written here with LogWriter: a known motion on GROUND_TRUTH and
// VO_UPDATE (and STATE), then every kind of damage the reader must survive and count.

#include "tools/eval/log_input.h"

#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "test/eval/known_log.h"
#include "test/eval/synthetic.h"
#include "test/support/test_support.h"
#include "metrics/evaluate.h"

namespace kestrel::eval {
namespace {

using test::gt_message;
using test::kBodyCamera;
using test::KnownLog;
using transport::LogWriter;
using transport::to_message;

std::vector<uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void write_bytes(const std::filesystem::path& p, const std::vector<uint8_t>& b) {
  std::ofstream(p, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

TEST(EvalLog, VoIsChainedAndScoresPerfectly) {
  kestrel::test::TempDir dir;
  const KnownLog log;
  log.write(dir / "run.lcmlog", kestrel::ground_truth_t::FRAME_CAMERA);
  ASSERT_TRUE(is_lcm_log(dir / "run.lcmlog"));

  const TrajectoryInput est = read_log_input(dir / "run.lcmlog", {"STATE", "VO_UPDATE"});
  EXPECT_EQ(est.source, (dir / "run.lcmlog").string() + ":VO_UPDATE");
  EXPECT_EQ(est.frame, PoseFrame::kCamera);
  EXPECT_EQ(est.frame_utimes, log.frames);
  EXPECT_EQ(est.trajectory.size(), log.frames.size() - 1);
  EXPECT_EQ(est.diagnostics.no_pose, 1u);
  ASSERT_TRUE(est.T_body_camera.has_value());
  EXPECT_TRUE(est.T_body_camera->isApprox(kBodyCamera, 1e-12));
  // The chain starts at the first frame: T_world_camera(k) = helix(0)^-1 helix(t_k).
  const Eigen::Isometry3d T_first_world = test::helix_pose(log.frames.front()).inverse();
  for (const StampedPose& p : est.trajectory.poses())
    EXPECT_TRUE(p.T.isApprox(T_first_world * test::helix_pose(p.utime), 1e-9)) << p.utime;

  TrajectoryInput gt = read_log_input(dir / "run.lcmlog", {"GROUND_TRUTH"});
  EXPECT_EQ(gt.frame, PoseFrame::kCamera);
  EXPECT_EQ(reconcile_frames(gt, est), "camera poses");
  const metrics::Evaluation e = metrics::evaluate(est.frame_utimes, est.trajectory, gt.trajectory, metrics::EvalOptions{});
  EXPECT_EQ(e.association.scored, log.frames.size() - 1);
  EXPECT_LT(e.ate.error_m.max, 1e-9);
  EXPECT_LT(e.velocity.error_mps.max, 1e-9);
  EXPECT_LT(e.rpe.translation_mps.max, 1e-9);
  EXPECT_EQ(e.velocity.gross.no_estimate, 1u);
  EXPECT_EQ(e.velocity.gross.total(), 1u);
}

TEST(EvalLog, BodyGroundTruthIsComparedInTheCameraFrame) {
  kestrel::test::TempDir dir;
  KnownLog().write(dir / "run.lcmlog", kestrel::ground_truth_t::FRAME_BODY);
  const TrajectoryInput est = read_log_input(dir / "run.lcmlog", {"VO_UPDATE"});
  TrajectoryInput gt = read_log_input(dir / "run.lcmlog", {"GROUND_TRUTH"});
  EXPECT_EQ(gt.frame, PoseFrame::kBody);
  EXPECT_EQ(reconcile_frames(gt, est),
            "camera poses (ground truth converted from body with T_body_camera)");
  const metrics::Evaluation e = metrics::evaluate(est.frame_utimes, est.trajectory, gt.trajectory, metrics::EvalOptions{});
  EXPECT_LT(e.ate.error_m.max, 1e-9);
  EXPECT_LT(e.velocity.error_mps.max, 1e-9);
}

TEST(EvalLog, TruncatedLogKeepsTheIntactEventsAndReportsTheDamage) {
  kestrel::test::TempDir dir;
  KnownLog().write(dir / "run.lcmlog", kestrel::ground_truth_t::FRAME_CAMERA);
  const TrajectoryInput whole = read_log_input(dir / "run.lcmlog", {"GROUND_TRUTH"});
  auto bytes = read_bytes(dir / "run.lcmlog");
  bytes.resize(bytes.size() * 2 / 3);
  write_bytes(dir / "cut.lcmlog", bytes);
  const TrajectoryInput gt = read_log_input(dir / "cut.lcmlog", {"GROUND_TRUTH"});
  EXPECT_NE(gt.diagnostics.damage.find("cut.lcmlog: damaged LCM log: truncated last event"),
            std::string::npos)
      << gt.diagnostics.damage;
  EXPECT_GT(gt.trajectory.size(), whole.trajectory.size() / 2);
  EXPECT_LT(gt.trajectory.size(), whole.trajectory.size());
  // What was read is exactly the start of the intact log.
  for (size_t i = 0; i < gt.trajectory.size(); ++i)
    EXPECT_EQ(gt.trajectory.poses()[i].utime, whole.trajectory.poses()[i].utime);
  EXPECT_EQ(gt.diagnostics.problems().front(), gt.diagnostics.damage);
}

TEST(EvalLog, WrongTypeCorruptNanAndOutOfOrderMessagesAreCounted) {
  kestrel::test::TempDir dir;
  {
    LogWriter w(dir / "bad.lcmlog");
    const auto T = test::helix_pose(test::kStart_us);
    w.write_message("GROUND_TRUTH", 1, gt_message(1000, T, kestrel::ground_truth_t::FRAME_CAMERA));
    kestrel::imu_t imu{};
    imu.utime = 1500;
    w.write_message("GROUND_TRUTH", 2, imu);  // wrong type
    auto bytes =
        transport::encode_message(gt_message(2000, T, kestrel::ground_truth_t::FRAME_CAMERA));
    bytes.resize(bytes.size() - 5);
    w.write("GROUND_TRUTH", 3, bytes);  // right fingerprint, cut short
    auto nan_pose = gt_message(3000, T, kestrel::ground_truth_t::FRAME_CAMERA);
    nan_pose.T_world_frame.position[1] = std::numeric_limits<double>::quiet_NaN();
    w.write_message("GROUND_TRUTH", 4, nan_pose);
    w.write_message("GROUND_TRUTH", 5, gt_message(500, T, kestrel::ground_truth_t::FRAME_CAMERA));
    w.write_message("GROUND_TRUTH", 6, gt_message(4000, T, kestrel::ground_truth_t::FRAME_CAMERA));
    w.close();
  }
  const TrajectoryInput gt = read_log_input(dir / "bad.lcmlog", {"GROUND_TRUTH"});
  const InputDiagnostics& d = gt.diagnostics;
  EXPECT_EQ(d.messages, 6u);
  EXPECT_EQ(d.wrong_type, 1u);
  EXPECT_EQ(d.corrupt, 1u);
  EXPECT_EQ(d.invalid_pose, 1u);
  EXPECT_EQ(d.out_of_order, 1u);
  EXPECT_EQ(gt.frame_utimes, (std::vector<int64_t>{1000, 4000}));
  EXPECT_EQ(d.problems().size(), 4u);
  EXPECT_EQ(d.problems().front(), "1 message(s) of another type skipped");
}

// STATE and VO_UPDATE in one log: the automatic choice takes STATE, and the camera mounting
// comes from VO_UPDATE.
TEST(EvalLog, StateGivesBodyPosesWhenTheFilterIsRunning) {
  kestrel::test::TempDir dir;
  {
    LogWriter w(dir / "state.lcmlog");
    w.write_message("VO_UPDATE", 500,
                    test::vo_message(500, 0, kestrel::vo_update_t::STATUS_NO_REFERENCE,
                                     Eigen::Isometry3d::Identity()));
    const int8_t statuses[] = {kestrel::state_t::STATUS_INITIALIZING, kestrel::state_t::STATUS_OK,
                               kestrel::state_t::STATUS_DEGRADED, kestrel::state_t::STATUS_FAILED};
    for (int i = 0; i < 4; ++i) {
      kestrel::state_t m{};
      m.utime = 1000 * (i + 1);
      m.status = statuses[i];
      m.T_world_body = to_message(se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(i, 0, 0)));
      w.write_message("STATE", m.utime, m);
    }
    w.close();
  }
  const TrajectoryInput est = read_log_input(dir / "state.lcmlog", {"STATE", "VO_UPDATE"});
  EXPECT_EQ(est.source, (dir / "state.lcmlog").string() + ":STATE");
  EXPECT_EQ(est.frame, PoseFrame::kBody);
  EXPECT_EQ(est.frame_utimes.size(), 4u);
  EXPECT_EQ(est.diagnostics.no_pose, 2u);
  ASSERT_EQ(est.trajectory.size(), 2u);
  EXPECT_EQ(est.trajectory.poses()[1].utime, 3000);
  EXPECT_DOUBLE_EQ(est.trajectory.poses()[1].T.translation().x(), 2.0);
  ASSERT_TRUE(est.T_body_camera.has_value());
  EXPECT_TRUE(est.T_body_camera->isApprox(kBodyCamera, 1e-12));
  EXPECT_FALSE(read_log_input(dir / "state.lcmlog", {"VO_UPDATE"}).trajectory.empty());
}

// SLAM_GRAPH: the final graph of each SLAM session. The first session's graphs grow and one
// moves a keyframe; a restarted SLAM (new ids, slam/slam_messages.h) maps on with a graph of
// its own; a graph of a lower revision is out of order.
TEST(EvalLog, SlamGraphGivesEachSessionsFinalKeyframes) {
  auto graph = [](int64_t first_id, int64_t revision, const std::vector<double>& x) {
    kestrel::slam_graph_t g{};
    g.revision = revision;
    for (size_t i = 0; i < x.size(); ++i) {
      kestrel::slam_keyframe_t k{};
      k.id = first_id + static_cast<int64_t>(i);
      k.utime = first_id * 10 + 1000 * static_cast<int64_t>(i);
      k.T_world_camera = to_message(se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(x[i], 0, 0)));
      k.T_camera_depth = to_message(Eigen::Isometry3d::Identity());
      g.keyframes.push_back(k);
    }
    g.num_keyframes = static_cast<int32_t>(g.keyframes.size());
    g.utime = g.keyframes.back().utime;
    return g;
  };
  kestrel::test::TempDir dir;
  {
    LogWriter w(dir / "slam.lcmlog");
    w.write_message("SLAM_GRAPH", 1, graph(1000, 1000, {0.0, 1.0}));
    w.write_message("SLAM_GRAPH", 2, graph(1000, 1001, {0.0, 1.5, 2.0}));
    w.write_message("SLAM_GRAPH", 3, graph(9000, 9000, {5.0}));
    w.write_message("SLAM_GRAPH", 4, graph(1000, 1002, {0.0, 9.0, 9.0}));  // the old session, late
    w.write_message("SLAM_GRAPH", 5, graph(9000, 9001, {5.0, 6.0}));
    w.close();
  }
  const TrajectoryInput est = read_log_input(dir / "slam.lcmlog", {"SLAM_GRAPH"});
  EXPECT_EQ(est.frame, PoseFrame::kCamera);
  EXPECT_EQ(est.diagnostics.out_of_order, 1u);
  const std::vector<std::pair<int64_t, double>> expected = {
      {10000, 0.0}, {11000, 1.5}, {12000, 2.0}, {90000, 5.0}, {91000, 6.0}};
  ASSERT_EQ(est.trajectory.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(est.trajectory.poses()[i].utime, expected[i].first) << i;
    EXPECT_DOUBLE_EQ(est.trajectory.poses()[i].T.translation().x(), expected[i].second) << i;
  }
}

TEST(EvalLog, MissingChannelNamesTheChannelsPresent) {
  kestrel::test::TempDir dir;
  KnownLog().write(dir / "run.lcmlog", kestrel::ground_truth_t::FRAME_CAMERA);
  try {
    read_log_input(dir / "run.lcmlog", {"STATE"});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("run.lcmlog: no messages on STATE; channels in the log: "
                                         "GROUND_TRUTH (62) VO_UPDATE (60)"),
              std::string::npos)
        << e.what();
  }
}

TEST(EvalLog, GroundTruthFrameMayNotChange) {
  kestrel::test::TempDir dir;
  {
    LogWriter w(dir / "mixed.lcmlog");
    const auto T = Eigen::Isometry3d::Identity();
    w.write_message("GROUND_TRUTH", 1, gt_message(1000, T, kestrel::ground_truth_t::FRAME_CAMERA));
    w.write_message("GROUND_TRUTH", 2, gt_message(2000, T, kestrel::ground_truth_t::FRAME_BODY));
    w.close();
  }
  try {
    read_log_input(dir / "mixed.lcmlog", {"GROUND_TRUTH"});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "GROUND_TRUTH: ground truth of the camera changes to the body at 0.002000");
  }
}

TEST(EvalLog, KindIsToldByContent) {
  kestrel::test::TempDir dir;
  std::ofstream(dir / "traj.lcmlog") << "1.0 0 0 0 0 0 0 1\n";  // a TUM file, whatever its name
  EXPECT_FALSE(is_lcm_log(dir / "traj.lcmlog"));
  std::ofstream(dir / "empty.txt") << "";
  EXPECT_FALSE(is_lcm_log(dir / "empty.txt"));
  KnownLog().write(dir / "run.txt", kestrel::ground_truth_t::FRAME_CAMERA);
  EXPECT_TRUE(is_lcm_log(dir / "run.txt"));
  EXPECT_THROW(is_lcm_log(dir / "missing"), InputError);
}

}  // namespace
}  // namespace kestrel::eval
