// kestrel-ros-bridge against a real ROS master (Debian's roscore in the test's private network
// namespace) fed by `rosbag play`: what it does with input it cannot use. No master: exit 4
// naming the master's URI. A depth encoding it does not read, a CameraInfo with a zero focal
// length, a topic of another message type: exit 3, one line naming the topic, and no
// CAMERA_RGBD published.

#include <gtest/gtest.h>

#include <rosbag/bag.h>

#include "common/transport/channels.h"
#include "kestrel/rgbd_frame_t.hpp"
#include "test/ros/bag_writer.h"
#include "test/ros/ros_master.h"
#include "test/support/live_system.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;
constexpr int64_t kT0 = 1305031102000000;  // 2011, as TUM's bags

// Three frames of a 4x3 camera at 30 Hz: depth in `depth_encoding` (16UC1 or one of a byte a
// pixel), CameraInfo with focal lengths `fx`.
void write_bag(const fs::path& path, const std::string& depth_encoding, double fx) {
  rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
  for (int i = 0; i < 3; ++i) {
    const int64_t t = kT0 + i * 33333;
    const auto stamp = ros::Time(static_cast<uint32_t>(t / 1000000), static_cast<uint32_t>(t % 1000000 * 1000));
    bag.write("/camera/rgb/image_color", stamp, test::colour_image(t, 4, 3));
    bag.write("/camera/rgb/camera_info", stamp, test::camera_info(t, 4, 3, fx, fx));
    sensor_msgs::Image depth = test::depth_image_mm(t, 4, 3, 1500);
    if (depth_encoding != depth.encoding) {
      depth.encoding = depth_encoding;  // 8UC1: one byte a pixel
      depth.step = 4;
      depth.data.resize(12);
    }
    bag.write("/camera/depth/image", stamp, depth);
  }
}

test::LiveSystem::Options frames_only() {
  test::LiveSystem::Options o;
  o.channels = {channel::kCameraRgbd};
  return o;
}

struct Refusal {
  int exit_code = -1;
  std::string log;
  size_t frames = 0;
};

// roscore, the bridge, then the bag played into it; the bridge should end by itself.
Refusal bridge_on(const std::string& depth_encoding, double fx) {
  Refusal r;
  test::TempDir dir;
  write_bag(dir / "bad.bag", depth_encoding, fx);
  test::use_ros_master(dir.path());
  test::LiveSystem system(dir.path(), frames_only());
  if (!test::start_roscore(system)) return r;
  system.start("bridge", {test::tool("ros-bridge").string()});
  system.wait_running("ros-bridge");
  system.start("play", {"rosbag", "play", "-q", "--wait-for-subscribers", "-d", "1", (dir / "bad.bag").string()});
  r.exit_code = system.exit_status("bridge", 30.0);
  r.log = system.output("bridge");
  r.frames = system.messages(channel::kCameraRgbd).size();
  return r;
}

#define KESTREL_REQUIRE_ROS()                                                                              \
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())                                  \
    KESTREL_SKIP_ENVIRONMENT() << why;                                                                     \
  if (const std::string why = test::missing_ros_programs(); !why.empty()) KESTREL_SKIP_ENVIRONMENT() << why; \
  if (!fs::exists(test::tool("ros-bridge"))) KESTREL_SKIP_ENVIRONMENT() << test::tool("ros-bridge") << " is not built"

TEST(RosBridge, WithoutAMasterItExitsFourNamingTheMaster) {
  KESTREL_REQUIRE_ROS();
  test::TempDir dir;
  // A port nothing in the test's own namespace listens on.
  test::use_ros_master(dir.path(), 11399);
  test::LiveSystem system(dir.path(), test::LiveSystem::Options{});
  const int status = system.run("bridge", {test::tool("ros-bridge").string()}, 20.0);
  EXPECT_EQ(status, 4);
  EXPECT_NE(system.output("bridge").find("kestrel-ros-bridge: error: no ROS master at http://127.0.0.1:11399"),
            std::string::npos)
      << system.output("bridge");
}

TEST(RosBridge, ADepthEncodingItDoesNotReadEndsItNamingTheTopic) {
  KESTREL_REQUIRE_ROS();
  const Refusal r = bridge_on("8UC1", 500.0);
  EXPECT_EQ(r.exit_code, 3) << r.log;
  EXPECT_NE(r.log.find("kestrel-ros-bridge: error: ros-bridge: /camera/depth/image at 1305031102."), std::string::npos)
      << r.log;
  EXPECT_NE(r.log.find("depth encoding '8UC1' is not one kestrel reads"), std::string::npos) << r.log;
  EXPECT_EQ(r.frames, 0u);
}

TEST(RosBridge, ACameraInfoWithZeroFocalLengthEndsItNamingTheTopic) {
  KESTREL_REQUIRE_ROS();
  const Refusal r = bridge_on("16UC1", 0.0);
  EXPECT_EQ(r.exit_code, 3) << r.log;
  EXPECT_NE(r.log.find("kestrel-ros-bridge: error: ros-bridge: /camera/rgb/camera_info at 1305031102."),
            std::string::npos)
      << r.log;
  EXPECT_NE(r.log.find("focal length fx=0"), std::string::npos) << r.log;
  EXPECT_EQ(r.frames, 0u);
}

TEST(RosBridge, ATopicOfAnotherMessageTypeEndsItNamingTheTopic) {
  KESTREL_REQUIRE_ROS();
  test::TempDir dir;
  {
    // CameraInfo's topic carrying Images: roscpp would refuse each connection in its own log.
    rosbag::Bag bag((dir / "typed.bag").string(), rosbag::bagmode::Write);
    for (int i = 0; i < 30; ++i) {
      const int64_t t = kT0 + i * 33333;
      const auto stamp = ros::Time(static_cast<uint32_t>(t / 1000000), static_cast<uint32_t>(t % 1000000 * 1000));
      bag.write("/camera/rgb/camera_info", stamp, test::colour_image(t, 4, 3));
    }
  }
  test::use_ros_master(dir.path());
  test::LiveSystem system(dir.path(), frames_only());
  ASSERT_TRUE(test::start_roscore(system));
  system.start("bridge", {test::tool("ros-bridge").string()});
  ASSERT_NE(system.wait_running("ros-bridge"), 0);
  // Not --wait-for-subscribers: the bridge's subscription of another type never connects.
  system.start("play", {"rosbag", "play", "-q", "-l", (dir / "typed.bag").string()});
  EXPECT_EQ(system.exit_status("bridge", 30.0), 3) << system.output("bridge");
  EXPECT_NE(system.output("bridge").find("kestrel-ros-bridge: error: ros-bridge: /camera/rgb/camera_info: published as "
                                         "sensor_msgs/Image, not sensor_msgs/CameraInfo"),
            std::string::npos)
      << system.output("bridge");
}

// The control: the same bag with a usable depth encoding and calibration gives its frames.
TEST(RosBridge, TheSameBagWellFormedGivesItsFrames) {
  KESTREL_REQUIRE_ROS();
  test::TempDir dir;
  write_bag(dir / "good.bag", "16UC1", 500.0);
  test::use_ros_master(dir.path());
  test::LiveSystem system(dir.path(), frames_only());
  ASSERT_TRUE(test::start_roscore(system));
  system.start("bridge", {test::tool("ros-bridge").string()});
  ASSERT_NE(system.wait_running("ros-bridge"), 0);
  ASSERT_EQ(system.run("play", {"rosbag", "play", "-q", "--wait-for-subscribers", "-d", "1", (dir / "good.bag").string()}, 30.0), 0);
  // The last colour image is decided by its own depth image (same stamp): all three go out.
  ASSERT_TRUE(system.wait_for<kestrel::rgbd_frame_t>(
      channel::kCameraRgbd, [](const kestrel::rgbd_frame_t& f) { return f.seq == 2; }, 20.0, "the third frame"));
  EXPECT_EQ(system.messages(channel::kCameraRgbd).size(), 3u);
  EXPECT_EQ(system.stop("bridge"), 0) << system.output("bridge");
  EXPECT_NE(system.output("bridge").find("ROS -> LCM: frames 3 (colour images 3, depth images 3"), std::string::npos)
      << system.output("bridge");
}

}  // namespace
}  // namespace kestrel
