#pragma once
// Bags written with the stock librosbag writer (rosbag::Bag, bagmode::Write) for the tests of
// ros/: a TUM RGB-D folder as TUM publishes its sequences as bags, and small messages to build
// good and bad bags from.

#include <cstdint>
#include <string>

#include <Eigen/Geometry>

#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

namespace kestrel::test {

struct TumBagOptions {
  size_t max_frames = 0;       ///< colour images written (with the depth images up to their end); 0 = all
  bool depth_16uc1_mm = false; ///< depth as 16UC1 millimetres instead of TUM's 32FC1 metres
};

struct TumBagContents {
  size_t colour = 0;
  size_t depth = 0;
  size_t imu = 0;
  size_t mocap = 0;  ///< world -> kinect transforms on /tf
};

/// The rigid mount from the mocap body ("kinect") to the camera's optical frame that the bag's
/// /tf carries (a made-up one: the importer must compose it with the mocap's transform to get
/// groundtruth.txt's camera pose back).
Eigen::Isometry3d tum_bag_mount();

/// Writes the TUM folder as a bag: colour (rgb8) on /camera/rgb/image_color, depth on
/// /camera/depth/image (32FC1 metres = PNG / 5000, NaN for no reading, as in TUM's bags; or
/// 16UC1 millimetres), the folder's calibration on /camera/rgb/camera_info with each colour
/// image, the accelerometer on /imu (camera axes, no gyro: covariance[0] = -1), the mocap on
/// /tf as world -> kinect (groundtruth.txt times the inverse mount) at 100 Hz with the static
/// kinect -> openni_rgb_optical_frame mount at every 10th. Bag time = header stamp.
TumBagContents write_tum_bag(const std::string& folder, const std::string& bag_path, const TumBagOptions& options = {});

/// A colour image of w x h in `encoding` (rgb8, bgr8, mono8 or any name) whose pixel (r, c)
/// has channels (r * 10 + c, 100 + r, 200 + c) in R, G, B (mono8: the first).
sensor_msgs::Image colour_image(int64_t utime, int w, int h, const std::string& encoding = "rgb8");
/// A 16UC1 depth image of `mm` everywhere.
sensor_msgs::Image depth_image_mm(int64_t utime, int w, int h, uint16_t mm);
/// A CameraInfo of w x h with focal lengths fx, fy and principal point at the centre.
sensor_msgs::CameraInfo camera_info(int64_t utime, int w, int h, double fx, double fy);
/// An accelerometer-only Imu message.
sensor_msgs::Imu accel_sample(int64_t utime, const Eigen::Vector3d& accel);
/// The transform of `child` in `parent` (T_parent_child) at `utime`, as tf publishes it.
geometry_msgs::TransformStamped transform(int64_t utime, const std::string& parent, const std::string& child,
                                          const Eigen::Isometry3d& T);

}  // namespace kestrel::test
