// kestrel-bag-import on TUM fr1_xyz written as a bag with the stock librosbag writer as TUM
// publishes its bags (32FC1 metres, rgb8, CameraInfo, /imu, mocap on /tf): the imported log
// holds exactly the TUM reader's frames, so the visual odometry gives the same trajectory as
// `kestrel vo --tum` on the folder (to 1e-9 m), and the ground truth and IMU of the folder.
// Skipped when ../shared/data is absent (a failure under CI=true).

#include <gtest/gtest.h>

#include <chrono>

#include "common/trajectory.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/rgbd_codec.h"
#include "drivers/kinect/accelerometer.h"
#include "drivers/tum/tum_lists.h"
#include "drivers/tum/tum_sequence.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "sensors/builtin_profiles.h"
#include "test/ros/bag_writer.h"
#include "test/support/test_support.h"
#include "vo/sequence_run.h"
#include "vo/variants.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;

struct Imported {
  std::vector<RgbdFrame> frames;
  std::vector<imu_t> imu;
  std::vector<ground_truth_t> truth;
};

Imported read_log(const fs::path& log) {
  Imported out;
  transport::LogReader reader(log.string());
  while (auto e = reader.next()) {
    if (e->channel == channel::kCameraRgbd) {
      const auto m = transport::decode_message<rgbd_frame_t>(e->data.data(), e->data.size(), e->channel);
      out.frames.push_back(transport::decode_rgbd(m, "CAMERA_RGBD"));
    } else if (e->channel == channel::kImu) {
      out.imu.push_back(transport::decode_message<imu_t>(e->data.data(), e->data.size(), e->channel));
    } else if (e->channel == channel::kGroundTruth) {
      out.truth.push_back(transport::decode_message<ground_truth_t>(e->data.data(), e->data.size(), e->channel));
    }
  }
  return out;
}

// Runs the tool on a bag of `folder`; the log's content, and the tool's output in `summary`.
Imported import(const fs::path& folder, const test::TempDir& dir, const test::TumBagOptions& options,
                std::string& summary) {
  const fs::path bag = dir / "fr1_xyz.bag", log = dir / "fr1_xyz.lcmlog";
  const auto t0 = std::chrono::steady_clock::now();
  const test::TumBagContents written = test::write_tum_bag(folder.string(), bag.string(), options);
  const auto t1 = std::chrono::steady_clock::now();
  const test::RunResult r = test::run({test::tool("bag-import").string(), bag.string(), "--log", log.string()}, 120.0);
  const auto t2 = std::chrono::steady_clock::now();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  summary = r.out;
  std::cout << "bag written in " << std::chrono::duration<double>(t1 - t0).count() << " s (" << written.colour
            << " colour, " << written.depth << " depth, " << fs::file_size(bag) / 1000000 << " MB); imported in "
            << std::chrono::duration<double>(t2 - t1).count() << " s:\n"
            << r.out;
  return read_log(log);
}

void expect_same_frames(const std::vector<RgbdFrame>& got, const tum::TumSequence& reference, size_t count) {
  ASSERT_EQ(got.size(), count);
  for (size_t i = 0; i < count; ++i) {
    const RgbdFrame want = reference.frame(i);
    const RgbdFrame& f = got[i];
    ASSERT_EQ(f.utime, want.utime) << i;
    ASSERT_EQ(f.depth_utime, want.depth_utime) << i;
    ASSERT_EQ(f.seq, want.seq) << i;
    ASSERT_EQ(f.sensor, want.sensor) << i;
    ASSERT_EQ(f.camera.fx, want.camera.fx);
    ASSERT_EQ(f.camera.fy, want.camera.fy);
    ASSERT_EQ(f.camera.cx, want.camera.cx);
    ASSERT_EQ(f.camera.cy, want.camera.cy);
    ASSERT_EQ(f.camera.distortion, want.camera.distortion);
    ASSERT_TRUE(f.T_body_camera.isApprox(want.T_body_camera, 0.0)) << i;
    ASSERT_EQ(cv::norm(f.rgb, want.rgb, cv::NORM_INF), 0.0) << "colour of frame " << i;
    ASSERT_EQ(cv::norm(f.depth_mm, want.depth_mm, cv::NORM_INF), 0.0) << "depth of frame " << i;
  }
}

class RosBagData : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(test::tool("bag-import")))
      KESTREL_SKIP_ENVIRONMENT() << test::tool("bag-import") << " is not built (the ROS packages are missing)";
  }
};

TEST_F(RosBagData, Fr1XyzBagGivesTheFoldersFramesTruthAndVoTrajectory) {
  KESTREL_REQUIRE_TUM(folder, "rgbd_dataset_freiburg1_xyz");
  test::TempDir dir;
  std::string summary;
  const Imported log = import(folder, dir, {}, summary);
  const tum::TumSequence reference(folder.string());
  EXPECT_NE(summary.find("frames written: " + std::to_string(reference.size()) + " (colour images " +
                         std::to_string(reference.association().rgb_images) + ", depth images " +
                         std::to_string(reference.association().depth_images) + ")\n"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("colour images without a depth image within 0.02 s: " +
                         std::to_string(reference.association().unmatched_rgb) + "\n"),
            std::string::npos);
  EXPECT_NE(summary.find("depth images serving two colour images: " +
                         std::to_string(reference.association().shared_depth) + "\n"),
            std::string::npos);
  expect_same_frames(log.frames, reference, reference.size());
  if (HasFatalFailure()) return;

  // The visual odometry: `kestrel vo --tum` on the folder (load_tum_sequence, the default
  // variant with the folder's camera profile) against the odometry the vo process runs on the
  // log's frames (the default variant with the profile the frames name).
  const vo::LoadedSequence loaded = vo::load_tum_sequence(folder.string());
  const vo::SequenceRun from_folder =
      vo::run_sequence(loaded.frames, vo::with_tum_sensor(folder.string(), vo::variant("default").options));
  const vo::SequenceRun from_bag = vo::run_sequence(
      log.frames, vo::with_sensor(sensors::profile_of_sensor(log.frames.front().sensor), vo::variant("default").options));
  const auto& a = from_folder.trajectory.poses();
  const auto& b = from_bag.trajectory.poses();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), reference.size() * 9 / 10) << "the odometry lost most frames: nothing was compared";
  double worst_m = 0.0, worst_rad = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].utime, b[i].utime) << i;
    worst_m = std::max(worst_m, (a[i].T.translation() - b[i].T.translation()).norm());
    worst_rad = std::max(worst_rad, Eigen::AngleAxisd(a[i].T.linear().transpose() * b[i].T.linear()).angle());
  }
  std::cout << "VO poses compared: " << a.size() << ", largest difference " << worst_m << " m, " << worst_rad
            << " rad; path end at " << a.back().T.translation().transpose() << " m\n";
  EXPECT_LE(worst_m, 1e-9);
  EXPECT_LE(worst_rad, 1e-9);

  // The command itself: `kestrel vo --tum` on the folder writes the same trajectory file, byte
  // for byte, as the same writer given the odometry of the imported log.
  const fs::path vo_tool = test::tool("vo");
  if (fs::exists(vo_tool)) {
    const test::RunResult r =
        test::run({vo_tool.string(), "--tum", folder.string(), "--out", (dir / "folder.txt").string()}, 300.0);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    write_tum_trajectory((dir / "bag.txt").string(), from_bag.trajectory);
    const std::string by_tool = test::read_file(dir / "folder.txt");
    EXPECT_GT(by_tool.size(), 190u * 50u);
    EXPECT_EQ(test::read_file(dir / "bag.txt"), by_tool) << "kestrel vo --tum wrote another trajectory";
  }

  // Ground truth: groundtruth.txt's camera poses back from world -> kinect -> optical frame.
  const Trajectory gt = read_tum_trajectory((folder / "groundtruth.txt").string());
  ASSERT_FALSE(log.truth.empty());
  size_t matched = 0;
  for (const ground_truth_t& m : log.truth) {
    const auto it = std::find_if(gt.poses().begin(), gt.poses().end(), [&](const StampedPose& p) { return p.utime == m.utime; });
    ASSERT_NE(it, gt.poses().end()) << m.utime;
    const Eigen::Isometry3d T = transport::from_message(m.T_world_frame, "gt");
    EXPECT_LE((T.translation() - it->T.translation()).norm(), 1e-9) << m.utime;
    EXPECT_LE(Eigen::AngleAxisd(T.linear().transpose() * it->T.linear()).angle(), 1e-9) << m.utime;
    EXPECT_EQ(m.frame, ground_truth_t::FRAME_CAMERA);
    ++matched;
  }
  EXPECT_GT(matched, 600u);  // 6.3 s at 100 Hz, and the margins

  // IMU: the accelerometer in the camera's axes, as the TUM player publishes it.
  const auto accel = tum::read_accelerometer((folder / "accelerometer.txt").string());
  ASSERT_FALSE(log.imu.empty());
  for (const imu_t& m : log.imu) {
    const auto it = std::find_if(accel.begin(), accel.end(), [&](const auto& s) { return s.utime == m.utime; });
    ASSERT_NE(it, accel.end()) << m.utime;
    EXPECT_EQ(m.fields, imu_t::HAS_ACCEL);
    const Eigen::Vector3d want = kinect::accel_to_camera(it->accel_kinect);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.linear_acceleration[k], want[k]) << m.utime;
  }
  if (!fs::exists(vo_tool))
    KESTREL_SKIP_ENVIRONMENT() << vo_tool << " is not built: the trajectory was compared with its engine only";
}

TEST_F(RosBagData, Fr1XyzWithMillimetreDepthGivesTheSameFrames) {
  KESTREL_REQUIRE_TUM(folder, "rgbd_dataset_freiburg1_xyz");
  test::TempDir dir;
  test::TumBagOptions options;
  options.depth_16uc1_mm = true;
  options.max_frames = 20;  // the conversion, not the sequence, is under test
  std::string summary;
  const Imported log = import(folder, dir, options, summary);
  expect_same_frames(log.frames, tum::TumSequence(folder.string()), 20);
}

}  // namespace
}  // namespace kestrel
