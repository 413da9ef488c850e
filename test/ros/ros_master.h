#pragma once
// A ROS master for a test: Debian's `roscore` started as a child of a LiveSystem, so inside the
// test's private network namespace (loopback only), on a port of that namespace; and the
// environment every ROS program the test starts afterwards reads (ROS_MASTER_URI, ROS_IP,
// ROS_HOME and ROS_LOG_DIR in the test's folder: nothing is written to ~/.ros).

#include <filesystem>
#include <string>

#include "test/support/live_system.h"

namespace kestrel::test {

/// "" if `roscore` and `rosbag` are on the PATH, else what is missing.
std::string missing_ros_programs();

/// Sets the ROS environment (for this process and its children from now on) to a master at
/// 127.0.0.1:`port` with its files under `dir`; returns the master's URI.
std::string use_ros_master(const std::filesystem::path& dir, int port = 11311);

/// Starts roscore (label "roscore") on the master use_ros_master() set, and waits until it
/// answers (a TCP connection to its port; at most `timeout_s`). False (a test failure recorded)
/// if it does not.
bool start_roscore(LiveSystem& system, int port = 11311, double timeout_s = 30.0);

}  // namespace kestrel::test
