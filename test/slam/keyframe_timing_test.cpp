// The timing correction of SLAM's keyframe features (slam/place/frame_features.h): on a camera
// moving with a known twist, a keypoint's depth is read where its point was at depth time and
// the point is carried to the middle row's time, landing where the scene geometry says; the
// simulator's profile (global shutter, one capture time) changes nothing, bit for bit.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "common/geometry/se3.h"
#include "sensors/builtin_profiles.h"
#include "slam/place/frame_features.h"
#include "test/slam/keyframe_scenes.h"
#include "test/slam/synthetic_room.h"
#include "vo/sensor_profile.h"

namespace kestrel::slam {
namespace {

using test::carried_to_middle_row;
using test::moving;

// Camera sliding along +x at 4 m/s, its depth image 30 ms older than the colour, over a plane
// tilted about the y axis: in the camera at depth time z = Z0 + k x (Z0 = 2 m, k = 0.25). At
// colour time the camera is 0.12 m further along x (x_depth = x - d with d = offset * v =
// -0.12 m), so the plane is z = Z0 + k (x - d), and the point on the ray (a, b, 1) of a keypoint
// is at z = (Z0 - k d) / (1 - k a). Read at the keypoint's pixel alone it would be
// Z0 / (1 - k a): k d = -0.03 m off.
TEST(KeyframeTiming, DepthReadWhereThePointWasAtDepthTime) {
  const PinholeCamera camera = test::test_camera();
  const double Z0 = 2.0, k = 0.25, v = 4.0, offset = -0.03, d = offset * v;
  cv::Mat depth(camera.height, camera.width, CV_32FC1);
  for (int r = 0; r < camera.height; ++r)
    for (int c = 0; c < camera.width; ++c)
      depth.at<float>(r, c) = static_cast<float>(Z0 / (1.0 - k * (c - camera.cx) / camera.fx));
  const cv::Mat grey = test::texture(camera, 7);
  const FeatureExtractor extractor;
  const FrameFeatures still = extractor.extract(grey, depth, camera);
  const FrameFeatures timed = extractor.extract(grey, depth, camera, moving({v, 0, 0}, {0, 0, 0}, offset, 0.0));
  ASSERT_EQ(still.size(), timed.size());
  int checked = 0;
  for (size_t i = 0; i < timed.size(); ++i) {
    if (!timed.has_point(i) || !still.has_point(i)) continue;
    // Global shutter: the keypoint stays where it was detected.
    EXPECT_FLOAT_EQ(timed.keypoints[i].pt.x, still.keypoints[i].pt.x);
    EXPECT_FLOAT_EQ(timed.keypoints[i].pt.y, still.keypoints[i].pt.y);
    const double a = (double(timed.keypoints[i].pt.x) - camera.cx) / camera.fx;
    const double b = (double(timed.keypoints[i].pt.y) - camera.cy) / camera.fy;
    const double z_true = (Z0 - k * d) / (1.0 - k * a);
    // Nearest-pixel lookup on a plane whose depth changes by at most 2.5 mm a pixel.
    EXPECT_NEAR(timed.points[i].z(), z_true, 2e-3) << "keypoint " << i;
    EXPECT_NEAR(timed.points[i].x(), a * timed.points[i].z(), 1e-6);
    EXPECT_NEAR(timed.points[i].y(), b * timed.points[i].z(), 1e-6);
    EXPECT_NEAR(still.points[i].z(), Z0 / (1.0 - k * a), 2e-3);  // uncorrected: 30 mm off
    EXPECT_GT(std::abs(still.points[i].z() - z_true), 0.02);
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

// A rolling shutter (15 ms first to last row) on a camera turning about its y axis at 1 rad/s
// over a fronto-parallel wall at 2 m: row v was read s = (v - 119.5) * 0.015 / 240 s after the
// middle row, and its point p = (x, y, 2) is carried to the middle row's camera as
// p + s (w x p) = (x + 2 s w, y, 2 - s w x); the keypoint moves to that point's pixel.
TEST(KeyframeTiming, RollingShutterCarriesPointAndPixelToTheMiddleRow) {
  const PinholeCamera camera = test::test_camera();
  const double Z = 2.0, w = 1.0, readout = 0.015;
  const cv::Mat depth(camera.height, camera.width, CV_32FC1, cv::Scalar(Z));
  const cv::Mat grey = test::texture(camera, 7);
  const FeatureExtractor extractor;
  const FrameFeatures still = extractor.extract(grey, depth, camera);
  const FrameFeatures timed = extractor.extract(grey, depth, camera, moving({0, 0, 0}, {0, w, 0}, 0.0, readout));
  ASSERT_EQ(still.size(), timed.size());
  int checked = 0;
  double largest_shift_px = 0.0;
  for (size_t i = 0; i < timed.size(); ++i) {
    ASSERT_EQ(still.has_point(i), timed.has_point(i));
    if (!timed.has_point(i)) continue;
    const Eigen::Vector3d expected =
        carried_to_middle_row(still.points[i], static_cast<double>(still.keypoints[i].pt.y), camera.height,
                              readout, w);
    EXPECT_NEAR((timed.points[i] - expected).norm(), 0.0, 2e-6) << "keypoint " << i;
    const Eigen::Vector2d pixel = camera.project(expected);
    EXPECT_NEAR(timed.keypoints[i].pt.x, pixel.x(), 2e-3);
    EXPECT_NEAR(timed.keypoints[i].pt.y, pixel.y(), 2e-3);
    largest_shift_px =
        std::max(largest_shift_px, double(std::abs(timed.keypoints[i].pt.x - still.keypoints[i].pt.x)));
    ++checked;
  }
  EXPECT_GT(checked, 50);
  EXPECT_GT(largest_shift_px, 1.5);  // the top and bottom rows: 2 * 0.0075 * 1 * fx ~ 4 px
}

// keyframe_motion(): the twist of the odometry's motion from the previous frame over the
// stamps' interval, the VO's depth offset (stamps minus the Kinect's 15 ms extra latency) and
// readout; the simulator's profile has neither.
TEST(KeyframeTiming, MotionFromTheOdometryAndTheProfile) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.015, 0.0, -0.006);
  const int64_t utime = 1'000'000'000, previous = utime - 30'000, depth_utime = utime - 12'000;
  const vo::DepthOptions kinect = vo::with_sensor(sensors::builtin_profile("kinect1"), vo::VoOptions{}).depth;
  const sensors::FrameMotion m = keyframe_motion(kinect, utime, depth_utime, previous, T);
  ASSERT_TRUE(m.known);
  EXPECT_NEAR(m.twist_per_s(0), 0.5, 1e-12);
  EXPECT_NEAR(m.twist_per_s(2), -0.2, 1e-12);
  EXPECT_NEAR(m.twist_per_s.tail<3>().norm(), 0.0, 1e-12);
  EXPECT_NEAR(m.depth_offset_s, -0.012 - 0.015, 1e-12);
  EXPECT_DOUBLE_EQ(m.readout_s, 0.015);  // kinect1.yaml's

  const vo::DepthOptions simulator = vo::with_sensor(sensors::builtin_profile("simulator"), vo::VoOptions{}).depth;
  const sensors::FrameMotion s = keyframe_motion(simulator, utime, depth_utime, previous, T);
  EXPECT_TRUE(s.known);
  EXPECT_EQ(s.depth_offset_s, 0.0);
  EXPECT_EQ(s.readout_s, 0.0);
  EXPECT_FALSE(keyframe_motion(kinect, utime, depth_utime, utime, T).known);  // no interval
}

// The simulator's profile: whatever the motion, the features are exactly those read without one.
TEST(KeyframeTiming, SimulatorProfileChangesNothing) {
  const test::SyntheticRoom room(3, 3.0, 2.5, 2.5);
  RgbdFrame frame = room.render(test::level_camera({0.5, 0.2, 1.0}, 0.3), test::test_camera(), 1'000'000);
  frame.depth_utime = frame.utime - 20'000;
  Eigen::Isometry3d T_previous_current = se3::exp((Eigen::Matrix<double, 6, 1>() << 0.02, 0.01, 0, 0.01, 0.03, 0).finished());
  const vo::DepthOptions simulator = vo::with_sensor(sensors::builtin_profile("simulator"), vo::VoOptions{}).depth;
  const sensors::FrameMotion motion = keyframe_motion(simulator, frame.utime, frame.depth_utime, frame.utime - 33'333, T_previous_current);
  ASSERT_TRUE(motion.known);
  const FeatureExtractor extractor;
  const FrameFeatures plain = extractor.extract(frame);
  const FrameFeatures timed = extractor.extract(frame, motion);
  ASSERT_EQ(plain.size(), timed.size());
  ASSERT_GT(plain.num_points(), 100u);
  for (size_t i = 0; i < plain.size(); ++i) {
    EXPECT_EQ(plain.keypoints[i].pt, timed.keypoints[i].pt);
    ASSERT_EQ(plain.has_point(i), timed.has_point(i));
    if (plain.has_point(i)) {
      EXPECT_EQ(plain.points[i], timed.points[i]);
    }
  }
  EXPECT_EQ(cv::norm(plain.descriptors, timed.descriptors, cv::NORM_HAMMING), 0.0);
}

}  // namespace
}  // namespace kestrel::slam
