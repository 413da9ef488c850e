#pragma once
// The command-line options of a ROS RGB-D camera's topics (camera_source.h), the same for
// kestrel-bag-import and kestrel-ros-bridge: one declaration, so that the two take the same
// names, defaults and checks.

#include <CLI/CLI.hpp>
#include <vector>

#include "drivers/kinect/encoding_options.h"
#include "ros/camera_source.h"

namespace kestrel::ros1 {

class CameraTopicCli {
 public:
  /// Declares --colour-topic, --depth-topic, --camera-info-topic, --imu-topic, --sensor,
  /// --max-dt, --intrinsics and the encoding options, writing into `options` (kept by reference).
  void add_to(CLI::App& app, CameraTopicOptions& options);
  /// Completes `options` from the parsed values (--max-dt, --intrinsics, the encoding); throws
  /// CLI::ValidationError for bad intrinsics.
  void apply(CameraTopicOptions& options) const;
  double max_dt_s() const { return max_dt_s_; }

 private:
  double max_dt_s_ = 0.02;
  std::vector<double> intrinsics_;
  kinect::EncodingOptions encoding_;
};

}  // namespace kestrel::ros1
