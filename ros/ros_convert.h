#pragma once
// ROS 1 messages to kestrel's own types: images, camera calibration, IMU samples, transforms
// and time stamps. Pure functions of the message: no bag, no file, no LCM (bag_import.h reads
// the bag and writes kestrel's messages).
//
// Conventions (sensor_msgs and geometry_msgs documentation, REP-103/104):
//  * time: header stamps to microseconds rounded to the nearest (TUM's text lists print the
//    same stamps with six decimals, so a bag and its folder give the same utime);
//  * colour: rgb8, bgr8 and mono8 become CV_8UC3 in R,G,B order (RgbdFrame's invariant);
//  * depth: 16UC1 (mono16) is millimetres and kept as is, 32FC1 is metres and rounded to the
//    nearest millimetre (common/rgbd_frame.h: NaN, <= 0 and >= 65.535 m are "no reading");
//  * rows may be padded (step > width * bytes per pixel) and big-endian (is_bigendian);
//  * CameraInfo: K (row-major 3x3) gives fx, fy, cx, cy; D with "plumb_bob" (or
//    "rational_polynomial" whose extra terms are zero) gives k1 k2 p1 p2 k3; no D is no
//    distortion. R and P are not used: the images are taken as published (raw), as the TUM
//    reader takes its PNGs;
//  * Imu: a covariance whose element 0 is -1 marks a vector the sensor does not measure;
//  * Transform / Pose: the child (or the pose's frame) in the parent's; quaternions x, y, z, w.
// Every function throws InputError naming `what` (the topic, and the message's stamp) for a
// message it cannot convert.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include <opencv2/core/mat.hpp>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include "common/camera.h"

// kestrel::ros1, not kestrel::ros: inside namespace kestrel a nested `ros` would hide ROS's own.
namespace kestrel::ros1 {

/// Microseconds of a ROS time, rounded to the nearest.
int64_t to_utime(const ros::Time& t);
/// The ROS time of `utime` microseconds (>= 0), exactly.
ros::Time to_ros_time(int64_t utime);

/// True for the colour encodings colour_to_rgb reads (rgb8, bgr8, mono8).
bool is_colour_encoding(const std::string& encoding);
/// True for the depth encodings depth_to_mm reads (16UC1, mono16, 32FC1).
bool is_depth_encoding(const std::string& encoding);

/// The colour image as CV_8UC3, R,G,B.
cv::Mat colour_to_rgb(const sensor_msgs::Image& image, const std::string& what);
/// The depth image as CV_16UC1 millimetres, 0 = no reading.
cv::Mat depth_to_mm(const sensor_msgs::Image& image, const std::string& what);
/// Checks size, step and data length against the encoding without converting (for a first
/// pass over a bag that keeps no pixels); throws as the conversions would.
void check_image(const sensor_msgs::Image& image, bool depth, const std::string& what);

/// The pinhole camera of a CameraInfo (width, height, K, D); throws for a zero, negative or
/// non-finite focal length, a non-finite principal point, a distortion model it does not know.
PinholeCamera camera_from_info(const sensor_msgs::CameraInfo& info, const std::string& what);

struct ImuReading {
  int64_t utime = 0;
  bool has_gyro = false;
  bool has_accel = false;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     ///< rad/s
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  ///< m/s^2
};
/// The sample in the message's own axes; throws for a non-finite value in a measured vector.
ImuReading imu_from_message(const sensor_msgs::Imu& imu, const std::string& what);

/// Throws for a non-finite value or a quaternion far from unit length (a slightly non-unit
/// one is normalised, as transport::from_message does).
Eigen::Isometry3d to_isometry(const geometry_msgs::Transform& t, const std::string& what);
Eigen::Isometry3d to_isometry(const geometry_msgs::Pose& p, const std::string& what);

/// A tf frame name without the leading '/' that ROS before tf2 wrote ("/world" -> "world").
std::string frame_name(const std::string& name);

}  // namespace kestrel::ros1
