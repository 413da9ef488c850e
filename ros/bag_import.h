#pragma once
// A ROS 1 bag of an RGB-D camera (and optionally an IMU and ground truth) as the kestrel
// messages a source publishes: CAMERA_RGBD (rgbd_frame_t), IMU (imu_t) and GROUND_TRUTH
// (ground_truth_t), the same messages and order `kestrel tum-play --log` writes. Reads the
// bag with librosbag (rosbag_storage); knows nothing of the output file: a sink takes each
// encoded message.
//
// What the messages say (conversions: ros_convert.h):
//  * frames: one per colour image that has a depth image within max_difference_us, by header
//    stamp, with the TUM reader's rule and code (drivers/tum/association.h: the nearest depth
//    image; one may serve two colour images); utime = the colour stamp, depth_utime = the depth
//    stamp, seq = the colour image's index among the topic's images in stamp order (as the TUM
//    reader's index in rgb.txt), camera = the first CameraInfo (or `intrinsics`), sensor as
//    given, T_body_camera = identity (body = the camera's optical frame, as for TUM);
//  * IMU: every Imu message that measures something, in the body's axes: rotated from its
//    header's frame into the colour images' by the tf tree's mount when the tree joins the two
//    (the mount at the first sample; no lever-arm term), else as published;
//  * GROUND_TRUTH (FRAME_CAMERA): the pose of `camera_frame` in `world_frame`, either from a
//    geometry_msgs/PoseStamped topic or composed along the tf tree (tf2_msgs/TFMessage on
//    tf_topic and tf_topic + "_static"): one pose per transform of the chain's most frequent
//    edge (the motion capture's), the other edges (rigid mounts) at their latest value.
// Events are sorted by utime; at equal utime IMU before ground truth before a frame (as
// tum::playback_schedule).
//
// The bag is read twice: once for the stamps, calibration, IMU and poses (and to check every
// image, so that a bad one fails before anything is written), then for the pixels of the
// paired images, which are kept only until their frame is written.
//
// Errors (InputError naming the bag and topic): a bag that cannot be opened or read (missing,
// truncated, unindexed), no colour or depth topic, a topic of another message type, an image
// encoding it does not read, a malformed image, an unusable CameraInfo (or none without
// `intrinsics`), images and CameraInfo of different sizes, a non-finite IMU value or pose, no
// colour image with a depth image within the tolerance.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/camera.h"
#include "ros/camera_source.h"

namespace kestrel::ros1 {

/// The camera's topics and what the frames say (camera_source.h; the defaults read TUM RGB-D's
/// own bags), and where the ground truth is.
struct BagImportOptions : CameraTopicOptions {
  std::string tf_topic = "/tf";         ///< "" = none
  std::string pose_topic;               ///< geometry_msgs/PoseStamped ground truth; "" = from tf
  std::string world_frame = "world";    ///< the ground truth's world (TUM: the mocap's)
  std::string camera_frame = "openni_rgb_optical_frame";  ///< the frame whose pose is the truth
};

struct BagImportStats {
  size_t colour_images = 0;     ///< on the colour topic, distinct stamps
  size_t depth_images = 0;
  size_t frames = 0;            ///< written
  size_t unmatched_colour = 0;  ///< no depth image within the tolerance: no frame
  size_t unused_depth = 0;      ///< nearest to no colour image
  size_t shared_depth = 0;      ///< serving two colour images
  size_t repeated_stamps = 0;   ///< images whose stamp repeats an earlier one of their topic: dropped
  size_t camera_infos = 0;
  size_t camera_info_changes = 0;  ///< CameraInfo messages unlike the first (the first is used)
  size_t imu_samples = 0;       ///< written
  size_t imu_empty = 0;         ///< Imu messages that measure nothing (both covariances -1): skipped
  std::string imu_axes;         ///< "as published", or the rotation applied from the IMU's frame
  size_t ground_truth_poses = 0;
  std::string ground_truth;     ///< where the poses came from, or why there are none
  PinholeCamera camera;         ///< the frames' camera
  bool stopped = false;         ///< ended early by ImportSink::stopping (what was sent is a prefix)
};

struct ImportSink {
  /// Each message, in order: channel, utime, encoded bytes.
  std::function<void(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes)> publish;
  /// Polled between messages of the bag; true ends the import early (Ctrl-C).
  std::function<bool()> stopping = [] { return false; };
};

BagImportStats import_bag(const std::string& bag_path, const BagImportOptions& options, const ImportSink& sink);

}  // namespace kestrel::ros1
