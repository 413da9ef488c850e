#pragma once
// kestrel's own output as ROS 1 messages in a bag (the other way from bag_import.h): a kestrel
// LCM log read with transport::LogReader, each message converted by the Exporter (exporter.h,
// the same conversions ros-bridge publishes live) and written with librosbag's own writer. See
// ros/README.md, "bag-export", for the topics and frames.

#include <functional>
#include <string>

#include "ros/exporter.h"

namespace rosbag {
class Bag;
}

namespace kestrel::ros1 {

using BagExportOptions = ExportOptions;
using BagExportStats = ExportStats;

/// Writes the log's messages to `bag` (open for writing). Throws InputError (naming the log)
/// for a log that cannot be read, is damaged (truncated, corrupt regions), holds a message that
/// does not decode, or holds none of the channels exported (STATE, VO_UPDATE, GROUND_TRUTH,
/// SLAM_GRAPH, PLAN, MAP_OCTOMAP; CAMERA_RGBD with `images`).
BagExportStats export_log(const std::string& log_path, const BagExportOptions& options, rosbag::Bag& bag,
                          const std::function<bool()>& stopping = {});

}  // namespace kestrel::ros1
