// ros/ros_convert.h against hand-computed answers: time stamps, image encodings, CameraInfo,
// Imu and transforms.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/error.h"
#include "ros/ros_convert.h"
#include "test/ros/bag_writer.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

using ros1::to_utime;

TEST(RosConvert, StampsRoundToTheNearestMicrosecondBothWays) {
  EXPECT_EQ(to_utime(ros::Time(1305031104, 675525000)), 1305031104675525);
  EXPECT_EQ(to_utime(ros::Time(10, 1499)), 10000001);       // 1.499 us
  EXPECT_EQ(to_utime(ros::Time(10, 1500)), 10000002);       // 1.5 us: up
  EXPECT_EQ(to_utime(ros::Time(10, 999999500)), 11000000);  // carries into the next second
  const ros::Time t = ros1::to_ros_time(1305031104675525);
  EXPECT_EQ(t.sec, 1305031104u);
  EXPECT_EQ(t.nsec, 675525000u);
  EXPECT_THROW(ros1::to_ros_time(-1), std::invalid_argument);
}

TEST(RosConvert, ColourEncodingsGiveRgbInRgbOrder) {
  for (const std::string enc : {"rgb8", "bgr8"}) {
    const cv::Mat rgb = ros1::colour_to_rgb(test::colour_image(0, 4, 3, enc), "/c");
    ASSERT_EQ(rgb.type(), CV_8UC3) << enc;
    ASSERT_EQ(rgb.size(), cv::Size(4, 3));
    // Pixel (row 2, column 3): R = 23, G = 102, B = 203, whatever the order on the wire.
    EXPECT_EQ(rgb.at<cv::Vec3b>(2, 3), cv::Vec3b(23, 102, 203)) << enc;
    EXPECT_EQ(rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 100, 200)) << enc;
  }
  const cv::Mat grey = ros1::colour_to_rgb(test::colour_image(0, 4, 3, "mono8"), "/c");
  EXPECT_EQ(grey.at<cv::Vec3b>(2, 3), cv::Vec3b(23, 23, 23));
}

TEST(RosConvert, PaddedRowsAreSkipped) {
  sensor_msgs::Image m = test::colour_image(0, 2, 2, "rgb8");
  // Rows of 6 bytes stored in 8: two bytes of padding that must not shift the second row.
  m.step = 8;
  m.data = {1, 2, 3, 4, 5, 6, 99, 99, 7, 8, 9, 10, 11, 12, 99, 99};
  const cv::Mat rgb = ros1::colour_to_rgb(m, "/c");
  EXPECT_EQ(rgb.at<cv::Vec3b>(1, 0), cv::Vec3b(7, 8, 9));
  EXPECT_EQ(rgb.at<cv::Vec3b>(1, 1), cv::Vec3b(10, 11, 12));
}

TEST(RosConvert, Depth16uc1IsMillimetresInEitherByteOrder) {
  sensor_msgs::Image m = test::depth_image_mm(0, 3, 2, 1234);
  cv::Mat mm = ros1::depth_to_mm(m, "/d");
  ASSERT_EQ(mm.type(), CV_16UC1);
  EXPECT_EQ(mm.at<uint16_t>(1, 2), 1234);
  // 1234 = 0x04D2, big-endian bytes 04 D2.
  m.is_bigendian = 1;
  for (size_t i = 0; i < m.data.size(); i += 2) m.data[i] = 0x04, m.data[i + 1] = 0xD2;
  mm = ros1::depth_to_mm(m, "/d");
  EXPECT_EQ(mm.at<uint16_t>(0, 0), 1234);
  m.encoding = "mono16";
  EXPECT_EQ(ros1::depth_to_mm(m, "/d").at<uint16_t>(1, 1), 1234);
}

TEST(RosConvert, Depth32fc1MetresRoundToMillimetresAndNanIsNoReading) {
  sensor_msgs::Image m;
  m.width = 6;
  m.height = 1;
  m.encoding = "32FC1";
  m.step = 24;
  const float values[6] = {1.2346f, 0.0004f, std::numeric_limits<float>::quiet_NaN(), -1.0f, 70.0f, 0.2f};
  m.data.resize(24);
  std::memcpy(m.data.data(), values, 24);
  const cv::Mat mm = ros1::depth_to_mm(m, "/d");
  EXPECT_EQ(mm.at<uint16_t>(0, 0), 1235);  // 1234.6 mm
  EXPECT_EQ(mm.at<uint16_t>(0, 1), 0);     // 0.4 mm: below any reading
  EXPECT_EQ(mm.at<uint16_t>(0, 2), 0);     // NaN: no reading
  EXPECT_EQ(mm.at<uint16_t>(0, 3), 0);     // negative
  EXPECT_EQ(mm.at<uint16_t>(0, 4), 0);     // beyond 65.535 m
  EXPECT_EQ(mm.at<uint16_t>(0, 5), 200);
  // TUM's 1/5000 m depth stored as metres gives the TUM reader's millimetres: round(raw / 5).
  for (const uint16_t raw : {1u, 2u, 3u, 7u, 5003u, 5004u, 65534u}) {
    const float metres = static_cast<float>(raw) / 5000.0f;
    std::memcpy(m.data.data(), &metres, 4);
    EXPECT_EQ(ros1::depth_to_mm(m, "/d").at<uint16_t>(0, 0), static_cast<uint16_t>(std::lround(raw / 5.0))) << raw;
  }
}

TEST(RosConvert, UnknownEncodingsAndShortImagesAreErrorsNamingTheTopic) {
  sensor_msgs::Image depth = test::depth_image_mm(0, 3, 2, 1);
  depth.encoding = "8UC1";
  const std::string e = test::input_error_of([&] { ros1::depth_to_mm(depth, "/camera/depth/image"); });
  EXPECT_NE(e.find("/camera/depth/image"), std::string::npos) << e;
  EXPECT_NE(e.find("'8UC1'"), std::string::npos) << e;
  EXPECT_NE(test::input_error_of([&] { ros1::colour_to_rgb(test::colour_image(0, 2, 2, "rgba8"), "/c"); })
                .find("'rgba8'"),
            std::string::npos);
  sensor_msgs::Image shortened = test::colour_image(0, 4, 3);
  shortened.data.resize(shortened.data.size() - 1);
  EXPECT_NE(test::input_error_of([&] { ros1::colour_to_rgb(shortened, "/c"); }).find("35 bytes of pixels, 36 expected"),
            std::string::npos);
  sensor_msgs::Image narrow = test::colour_image(0, 4, 3);
  narrow.step = 11;
  EXPECT_NE(test::input_error_of([&] { ros1::colour_to_rgb(narrow, "/c"); }).find("step 11"), std::string::npos);
  // A depth row padded by an odd byte is not a whole number of 16-bit pixels: refused by name,
  // not by OpenCV.
  sensor_msgs::Image odd = test::depth_image_mm(0, 3, 2, 1);
  odd.step = 7;
  odd.data.resize(size_t{odd.step} * odd.height);
  const std::string o = test::input_error_of([&] { ros1::depth_to_mm(odd, "/camera/depth/image"); });
  EXPECT_NE(o.find("step 7 is not a whole number"), std::string::npos) << o;
}

TEST(RosConvert, CameraInfoGivesIntrinsicsAndPlumbBobDistortion) {
  sensor_msgs::CameraInfo info = test::camera_info(0, 640, 480, 517.3, 516.5);
  info.K[2] = 318.6;
  info.K[5] = 255.3;
  info.D = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  PinholeCamera c = ros1::camera_from_info(info, "/ci");
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_EQ(c.fx, 517.3);
  EXPECT_EQ(c.fy, 516.5);
  EXPECT_EQ(c.cx, 318.6);
  EXPECT_EQ(c.cy, 255.3);
  EXPECT_EQ(c.distortion, (std::array<double, 5>{0.2624, -0.9531, -0.0054, 0.0026, 1.1633}));
  // rational_polynomial with k4..k6 = 0 is the same lens.
  info.distortion_model = "rational_polynomial";
  info.D = {0.1, -0.2, 0.001, 0.002, 0.3, 0, 0, 0};
  c = ros1::camera_from_info(info, "/ci");
  EXPECT_EQ(c.distortion, (std::array<double, 5>{0.1, -0.2, 0.001, 0.002, 0.3}));
  // No coefficients, or all zero under any name: no distortion.
  info.distortion_model = "";
  info.D.clear();
  EXPECT_FALSE(ros1::camera_from_info(info, "/ci").distorted());
  info.distortion_model = "equidistant";
  info.D = {0.1, 0.2, 0.3, 0.4};
  EXPECT_NE(test::input_error_of([&] { ros1::camera_from_info(info, "/ci"); }).find("'equidistant'"), std::string::npos);
}

TEST(RosConvert, CameraInfoWithZeroFocalLengthIsAnErrorNamingTheTopic) {
  const sensor_msgs::CameraInfo info = test::camera_info(0, 640, 480, 0.0, 0.0);
  const std::string e = test::input_error_of([&] { ros1::camera_from_info(info, "/camera/rgb/camera_info"); });
  EXPECT_NE(e.find("/camera/rgb/camera_info"), std::string::npos) << e;
  EXPECT_NE(e.find("focal length"), std::string::npos) << e;
}

TEST(RosConvert, ImuCovarianceMinusOneMarksWhatIsNotMeasured) {
  sensor_msgs::Imu m = test::accel_sample(5, {0.1, -9.8, 0.2});
  ros1::ImuReading r = ros1::imu_from_message(m, "/imu");
  EXPECT_EQ(r.utime, 5);
  EXPECT_TRUE(r.has_accel);
  EXPECT_FALSE(r.has_gyro);
  EXPECT_EQ(r.linear_acceleration, Eigen::Vector3d(0.1, -9.8, 0.2));
  m.angular_velocity_covariance[0] = 0.01;
  m.angular_velocity.z = 0.5;
  r = ros1::imu_from_message(m, "/imu");
  EXPECT_TRUE(r.has_gyro);
  EXPECT_EQ(r.angular_velocity, Eigen::Vector3d(0, 0, 0.5));
  // A NaN in an unmeasured vector is no error (nothing reads it); in a measured one it is.
  m.angular_velocity_covariance[0] = -1.0;
  m.angular_velocity.x = std::nan("");
  EXPECT_NO_THROW(ros1::imu_from_message(m, "/imu"));
  m.linear_acceleration.y = std::nan("");
  const std::string e = test::input_error_of([&] { ros1::imu_from_message(m, "/imu at 5 s"); });
  EXPECT_NE(e.find("/imu at 5 s"), std::string::npos) << e;
  EXPECT_NE(e.find("linear_acceleration"), std::string::npos) << e;
}

TEST(RosConvert, TransformsAreTheChildInTheParent) {
  geometry_msgs::Transform t;
  t.translation.x = 1.0;
  t.translation.y = 2.0;
  t.translation.z = 3.0;
  // 90 degrees about z: x, y, z, w = 0, 0, sin 45, cos 45.
  t.rotation.z = std::sqrt(0.5);
  t.rotation.w = std::sqrt(0.5);
  const Eigen::Isometry3d T = ros1::to_isometry(t, "/tf");
  // The child's x axis is the parent's y; its origin at (1, 2, 3).
  EXPECT_TRUE((T * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(1, 3, 3), 1e-12));
  t.rotation.w = 0.9;  // norm 1.14: not a rotation
  EXPECT_NE(test::input_error_of([&] { ros1::to_isometry(t, "/tf"); }).find("quaternion"), std::string::npos);
  EXPECT_EQ(ros1::frame_name("/world"), "world");
  EXPECT_EQ(ros1::frame_name("world"), "world");
}

}  // namespace
}  // namespace kestrel
