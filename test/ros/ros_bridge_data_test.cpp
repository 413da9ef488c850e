// kestrel-ros-bridge with the real components: Debian's roscore in the test's private network
// namespace, the first 2 s of fr1_xyz written as a bag by librosbag (as TUM publishes its bags)
// and played by `rosbag play` into the bridge, the VO and the estimator on the bridge's LCM
// side, and this test as a ROS node on /kestrel/odom. Known answers:
//  * every CAMERA_RGBD, IMU and GROUND_TRUTH message the bridge publishes is bag-import's of
//    the same bag, byte for byte and in the same order (same conversions, same pairing, the
//    mocap's chain on /tf composed by the same tree);
//  * the estimator's STATE, one per frame, and /kestrel/odom on ROS carry the same poses: one
//    Odometry per STATE, same stamp, position and rotation to 1e-9.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <mutex>

#include <nav_msgs/Odometry.h>
#include <sensor_msgs/Image.h>
#include <ros/ros.h>

#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/state_t.hpp"
#include "ros/ros_convert.h"
#include "test/ros/bag_writer.h"
#include "test/ros/ros_master.h"
#include "test/support/live_system.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;

std::vector<std::vector<uint8_t>> payloads(const std::vector<test::ReceivedMessage>& messages) {
  std::vector<std::vector<uint8_t>> out;
  for (const auto& m : messages) out.push_back(m.data);
  return out;
}

std::vector<std::vector<uint8_t>> log_payloads(const fs::path& log, const std::string& channel) {
  std::vector<std::vector<uint8_t>> out;
  transport::LogReader reader(log.string());
  while (auto e = reader.next())
    if (e->channel == channel) out.push_back(e->data);
  return out;
}

TEST(RosBridgeData, Fr1XyzPlayedIntoTheBridgeGivesImportsFramesAndTheStateOnBothSides) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty()) KESTREL_SKIP_ENVIRONMENT() << why;
  if (const std::string why = test::missing_ros_programs(); !why.empty()) KESTREL_SKIP_ENVIRONMENT() << why;
  for (const char* t : {"ros-bridge", "bag-import", "vo", "estimator"})
    if (!fs::exists(test::tool(t))) KESTREL_SKIP_ENVIRONMENT() << test::tool(t) << " is not built";
  KESTREL_REQUIRE_TUM(folder, "rgbd_dataset_freiburg1_xyz");
  test::TempDir dir;
  const fs::path bag = dir / "xyz.bag";
  const test::TumBagContents written = test::write_tum_bag(folder.string(), bag.string(), {60, false});
  ASSERT_EQ(written.colour, 60u);
  // Depth as zstd on both ways in: the option is the same one, and the frames half as big on LCM.
  const std::vector<std::string> encoding = {"--depth-encoding", "zstd"};
  std::vector<std::string> import = {test::tool("bag-import").string(), bag.string(), "--log", (dir / "xyz.lcmlog").string()};
  import.insert(import.end(), encoding.begin(), encoding.end());
  const auto imported = test::run(import, 60.0);
  ASSERT_EQ(imported.exit_code, 0) << imported.err;
  const auto want_frames = log_payloads(dir / "xyz.lcmlog", channel::kCameraRgbd);
  const auto want_imu = log_payloads(dir / "xyz.lcmlog", channel::kImu);
  const auto want_truth = log_payloads(dir / "xyz.lcmlog", channel::kGroundTruth);
  ASSERT_GE(want_truth.size(), 200u);
  ASSERT_GE(want_frames.size(), 58u);

  test::use_ros_master(dir.path());
  test::LiveSystem::Options heard;
  heard.channels = {channel::kCameraRgbd, channel::kImu, channel::kState, channel::kGroundTruth};
  test::LiveSystem system(dir.path(), heard);
  ASSERT_TRUE(test::start_roscore(system));
  std::vector<std::string> bridge = {test::tool("ros-bridge").string()};
  bridge.insert(bridge.end(), encoding.begin(), encoding.end());
  system.start("bridge", bridge);
  system.start("vo", {test::tool("vo").string(), "-q"});
  system.start("estimator", {test::tool("estimator").string(), "-q"});
  for (const char* p : {"ros-bridge", "vo", "estimator"}) ASSERT_NE(system.wait_running(p), 0) << p;

  // This test as a ROS node: /kestrel/odom, connected before the bag plays.
  ros::init(ros::M_string{}, "kestrel_bridge_test", ros::init_options::NoSigintHandler | ros::init_options::AnonymousName);
  std::mutex mutex;
  std::vector<nav_msgs::Odometry> odom;
  std::vector<int64_t> odom_received_us;  // wall clock, as LiveSystem stamps what it hears
  {
    ros::NodeHandle nh;
    ros::Subscriber sub = nh.subscribe<nav_msgs::Odometry>("/kestrel/odom", 10000, [&](const nav_msgs::Odometry::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex);
      odom.push_back(*m);
      odom_received_us.push_back(std::chrono::duration_cast<std::chrono::microseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
    });
    // The colour images too, when this node hears them: a frame's latency through the bridge
    // is from its colour image on ROS to its CAMERA_RGBD on LCM (pairing's wait included).
    std::map<int64_t, int64_t> colour_received_us;  // by stamp
    ros::Subscriber colour = nh.subscribe<sensor_msgs::Image>("/camera/rgb/image_color", 100, [&](const sensor_msgs::Image::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex);
      colour_received_us[ros1::to_utime(m->header.stamp)] = std::chrono::duration_cast<std::chrono::microseconds>(
                                                                std::chrono::system_clock::now().time_since_epoch())
                                                                .count();
    });
    ros::AsyncSpinner spinner(1);
    spinner.start();
    for (int i = 0; i < 400 && sub.getNumPublishers() == 0; ++i) ros::WallDuration(0.05).sleep();
    ASSERT_EQ(sub.getNumPublishers(), 1u) << "/kestrel/odom not connected to the bridge";

    // The camera's topics and the mocap's /tf (--wait-for-subscribers waits on each).
    ASSERT_EQ(system.run("play", {"rosbag", "play", "-q", "--wait-for-subscribers", "-d", "1", bag.string(), "--topics",
                                  "/camera/rgb/image_color", "/camera/depth/image", "/camera/rgb/camera_info", "/imu",
                                  "/tf"},
                         40.0),
              0)
        << system.output("play");
    // The last frame can be decided only by a depth image at or after it: the bag's last.
    const int64_t last_frame_utime = transport::decode_message<kestrel::rgbd_frame_t>(
                                         want_frames.back().data(), want_frames.back().size(), "frame")
                                         .utime;
    ASSERT_TRUE(system.wait_for<kestrel::state_t>(
        channel::kState, [&](const kestrel::state_t& s) { return s.utime >= last_frame_utime; }, 30.0,
        "STATE at the last frame"));
    const size_t states = system.messages(channel::kState).size();
    for (int i = 0; i < 200; ++i) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (odom.size() >= states) break;
      }
      ros::WallDuration(0.025).sleep();
    }
    spinner.stop();
    std::vector<int64_t> frame_latency_us;
    for (const auto& f : system.messages(channel::kCameraRgbd)) {
      const auto frame = transport::decode_message<kestrel::rgbd_frame_t>(f.data.data(), f.data.size(), "frame");
      if (const auto it = colour_received_us.find(frame.utime); it != colour_received_us.end())
        frame_latency_us.push_back(f.received_utime - it->second);
    }
    std::sort(frame_latency_us.begin(), frame_latency_us.end());
    if (!frame_latency_us.empty())
      std::cout << "colour image on ROS -> CAMERA_RGBD on LCM: median " << frame_latency_us[frame_latency_us.size() / 2]
                << " us, max " << frame_latency_us.back() << " us over " << frame_latency_us.size() << "\n";
  }
  ros::shutdown();

  // The bridge's frames and IMU samples are bag-import's, byte for byte.
  EXPECT_TRUE(payloads(system.messages(channel::kCameraRgbd)) == want_frames)
      << system.messages(channel::kCameraRgbd).size() << " frames from the bridge, " << want_frames.size()
      << " imported\n" << system.output("bridge");
  EXPECT_TRUE(payloads(system.messages(channel::kImu)) == want_imu)
      << system.messages(channel::kImu).size() << " IMU from the bridge, " << want_imu.size() << " imported";
  EXPECT_TRUE(payloads(system.messages(channel::kGroundTruth)) == want_truth)
      << system.messages(channel::kGroundTruth).size() << " truths from the bridge, " << want_truth.size() << " imported";

  // One STATE per frame (the visual-only estimator: the accelerometer alone), and each is an
  // Odometry on /kestrel/odom.
  const auto state_messages = system.messages(channel::kState);
  EXPECT_GE(state_messages.size(), want_frames.size() - 2);
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_EQ(odom.size(), state_messages.size());
  for (size_t i = 0; i < odom.size(); ++i) {
    const auto s = transport::decode_message<kestrel::state_t>(state_messages[i].data.data(), state_messages[i].data.size(), "STATE");
    const nav_msgs::Odometry& o = odom[i];
    ASSERT_EQ(o.header.stamp, ros1::to_ros_time(s.utime)) << i;
    EXPECT_EQ(o.header.frame_id, "map");
    EXPECT_EQ(o.child_frame_id, "base_link");
    EXPECT_NEAR(o.pose.pose.position.x, s.T_world_body.position[0], 1e-9);
    EXPECT_NEAR(o.pose.pose.position.y, s.T_world_body.position[1], 1e-9);
    EXPECT_NEAR(o.pose.pose.position.z, s.T_world_body.position[2], 1e-9);
    const auto& q = o.pose.pose.orientation;
    const double dot = q.w * s.T_world_body.orientation[0] + q.x * s.T_world_body.orientation[1] +
                       q.y * s.T_world_body.orientation[2] + q.z * s.T_world_body.orientation[3];
    EXPECT_NEAR(std::abs(dot), 1.0, 1e-9);
  }
  // The camera moved: fr1_xyz's first 2 s sweep tens of centimetres.
  const auto first = transport::decode_message<kestrel::state_t>(state_messages.front().data.data(), state_messages.front().data.size(), "STATE");
  const auto last = transport::decode_message<kestrel::state_t>(state_messages.back().data.data(), state_messages.back().data.size(), "STATE");
  const Eigen::Vector3d moved(last.T_world_body.position[0] - first.T_world_body.position[0],
                              last.T_world_body.position[1] - first.T_world_body.position[1],
                              last.T_world_body.position[2] - first.T_world_body.position[2]);
  EXPECT_GT(moved.norm(), 0.02);
  // For the record, not a check: how long a STATE took from LCM to /kestrel/odom here (both
  // heard by this process, on one clock; the bridge and this test share 2 cores with the rest).
  std::vector<int64_t> latency_us;
  for (size_t i = 0; i < odom.size(); ++i) latency_us.push_back(odom_received_us[i] - state_messages[i].received_utime);
  std::sort(latency_us.begin(), latency_us.end());
  std::cout << "STATE -> /kestrel/odom: median " << latency_us[latency_us.size() / 2] << " us, max " << latency_us.back()
            << " us over " << latency_us.size() << "\n";
  EXPECT_EQ(system.stop("bridge"), 0) << system.output("bridge");
  std::cout << system.output("bridge");
}

}  // namespace
}  // namespace kestrel
