// Depth between cameras: the z-buffered forward warp (depth_warp.h) and the Kinect's
// registration of raw IR depth to the RGB camera (depth_registration.h), against analytic
// scenes.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <random>

#include "drivers/kinect/depth_registration.h"
#include "drivers/kinect/depth_warp.h"

namespace kestrel::kinect {
namespace {

// A plane n . p = d in the RGB camera's frame, tilted in both image directions.
struct Plane {
  Eigen::Vector3d n = Eigen::Vector3d(0.25, -0.15, 1.0).normalized();
  double d = 2.0 * Eigen::Vector3d(0.25, -0.15, 1.0).normalized().z();  // through (0, 0, 2)

  // Depth (z) of the plane seen through pixel (u, v) of `c`, in the frame of `c` whose
  // points map into the RGB frame by T_rgb_c.
  double depth(const PinholeCamera& c, const Eigen::Isometry3d& T_rgb_c, double u, double v) const {
    const Eigen::Vector3d ray((u - c.cx) / c.fx, (v - c.cy) / c.fy, 1.0);
    return (d - n.dot(T_rgb_c.translation())) / n.dot(T_rgb_c.linear() * ray);
  }
};

TEST(DepthWarp, IdentityChangesNothing) {
  PinholeCamera c;
  cv::Mat depth(480, 640, CV_32FC1);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> z(0.4f, 6.0f);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) depth.at<float>(v, u) = (u * 7 + v) % 11 == 0 ? 0.0f : z(rng);
  depth.at<float>(5, 5) = std::nanf("");
  depth.at<float>(6, 6) = -1.0f;
  const cv::Mat out = DepthWarp(c, c, Eigen::Isometry3d::Identity())(depth);
  cv::Mat expected = depth.clone();
  expected.at<float>(5, 5) = 0.0f;
  expected.at<float>(6, 6) = 0.0f;
  EXPECT_EQ(cv::norm(out, expected, cv::NORM_INF), 0.0);
}

TEST(DepthWarp, NearestSurfaceWinsAndHolesStayEmpty) {
  PinholeCamera c;  // fx = 525
  // Background at 3 m, a 40x40 px square at 1 m around the centre.
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(3.0));
  depth(cv::Rect(300, 220, 40, 40)).setTo(1.0);
  // The target camera sits 0.1 m to the +x side: points move left by f b / z pixels,
  // 52.5 px at 1 m and 17.5 px at 3 m.
  Eigen::Isometry3d T_to_from = Eigen::Isometry3d::Identity();
  T_to_from.translation() = Eigen::Vector3d(-0.1, 0.0, 0.0);
  const cv::Mat out = DepthWarp(c, c, T_to_from)(depth);
  // The square now covers columns 247.5 .. 287 (300 - 52.5 ...): it hides the background
  // that also lands there.
  for (int u = 249; u <= 286; ++u) EXPECT_FLOAT_EQ(out.at<float>(240, u), 1.0f) << u;
  // Just right of it, background the source camera could not see (it was behind the
  // square): from 287.5 to 339 - 17.5 = 322.5 nothing lands, and nothing is invented.
  for (int u = 289; u <= 321; ++u) EXPECT_EQ(out.at<float>(240, u), 0.0f) << u;
  EXPECT_FLOAT_EQ(out.at<float>(240, 330), 3.0f);
  EXPECT_FLOAT_EQ(out.at<float>(100, 100), 3.0f);
  // The right 17 columns of the target see beyond the source image.
  EXPECT_EQ(out.at<float>(100, 630), 0.0f);
}

TEST(DepthRegistration, IdentityCalibrationGivesExactlyTheInput) {
  PinholeCamera c;
  c.fx = 517.3;
  c.fy = 516.5;
  c.cx = 318.6;
  c.cy = 255.3;
  const DepthRegistration reg(KinectCalibration::identity(c));
  const DisparityModel model;
  cv::Mat raw(480, 640, CV_16UC1);
  std::mt19937 rng(5);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u)
      raw.at<uint16_t>(v, u) = rng() % 9 == 0 ? DisparityModel::kNoReading : static_cast<uint16_t>(rng() % 1050);
  const cv::Mat mm = reg.register_raw(raw);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const uint16_t r = raw.at<uint16_t>(v, u);
      // The registration works in float metres; millimetres are those rounded.
      const long expected = r == DisparityModel::kNoReading ? 0 : std::lround(static_cast<float>(model.metres(r)) * 1000.0f);
      ASSERT_EQ(mm.at<uint16_t>(v, u), expected) << v << "," << u << " raw " << r;
    }
  }
  // And back: millimetres -> raw -> millimetres is exact within the quantisation everywhere.
  const cv::Mat back = reg.register_raw(reg.unregister_mm(mm));
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const int z = mm.at<uint16_t>(v, u);
      if (z == 0) {
        ASSERT_EQ(back.at<uint16_t>(v, u), 0);
        continue;
      }
      ASSERT_NEAR(back.at<uint16_t>(v, u), z, 0.5 * model.step_at(z * 1e-3) * 1e3 + 1.0) << v << "," << u;
    }
  }
}

TEST(DepthRegistration, RegisteredPlaneHasTheAnalyticDepth) {
  const KinectCalibration cal = KinectCalibration::standard();
  const DepthRegistration reg(cal);
  const Plane plane;
  // What the IR camera measures: the plane's depth along each IR ray, as raw values.
  cv::Mat raw(480, 640, CV_16UC1);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) raw.at<uint16_t>(v, u) = cal.disparity.raw(plane.depth(cal.ir, cal.T_rgb_ir(), u, v));
  const cv::Mat mm = reg.register_raw(raw);

  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  int checked = 0, covered = 0;
  double worst = 0.0;
  for (int v = 2; v < 478; ++v) {
    for (int u = 2; u < 638; ++u) {
      const double z = plane.depth(cal.rgb, I, u, v);
      // Only pixels whose surface point the IR camera sees, away from its border.
      const Eigen::Vector3d p_ir = cal.T_ir_rgb * (z * Eigen::Vector3d((u - cal.rgb.cx) / cal.rgb.fx,
                                                                       (v - cal.rgb.cy) / cal.rgb.fy, 1.0));
      const Eigen::Vector2d px = cal.ir.project(p_ir);
      if (!cal.ir.contains(px.x(), px.y(), 2.0)) continue;
      ++checked;
      const int got = mm.at<uint16_t>(v, u);
      if (got == 0) continue;
      ++covered;
      // Quantisation of the raw value, plus half a pixel of resampling times the slope.
      const double slope = std::abs(plane.depth(cal.rgb, I, u + 1, v) - z) + std::abs(plane.depth(cal.rgb, I, u, v + 1) - z);
      const double tolerance = 0.5 * cal.disparity.step_at(z) + 0.5 * slope + 0.0006;
      worst = std::max(worst, std::abs(got * 1e-3 - z) / tolerance);
      ASSERT_LE(std::abs(got * 1e-3 - z), tolerance) << v << "," << u << " z " << z;
    }
  }
  EXPECT_GT(checked, 200000);
  // The IR camera has the finer pixels (fx 594 vs 529), so every RGB pixel it sees gets depth.
  EXPECT_GE(covered, checked * 0.999) << covered << " of " << checked;
  RecordProperty("worst_error_over_tolerance", std::to_string(worst));
}

TEST(DepthRegistration, UnregisterThenRegisterReturnsTheDepth) {
  const KinectCalibration cal = KinectCalibration::standard();
  const DepthRegistration reg(cal);
  const Plane plane;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  cv::Mat mm(480, 640, CV_16UC1);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) mm.at<uint16_t>(v, u) = static_cast<uint16_t>(std::lround(plane.depth(cal.rgb, I, u, v) * 1e3));
  const cv::Mat back = reg.register_raw(reg.unregister_mm(mm));
  int in_view = 0, lost_in_view = 0, outside_view = 0, kept_outside_view = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const double z = mm.at<uint16_t>(v, u) * 1e-3;
      const int got = back.at<uint16_t>(v, u);
      // The IR camera has the narrower view (fx 594 vs 529): what it cannot see is lost.
      const Eigen::Vector2d px = cal.ir.project(
          cal.T_ir_rgb * (z * Eigen::Vector3d((u - cal.rgb.cx) / cal.rgb.fx, (v - cal.rgb.cy) / cal.rgb.fy, 1.0)));
      if (!cal.ir.contains(px.x(), px.y(), 1.0)) {
        ++outside_view;
        kept_outside_view += got != 0 && !cal.ir.contains(px.x(), px.y(), -1.0);
        continue;
      }
      ++in_view;
      if (got == 0) {
        ++lost_in_view;
        continue;
      }
      const double slope = std::abs(plane.depth(cal.rgb, I, u + 1, v) - plane.depth(cal.rgb, I, u, v)) +
                           std::abs(plane.depth(cal.rgb, I, u, v + 1) - plane.depth(cal.rgb, I, u, v));
      // Two resamplings to the nearest pixel: up to a pixel of slope, plus quantisation.
      ASSERT_LE(std::abs(got * 1e-3 - z), 0.5 * cal.disparity.step_at(z) + slope + 0.0011) << v << "," << u;
    }
  }
  EXPECT_GT(outside_view, 640 * 480 / 10);  // about a fifth of the RGB image
  EXPECT_EQ(kept_outside_view, 0);
  EXPECT_EQ(lost_in_view, 0) << "of " << in_view;  // a smooth surface loses nothing it sees
}

TEST(KinectCalibration, StandardIsValidAndPutsTheRgbCameraOnTheIrCamerasPlusXSide) {
  const KinectCalibration c = KinectCalibration::standard();
  EXPECT_NO_THROW(c.validate());
  EXPECT_NEAR(c.T_ir_rgb.translation().x(), 0.019985, 1e-6);  // the RGB centre, in the IR frame
  EXPECT_NEAR(c.T_ir_rgb.linear().determinant(), 1.0, 1e-12);
  EXPECT_TRUE((c.T_ir_rgb * c.T_rgb_ir()).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  Eigen::Matrix3d skew = Eigen::Matrix3d::Identity();
  skew(0, 1) = 0.1;
  EXPECT_THROW(make_rigid(skew, Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(make_rigid(-Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()), std::invalid_argument);
  KinectCalibration bad = c;
  bad.ir.fx = 0.0;
  EXPECT_THROW(DepthRegistration{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::kinect
