// kestrel-ros-bridge's way out, against a real ROS master (roscore in the test's private network
// namespace): kestrel's SLAM_GRAPH, PLAN, MAP_OCTOMAP and STATE sent on LCM come out on ROS as
// bag-export writes the same messages to a bag (the same Exporter), and the graph, plan and map
// are latched: `rosbag record` started after they went out still gets each once.

#include <gtest/gtest.h>

#include <sstream>

#include <lcm/lcm-cpp.hpp>
#include <octomap/OcTree.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/lcm_url.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/process_status_t.hpp"
#include "ros/bag_export.h"
#include "test/ros/bag_export_logs.h"
#include "test/ros/ros_master.h"
#include "test/support/live_system.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;
constexpr int64_t kUtime = 1700000000000000;

struct Outputs {
  kestrel::slam_graph_t graph{};
  kestrel::plan_t plan{};
  kestrel::octomap_t map{};
  kestrel::state_t state{};
};

Outputs outputs() {
  Outputs o;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 2; ++i) {
    kestrel::slam_keyframe_t k{};
    k.id = i;
    k.utime = kUtime - 100000 + i * 50000;
    T.translation() = Eigen::Vector3d(0.5 * i, 0.1, 1.0);
    k.T_world_camera = transport::to_message(T);
    k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
    o.graph.keyframes.push_back(k);
  }
  o.graph.utime = kUtime - 50000;
  o.graph.revision = 3;
  o.graph.num_keyframes = 2;
  o.plan.utime = kUtime;
  o.plan.request_id = 7;
  o.plan.status = kestrel::plan_t::STATUS_OK;
  o.plan.waypoints = {{0, 0, 1, 0}, {2, 1, 1.2, 0.5}};
  o.plan.covariance_trace = {0.01, 0.02};
  o.plan.num_waypoints = 2;
  octomap::OcTree tree(0.1);
  for (int n = 0; n < 5; ++n) {
    tree.updateNode(octomap::point3d(0.35f, 0.15f, 0.05f), true);
    tree.updateNode(octomap::point3d(-0.15f, 0.55f, 0.75f), true);
  }
  std::stringstream s;
  tree.writeBinary(s);
  const std::string bytes = s.str();
  o.map.utime = kUtime;
  o.map.revision = 1;
  o.map.resolution = 0.1;
  o.map.format = kestrel::octomap_t::FORMAT_BINARY;
  o.map.data.assign(bytes.begin(), bytes.end());
  o.map.size = static_cast<int32_t>(o.map.data.size());
  T.translation() = Eigen::Vector3d(1, 2, 3);
  o.state = test::make_state(kUtime + 10000, T, Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d::Zero());
  return o;
}

// The message's bytes with its header's seq zeroed (roscpp numbers what it publishes itself).
template <class M>
std::vector<uint8_t> bytes_of(const rosbag::MessageInstance& m) {
  auto message = m.instantiate<M>();
  if (!message) return {};
  message->header.seq = 0;
  std::vector<uint8_t> out(ros::serialization::serializationLength(*message));
  ros::serialization::OStream stream(out.data(), static_cast<uint32_t>(out.size()));
  ros::serialization::serialize(stream, *message);
  return out;
}

// topic -> each message's bytes, in the bag's order.
template <class M>
std::vector<std::vector<uint8_t>> topic_bytes(const fs::path& bag_path, const std::string& topic) {
  rosbag::Bag bag(bag_path.string(), rosbag::bagmode::Read);
  std::vector<std::vector<uint8_t>> out;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) out.push_back(bytes_of<M>(m));
  return out;
}

TEST(RosBridgeExport, ALateSubscriberGetsTheGraphPlanAndMapAsBagExportWritesThem) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty()) KESTREL_SKIP_ENVIRONMENT() << why;
  if (const std::string why = test::missing_ros_programs(); !why.empty()) KESTREL_SKIP_ENVIRONMENT() << why;
  if (!fs::exists(test::tool("ros-bridge"))) KESTREL_SKIP_ENVIRONMENT() << test::tool("ros-bridge") << " is not built";
  test::TempDir dir;
  const Outputs o = outputs();
  // What bag-export makes of them.
  {
    transport::LogWriter log((dir / "out.lcmlog").string());
    log.write(channel::kSlamGraph, o.graph.utime, transport::encode_message(o.graph));
    log.write(channel::kPlan, o.plan.utime, transport::encode_message(o.plan));
    log.write(channel::kMapOctomap, o.map.utime, transport::encode_message(o.map));
    log.write(channel::kState, o.state.utime, transport::encode_message(o.state));
  }
  {
    rosbag::Bag bag((dir / "want.bag").string(), rosbag::bagmode::Write);
    ros1::export_log((dir / "out.lcmlog").string(), ros1::BagExportOptions{}, bag);
  }

  test::use_ros_master(dir.path());
  test::LiveSystem system(dir.path(), test::LiveSystem::Options{});
  ASSERT_TRUE(test::start_roscore(system));
  system.start("bridge", {test::tool("ros-bridge").string()});
  ASSERT_NE(system.wait_running("ros-bridge"), 0);
  lcm::LCM lcm(transport::kDefaultLcmUrl);
  ASSERT_TRUE(lcm.good());
  const auto send = [&](const char* channel, const auto& m) {
    const auto bytes = transport::encode_message(m);
    lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size()));
  };
  send(channel::kSlamGraph, o.graph);
  send(channel::kPlan, o.plan);
  send(channel::kMapOctomap, o.map);
  send(channel::kState, o.state);
  ASSERT_TRUE(system.wait_for<kestrel::process_status_t>(
      channel::kProcessStatus,
      [](const kestrel::process_status_t& s) { return s.name == "ros-bridge" && s.messages_in >= 4; }, 20.0,
      "the bridge's heartbeat counting the 4 messages"));

  // Recorded after they went out: the latched topics come once each; -l 1 ends the recording.
  const std::vector<std::string> latched = {"/kestrel/slam/keyframes", "/kestrel/plan", "/kestrel/map/occupied",
                                            "/kestrel/map/voxels"};
  std::vector<std::string> record = {"rosbag", "record", "-q", "-l", "1", "-O", (dir / "late.bag").string()};
  record.insert(record.end(), latched.begin(), latched.end());
  ASSERT_EQ(system.run("record", record, 30.0), 0) << system.output("record");
  for (const std::string& topic : {latched[0], latched[1]}) {
    const auto got = topic_bytes<nav_msgs::Path>(dir / "late.bag", topic);
    ASSERT_EQ(got.size(), 1u) << topic;
    EXPECT_GT(got[0].size(), 100u) << topic;  // a Path of two poses, read
    EXPECT_TRUE(got == topic_bytes<nav_msgs::Path>(dir / "want.bag", topic)) << topic;
  }
  const auto cloud = topic_bytes<sensor_msgs::PointCloud2>(dir / "late.bag", latched[2]);
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_GT(cloud[0].size(), 24u);  // two points, read
  EXPECT_TRUE(cloud == topic_bytes<sensor_msgs::PointCloud2>(dir / "want.bag", latched[2]));
  // MarkerArray has no header of its own: compared whole.
  rosbag::Bag late((dir / "late.bag").string(), rosbag::bagmode::Read), want((dir / "want.bag").string(), rosbag::bagmode::Read);
  const auto got_voxels = rosbag::View(late, rosbag::TopicQuery(latched[3])).begin()->instantiate<visualization_msgs::MarkerArray>();
  const auto want_voxels = rosbag::View(want, rosbag::TopicQuery(latched[3])).begin()->instantiate<visualization_msgs::MarkerArray>();
  ASSERT_TRUE(got_voxels && want_voxels);
  ASSERT_EQ(got_voxels->markers.size(), 1u);
  EXPECT_EQ(got_voxels->markers[0].points.size(), 2u);
  EXPECT_TRUE(*got_voxels == *want_voxels);
  EXPECT_EQ(system.stop("bridge"), 0) << system.output("bridge");
}

}  // namespace
}  // namespace kestrel
