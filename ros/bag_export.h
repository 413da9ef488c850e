#pragma once
// kestrel's own output as ROS 1 messages in a bag (the other way from bag_import.h): a kestrel
// LCM log read with transport::LogReader, written with librosbag's own writer. See
// ros/README.md, "bag-export", for the topics and frames.
//
// Frames (REP-105 names, configurable): `world_frame` (default "map") is the estimator's world,
// the frame STATE's T_world_body is in (SLAM's world once the estimator took it); `body_frame`
// ("base_link") the vehicle body; `camera_frame` ("camera") the RGB camera's optical frame. The
// map -> odom -> base_link split of REP-105 waits for an odometry frame of kestrel's own
// (issue 39 item 1): today /tf holds map -> base_link directly.

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include <nav_msgs/Odometry.h>

#include "kestrel/state_t.hpp"

namespace rosbag {
class Bag;
}

namespace kestrel::ros1 {

struct BagExportOptions {
  std::string world_frame = "map";
  std::string body_frame = "base_link";
  std::string camera_frame = "camera";
  /// VO_UPDATE's chained poses are the camera's in the VO's own world, the camera frame of the
  /// VO's first frame: /kestrel/vo's header.frame_id (not joined to the others by tf).
  std::string vo_frame = "vo";
  /// GROUND_TRUTH's world (the sim's, the motion capture's): /kestrel/ground_truth's frame_id.
  /// The estimator's world only where the run starts at the truth's pose (the sim does).
  std::string truth_frame = "map";
  /// CAMERA_RGBD as sensor_msgs/Image (colour rgb8, depth 16UC1 mm) and CameraInfo (big).
  bool images = false;
};

struct BagExportStats {
  std::map<std::string, int64_t> messages;  ///< per topic, messages written
  int64_t log_events = 0;                   ///< events read from the log
  bool stopped = false;                     ///< `stopping` said so before the end
  int64_t vo_without_estimate = 0;          ///< VO_UPDATEs the chain gives no pose (VoChain)
  int64_t vo_out_of_order = 0;              ///< VO_UPDATEs not after the previous one, skipped
  std::string truth_of;                     ///< "body", "camera" or "" (no GROUND_TRUTH)
  int64_t total() const {
    int64_t n = 0;
    for (const auto& [topic, count] : messages) n += count;
    return n;
  }
};

/// STATE as nav_msgs/Odometry: the pose of `body_frame` in `world_frame`, the twist in
/// `body_frame`'s axes, both covariances from state_t's error state (bag_export.cpp says which
/// blocks go where). Throws InputError naming `what` for a non-finite pose.
nav_msgs::Odometry odometry_from_state(const kestrel::state_t& state, const std::string& world_frame,
                                       const std::string& body_frame, const std::string& what);

/// Writes the log's messages to `bag` (open for writing). Throws InputError (naming the log)
/// for a log that cannot be read, is damaged (truncated, corrupt regions), holds a message that
/// does not decode, or holds none of the channels exported (STATE, VO_UPDATE, GROUND_TRUTH,
/// SLAM_GRAPH, PLAN; CAMERA_RGBD with `images`).
BagExportStats export_log(const std::string& log_path, const BagExportOptions& options, rosbag::Bag& bag,
                          const std::function<bool()>& stopping = {});

}  // namespace kestrel::ros1
