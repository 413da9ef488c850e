// Reading inputs for the evaluation: TUM frame lists, frame reconciliation (body vs camera)
// and the chaining of visual-odometry motions.

#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "test/eval/synthetic.h"
#include "test/support/test_support.h"
#include "tools/eval/trajectory_input.h"
#include "tools/eval/vo_chain.h"

namespace kestrel::eval {
namespace {

void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}


TEST(EvalInput, FrameListReadsTheFirstColumn) {
  kestrel::test::TempDir dir;
  write_file(dir / "rgb.txt",
             "# color images\n# timestamp filename\n"
             "1305031104.675525 rgb/1305031104.675525.png\n\n"
             "1305031104.711277 rgb/1305031104.711277.png\n");
  EXPECT_EQ(read_frame_list(dir / "rgb.txt"),
            (std::vector<int64_t>{1305031104675525, 1305031104711277}));
}

TEST(EvalInput, BadFrameListsNameFileAndLine) {
  kestrel::test::TempDir dir;
  const std::string path = dir / "rgb.txt";
  write_file(path, "1.0 a.png\nx.5 b.png\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_frame_list(path); }).find(path + ":2: bad timestamp 'x.5'"),
            std::string::npos);
  write_file(path, "2.0 a.png\n1.0 b.png\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_frame_list(path); }).find(path + ":2: timestamp 1.0 is not after"),
            std::string::npos);
  const std::string missing = dir / "missing.txt";
  EXPECT_NE(kestrel::test::input_error_of([&] { read_frame_list(missing); }).find(missing + ": cannot open"),
            std::string::npos);
}

TEST(EvalInput, TumInputListsEveryPoseAsAFrame) {
  kestrel::test::TempDir dir;
  write_file(dir / "t.txt", "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n");
  const TrajectoryInput in = read_tum_input(dir / "t.txt");
  EXPECT_EQ(in.frame_utimes, (std::vector<int64_t>{1000000, 2000000}));
  EXPECT_EQ(in.frame, PoseFrame::kUnspecified);
  EXPECT_TRUE(in.diagnostics.problems().empty());
  write_file(dir / "nan.txt", "1.0 0 nan 0 0 0 0 1\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_tum_input(dir / "nan.txt"); }).find(":1: non-finite value"),
            std::string::npos);
}

// Ground truth of the body, estimate of the camera mounted at T_body_camera: the ground truth
// becomes T_world_body * T_body_camera, which is exactly the estimate's pose.
TEST(EvalInput, BodyGroundTruthIsPutIntoTheCameraFrame) {
  const Eigen::Isometry3d T_body_camera =
      se3::make(so3::exp(Eigen::Vector3d(-1.2, 0.0, -1.5)), Eigen::Vector3d(0.1, 0.0, -0.05));
  TrajectoryInput gt, est;
  gt.frame = PoseFrame::kBody;
  est.frame = PoseFrame::kCamera;
  est.T_body_camera = T_body_camera;
  for (int64_t t : test::frame_times(5)) {
    gt.trajectory.push_back(t, test::helix_pose(t));
    est.trajectory.push_back(t, test::helix_pose(t) * T_body_camera);
  }
  EXPECT_EQ(reconcile_frames(gt, est),
            "camera poses (ground truth converted from body with T_body_camera)");
  EXPECT_EQ(gt.frame, PoseFrame::kCamera);
  for (size_t i = 0; i < 5; ++i)
    EXPECT_TRUE(gt.trajectory.poses()[i].T.isApprox(est.trajectory.poses()[i].T, 1e-12));

  // And the other way round: camera ground truth, body estimate.
  TrajectoryInput gt_camera = est, est_body = gt;
  est_body.frame = PoseFrame::kBody;
  gt_camera.T_body_camera.reset();
  est_body.T_body_camera = T_body_camera;
  est_body.trajectory = Trajectory();
  for (int64_t t : test::frame_times(5)) est_body.trajectory.push_back(t, test::helix_pose(t));
  reconcile_frames(gt_camera, est_body);
  for (size_t i = 0; i < 5; ++i)
    EXPECT_TRUE(
        gt_camera.trajectory.poses()[i].T.isApprox(est_body.trajectory.poses()[i].T, 1e-12));
}

TEST(EvalInput, FramesThatCannotBeReconciledAreAnError) {
  TrajectoryInput gt, est;
  gt.source = "gt.lcmlog:GROUND_TRUTH";
  gt.frame = PoseFrame::kCamera;
  est.frame = PoseFrame::kBody;
  EXPECT_NE(kestrel::test::input_error_of([&] {
              reconcile_frames(gt, est);
            }).find("gt.lcmlog:GROUND_TRUTH: ground truth of the camera"),
            std::string::npos);
  est.frame = PoseFrame::kUnspecified;
  EXPECT_NE(reconcile_frames(gt, est).find("as given"), std::string::npos);
}

Eigen::Isometry3d step_x(double x) {
  return se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(x, 0, 0));
}

VoStep ok(int64_t utime, int64_t reference, const Eigen::Isometry3d& T) {
  VoStep s;
  s.utime = utime;
  s.reference_utime = reference;
  s.valid = true;
  s.T_reference_current = T;
  return s;
}
VoStep failed(int64_t utime, bool no_reference = false) {
  VoStep s;
  s.utime = utime;
  s.no_reference = no_reference;
  return s;
}

// Keyframe 1 at x = 0; frames 2, 3 relative to it; frame 3 becomes the keyframe for 4.
TEST(EvalVoChain, ChainsThroughKeyframes) {
  VoChain chain;
  chain.add(failed(1, true));
  chain.add(ok(2, 1, step_x(0.1)));
  chain.add(ok(3, 1, step_x(0.2)));
  chain.add(ok(4, 3, step_x(0.05)));
  const auto& poses = chain.trajectory().poses();
  ASSERT_EQ(poses.size(), 4u);
  EXPECT_TRUE(poses[0].T.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_NEAR(poses[1].T.translation().x(), 0.1, 1e-15);
  EXPECT_NEAR(poses[2].T.translation().x(), 0.2, 1e-15);
  EXPECT_NEAR(poses[3].T.translation().x(), 0.25, 1e-15);
  EXPECT_EQ(chain.without_estimate(), 0u);
  EXPECT_EQ(chain.unknown_reference(), 0u);
}

// Frame 3 fails and becomes the reference of frame 4: frame 4 continues from the last known
// pose (frame 2); a restart after a reset (frame 5, "no reference") has no estimate either.
TEST(EvalVoChain, UnknownReferenceContinuesFromTheLastKnownPose) {
  VoChain chain;
  chain.add(failed(1, true));
  chain.add(ok(2, 1, step_x(0.1)));
  chain.add(failed(3));
  chain.add(ok(4, 3, step_x(0.03)));
  chain.add(failed(5, true));
  chain.add(ok(6, 5, step_x(0.01)));
  EXPECT_EQ(chain.frame_utimes(), (std::vector<int64_t>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(chain.without_estimate(), 2u);
  EXPECT_EQ(chain.unknown_reference(), 2u);
  const Trajectory& t = chain.trajectory();
  ASSERT_EQ(t.size(), 4u);
  EXPECT_NEAR(t.at(4, 0)->translation().x(), 0.13, 1e-15);
  EXPECT_NEAR(t.at(6, 0)->translation().x(), 0.14, 1e-15);
  EXPECT_FALSE(t.at(3, 0).has_value());
  EXPECT_THROW(chain.add(ok(6, 5, step_x(0.0))), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::eval
