// kestrel-ros-bridge: a live process between ROS 1 topics and kestrel's LCM channels, both ways
// (ros/bridge.h): a ROS RGB-D camera driver feeds vo, slam and mapper; STATE, VO, the SLAM
// graph, plans and the map appear on ROS topics for rviz. Needs a running ROS master
// (`roscore`): without one it says so and exits 4. See ros/README.md.

#include <iostream>

#include "common/cli.h"
#include "common/error.h"
#include "ros/bridge.h"
#include "ros/camera_cli.h"

namespace {

using namespace kestrel;

struct Options {
  ros1::BridgeOptions bridge;
  ros1::CameraTopicCli camera;
};

int run(Options& o) {
  o.camera.apply(o.bridge.camera);
  const ros1::BridgeSummary s = ros1::run_bridge(o.bridge);
  const ros1::CameraStreamStats& c = s.camera;
  std::cout << "ROS -> LCM: frames " << c.frames << " (colour images " << c.colour_images << ", depth images "
            << c.depth_images << ", colour without depth within the tolerance " << c.unmatched_colour
            << ", dropped before a CameraInfo " << c.without_camera << ", out of order " << c.out_of_order
            << "), IMU samples " << c.imu_samples << " (axes " << c.imu_axes << "; dropped before the first colour image "
            << c.imu_dropped_awaiting_axes << "), CameraInfo messages "
            << c.camera_infos << " (" << c.camera_info_changes << " unlike the first), bad messages dropped "
            << s.ros_messages_rejected << "\n";
  std::cout << "ground truth: " << s.ground_truth_poses << " poses (" << s.ground_truth << "); tf transforms "
            << s.tf_transforms << "\n";
  std::cout << "LCM -> ROS:";
  for (const auto& [topic, n] : s.exported.messages) std::cout << " " << topic << " " << n << ";";
  std::cout << " messages " << s.exported.total() << "\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("ros-bridge",
                        "Bridge ROS 1 topics and kestrel's LCM channels live: an RGB-D camera in, STATE, VO, "
                        "SLAM, plans and the map out");
  Options o;
  auto& b = o.bridge;
  auto& e = b.exporter;
  o.camera.add_to(app, b.camera);
  app.add_flag("!--no-export", b.to_ros, "Do not publish kestrel's output on ROS topics");
  app.add_option("--tf-topic", b.tf_topic,
                 "tf2_msgs/TFMessage (and <topic>_static): the IMU's mount, the ground truth; \"\" = none")
      ->capture_default_str();
  app.add_option("--mocap-world-frame", b.mocap_world_frame, "Ground truth: the world frame (tf)")->capture_default_str();
  app.add_option("--mocap-frame", b.mocap_frame, "Ground truth: the frame whose pose is the truth (tf)")
      ->capture_default_str();
  app.add_option("--world-frame", e.world_frame, "tf frame of the estimator's world (STATE's)")->capture_default_str();
  app.add_option("--body-frame", e.body_frame, "tf frame of the vehicle body")->capture_default_str();
  app.add_option("--camera-frame", e.camera_frame, "tf frame of the RGB camera (optical)")->capture_default_str();
  app.add_option("--vo-frame", e.vo_frame, "frame_id of /kestrel/vo (the VO's own world: its first camera frame)")
      ->capture_default_str();
  app.add_flag("--map-free", e.map_free, "Also the map's free cells, as /kestrel/map/free");
  app.add_option("--ros-name", b.ros_name, "The ROS node's name")->capture_default_str();
  app.add_option("--lcm-url", b.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  return app.run(argc, argv, [&] { return run(o); });
}
