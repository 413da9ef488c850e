#include "ros/camera_cli.h"

#include <cmath>

#include "common/cli.h"

namespace kestrel::ros1 {

void CameraTopicCli::add_to(CLI::App& app, CameraTopicOptions& o) {
  app.add_option("--colour-topic", o.colour_topic, "sensor_msgs/Image, rgb8, bgr8 or mono8")->capture_default_str();
  app.add_option("--depth-topic", o.depth_topic, "sensor_msgs/Image registered to colour, 16UC1 mm or 32FC1 m")
      ->capture_default_str();
  app.add_option("--camera-info-topic", o.camera_info_topic, "sensor_msgs/CameraInfo of the colour camera")
      ->capture_default_str();
  app.add_option("--imu-topic", o.imu_topic, "sensor_msgs/Imu (\"\" or an absent topic: no IMU)")->capture_default_str();
  app.add_option("--sensor", o.sensor, "Sensor model the frames name (kinect1, simulator, \"\" = unknown)")
      ->capture_default_str();
  app.add_option("--max-dt", max_dt_s_, "Largest colour-depth time difference of a frame, seconds")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--intrinsics", intrinsics_, "fx,fy,cx,cy instead of the CameraInfo (no distortion)")
      ->expected(4)
      ->delimiter(',');
  encoding_.add_to(app);
}

void CameraTopicCli::apply(CameraTopicOptions& o) const {
  o.max_difference_us = std::llround(max_dt_s_ * 1e6);
  o.intrinsics = cli::intrinsics_option(intrinsics_);
  o.encoding = encoding_.encoding();
}

}  // namespace kestrel::ros1
