#pragma once
// ros-bridge: a live process between ROS 1 topics and kestrel's LCM channels, both ways, with
// bag-import's and bag-export's conversions (camera_stream.h, exporter.h):
//  * ROS -> LCM: an RGB-D camera driver's colour, depth, CameraInfo and Imu topics as
//    CAMERA_RGBD and IMU, for vo, slam and mapper, the IMU in the images' axes by the tf tree's
//    mount (camera_stream.h); and, when /tf holds a chain from mocap_world_frame to
//    mocap_frame (a motion capture), GROUND_TRUTH at each transform of its busiest edge, as
//    bag-import writes it (tf_tree.h). The bridge's own /tf (STATE's) is not read back;
//  * LCM -> ROS: STATE, VO_UPDATE, SLAM_GRAPH, PLAN and MAP_OCTOMAP as /kestrel/odom, /tf,
//    /tf_static, /kestrel/vo, /kestrel/slam/keyframes, /kestrel/plan, /kestrel/map/*, for rviz.
//
// One thread does both: the LCM side is a transport::Node (heartbeats, checked decoding,
// counted rejections), the ROS side roscpp's global callback queue, polled in turn, so that
// every handler runs alone and the conversions need no lock.
//
// Errors: no ROS master at start is UnavailableError (exit 4) naming ROS_MASTER_URI; a camera
// stream that can never give a frame (StreamError: an unknown encoding, an unusable
// CameraInfo, a topic published with another message type) ends the bridge with InputError
// naming the topic (exit 3); one bad ROS message
// is dropped, counted and logged (rate-limited); a bad LCM message is counted by the Node.

#include <string>

#include "ros/camera_stream.h"
#include "ros/exporter.h"

namespace kestrel::ros1 {

struct BridgeOptions {
  /// The camera's topics; colour_topic "" = no ROS -> LCM side.
  CameraTopicOptions camera;
  ExportOptions exporter;
  bool to_ros = true;                     ///< the LCM -> ROS side
  /// tf2_msgs/TFMessage on this topic and on it + "_static": the IMU's mount and the ground
  /// truth; "" = no tf read (IMU samples as published, no GROUND_TRUTH).
  std::string tf_topic = "/tf";
  std::string mocap_world_frame = "world";                  ///< GROUND_TRUTH's world (TUM: the mocap's)
  std::string mocap_frame = "openni_rgb_optical_frame";     ///< the frame whose pose is the truth
  std::string ros_name = "kestrel_bridge";  ///< the ROS node's name
  std::string lcm_url;                    ///< "" = $LCM_DEFAULT_URL or kestrel's
  double master_check_period_s = 1.0;     ///< how often the master (and the topics' types) is looked at
};

struct BridgeSummary {
  CameraStreamStats camera;
  ExportStats exported;
  int64_t ros_messages_rejected = 0;
  int64_t tf_transforms = 0;          ///< taken into the tree
  int64_t ground_truth_poses = 0;     ///< GROUND_TRUTH published
  std::string ground_truth = "none";  ///< the chain, or why there is none
};

/// Runs until SIGINT / SIGTERM; the summary of what crossed. Throws UnavailableError without a
/// master, InputError for a camera stream that cannot give frames.
BridgeSummary run_bridge(const BridgeOptions& options);

}  // namespace kestrel::ros1
