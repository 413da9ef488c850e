// The lens of SLAM's keyframe features (slam/place/frame_features.h): with a camera reporting
// its distortion (freiburg1's calibration here), a keypoint detected at a raw pixel gets the
// ideal pixel the Brown-Conrady model maps to that raw pixel, its point lies on that ideal
// pixel's ray with the depth read at the raw pixel, and its descriptor is the raw image's; a
// rolling shutter's row time is the raw row's. Zero distortion leaves the raw pixels as they are.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "slam/place/frame_features.h"
#include "test/slam/keyframe_scenes.h"

namespace kestrel::slam {
namespace {

// freiburg1's colour camera as TUM calibrated it (k1, k2, p1, p2, k3).
PinholeCamera fr1(bool with_distortion) {
  PinholeCamera c = PinholeCamera::vga(517.3, 516.5, 318.6, 255.3);
  if (with_distortion) c.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  return c;
}

/// Depth that changes with the raw column (1 mm a pixel, under the edge test's 3 %), so a
/// reading taken at the ideal pixel instead of the raw one would show.
cv::Mat column_ramp(const PinholeCamera& camera) {
  cv::Mat depth(camera.height, camera.width, CV_32FC1);
  for (int r = 0; r < camera.height; ++r)
    for (int c = 0; c < camera.width; ++c) depth.at<float>(r, c) = static_cast<float>(1.5 + 0.001 * c);
  return depth;
}

// Hand-worked: at ideal pixel (418.6, 255.3), x = 100 / 517.3 = 0.193311, y = 0, r^2 = 0.037369;
// radial = 1 + 0.2624 r^2 - 0.9531 r^4 + 1.1633 r^6 = 1.008535; p2 (r^2 + 2 x^2) = 0.000291; so
// the raw pixel is 318.6 + 517.3 (0.193311 * 1.008535 + 0.000291) = 419.604 (1.0 px further out).
TEST(KeyframeLens, Fr1sLensMapsTheHandWorkedPixel) {
  const Eigen::Vector2d raw = fr1(true).distort(418.6, 255.3);
  EXPECT_NEAR(raw.x(), 419.604, 0.001);
  // y: p1 (r^2 + 2 y^2) = -0.0054 * 0.037370 -> -0.104 px; 2 p2 x y = 0.
  EXPECT_NEAR(raw.y(), 255.3 - 0.104, 0.001);
}

TEST(KeyframeLens, PointOnTheIdealRayWithDepthReadAtTheRawPixel) {
  const PinholeCamera raw_camera = fr1(false), camera = fr1(true);
  const cv::Mat grey = test::texture(camera, 11), depth = column_ramp(camera);
  const FeatureExtractor extractor;
  const FrameFeatures plain = extractor.extract(grey, depth, raw_camera);  // zero distortion
  const FrameFeatures f = extractor.extract(grey, depth, camera);
  ASSERT_EQ(plain.size(), f.size());
  ASSERT_GT(f.size(), 300u);
  EXPECT_EQ(cv::norm(plain.descriptors, f.descriptors, cv::NORM_HAMMING), 0.0);  // described raw
  int checked = 0;
  double largest_shift_px = 0.0;
  for (size_t i = 0; i < f.size(); ++i) {
    const cv::Point2f raw = plain.keypoints[i].pt, ideal = f.keypoints[i].pt;
    // Zero distortion: the detected pixel and the pinhole ray through it, as always.
    if (plain.has_point(i)) {
      EXPECT_EQ(plain.points[i], raw_camera.backproject(static_cast<double>(raw.x), static_cast<double>(raw.y),
                                                        plain.points[i].z()));
    }
    // The ideal pixel is the one the lens maps to the raw keypoint (sensors::Lens: within 0.01 px).
    const Eigen::Vector2d back = camera.distort(static_cast<double>(ideal.x), static_cast<double>(ideal.y));
    EXPECT_NEAR(back.x(), raw.x, 1e-2) << "keypoint " << i;
    EXPECT_NEAR(back.y(), raw.y, 1e-2) << "keypoint " << i;
    largest_shift_px = std::max(largest_shift_px, double(std::hypot(ideal.x - raw.x, ideal.y - raw.y)));
    ASSERT_EQ(plain.has_point(i), f.has_point(i));  // depth validity is the raw pixel's
    if (!f.has_point(i)) continue;
    // Depth read at the raw pixel (the ramp's value there), along the ideal pixel's ray.
    const double z = f.points[i].z();
    EXPECT_EQ(z, plain.points[i].z());
    EXPECT_EQ(z, static_cast<double>(depth.at<float>(static_cast<int>(std::lround(raw.y)),
                                                     static_cast<int>(std::lround(raw.x)))));
    EXPECT_NEAR(f.points[i].x(), (double(ideal.x) - camera.cx) / camera.fx * z, 1e-9);
    EXPECT_NEAR(f.points[i].y(), (double(ideal.y) - camera.cy) / camera.fy * z, 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 300);
  EXPECT_GT(largest_shift_px, 5.0);  // freiburg1's lens moves most of the image by 5-8 px
}

// A rolling shutter (15 ms) on a camera turning about its y axis at 1 rad/s over a wall at 2 m,
// through freiburg1's lens: the point on the ideal ray is carried by the time of the raw row
// it was read on, s = (v_raw - 239.5) * 0.015 / 480, to p + s (w x p); the keypoint goes to the
// projection of that point (an ideal pixel).
TEST(KeyframeLens, RollingShutterTakesTheRawRowsTime) {
  const PinholeCamera raw_camera = fr1(false), camera = fr1(true);
  const double Z = 2.0, w = 1.0, readout = 0.015;
  const cv::Mat depth(camera.height, camera.width, CV_32FC1, cv::Scalar(Z));
  const cv::Mat grey = test::texture(camera, 11);
  const sensors::FrameMotion motion = test::moving({0, 0, 0}, {0, w, 0}, 0.0, readout);
  const FeatureExtractor extractor;
  const FrameFeatures plain = extractor.extract(grey, depth, raw_camera);
  const FrameFeatures still = extractor.extract(grey, depth, camera);
  const FrameFeatures timed = extractor.extract(grey, depth, camera, motion);
  ASSERT_EQ(plain.size(), timed.size());
  ASSERT_EQ(still.size(), timed.size());
  int checked = 0;
  for (size_t i = 0; i < timed.size(); ++i) {
    ASSERT_EQ(still.has_point(i), timed.has_point(i));
    if (!timed.has_point(i)) continue;
    const Eigen::Vector3d expected =
        test::carried_to_middle_row(still.points[i], static_cast<double>(plain.keypoints[i].pt.y), camera.height,
                                    readout, w);
    EXPECT_NEAR((timed.points[i] - expected).norm(), 0.0, 5e-6) << "keypoint " << i;
    const Eigen::Vector2d pixel = camera.project(expected);
    EXPECT_NEAR(timed.keypoints[i].pt.x, pixel.x(), 2e-3);
    EXPECT_NEAR(timed.keypoints[i].pt.y, pixel.y(), 2e-3);
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

}  // namespace
}  // namespace kestrel::slam
