#pragma once
// A ROS RGB-D camera driver's topics (colour, depth, CameraInfo, Imu) as the messages a
// kestrel source publishes (CAMERA_RGBD, IMU, GROUND_TRUTH): the options that name the topics,
// and the one place where converted ROS data becomes those messages. bag-import (a bag, two
// passes, bag_import.h) and ros-bridge (live topics, camera_stream.h) both build their
// messages here, so a bag imported and the same bag played into the bridge give the same bytes.
//
// Invariants of the messages made here:
//  * CAMERA_RGBD: utime = the colour stamp, depth_utime = the depth stamp, the camera given
//    (the first CameraInfo, or --intrinsics), T_body_camera = identity (the body is the colour
//    camera's optical frame, as for TUM), sensor as given; encoded with `encoding`;
//  * IMU: HAS_GYRO / HAS_ACCEL as the Imu measured them, in the axes given;
//  * GROUND_TRUTH: FRAME_CAMERA (the import's body is the camera).
// The size checks throw InputError with the words bag-import has always used.

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "common/camera.h"
#include "common/transport/rgbd_codec.h"
#include "ros/ros_convert.h"

namespace kestrel::ros1 {

/// Defaults read TUM RGB-D's own bags (rgbd_dataset_freiburg*_*.bag, recorded with a Kinect
/// through openni_camera; https://vision.in.tum.de/data/datasets/rgbd-dataset/file_formats).
struct CameraTopicOptions {
  std::string colour_topic = "/camera/rgb/image_color";
  std::string depth_topic = "/camera/depth/image";
  std::string camera_info_topic = "/camera/rgb/camera_info";
  std::string imu_topic = "/imu";       ///< "" = none
  std::string sensor = "kinect1";       ///< RgbdFrame::sensor (the VO's camera profile)
  int64_t max_difference_us = 20000;    ///< largest |t_colour - t_depth| of a frame (TUM's 20 ms)
  std::optional<PinholeCamera> intrinsics;  ///< instead of the CameraInfo (size from the images)
  transport::RgbdEncoding encoding;
};

/// The encoded CAMERA_RGBD message of one paired colour (CV_8UC3 R,G,B) and depth (CV_16UC1
/// mm) image.
std::vector<uint8_t> frame_message(int64_t colour_utime, int64_t depth_utime, int64_t seq, const PinholeCamera& camera,
                                   const cv::Mat& rgb, const cv::Mat& depth_mm, const CameraTopicOptions& options);
/// The encoded IMU message of a sample that measures something.
std::vector<uint8_t> imu_message(const ImuReading& reading, int64_t seq);
/// The encoded GROUND_TRUTH message: the camera's pose in the world at `utime`.
std::vector<uint8_t> ground_truth_message(int64_t utime, const Eigen::Isometry3d& T_world_camera);

/// Throws unless the depth images are the colour images' size (kestrel needs depth registered
/// to the colour camera). `source` names the bag (or the bridge).
void check_depth_size(int colour_width, int colour_height, int depth_width, int depth_height,
                      const CameraTopicOptions& options, const std::string& source);
/// Throws unless the CameraInfo's size is the colour images'.
void check_camera_size(const PinholeCamera& camera, int colour_width, int colour_height,
                       const CameraTopicOptions& options, const std::string& source);
/// The camera of --intrinsics at the images' size, checked.
PinholeCamera intrinsics_camera(const PinholeCamera& intrinsics, int width, int height);

/// True if the two give the same calibration (size, K, distortion): a CameraInfo unlike the
/// first is counted.
bool same_camera(const PinholeCamera& a, const PinholeCamera& b);

}  // namespace kestrel::ros1
