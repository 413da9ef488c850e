#pragma once
// Writes a simulated flight as a TUM RGB-D sequence folder, so that any RGB-D system (and
// kestrel's own TUM player and evaluation) runs on exactly the same data:
//
//   rgb/<t>.png, depth/<t>.png   8-bit RGB; 16-bit depth, 5000 units per metre (0 = none)
//   rgb.txt, depth.txt           "timestamp filename", three '#' header lines, as TUM
//   groundtruth.txt              "timestamp tx ty tz qx qy qz qw": the RGB optical frame in
//                                the world, at every IMU and frame time stamp
//   accelerometer.txt            "timestamp ax ay az": specific force at the body origin on
//                                the Kinect accelerometer's axes (x left, y up, z forward of the
//                                camera), the form of TUM's own file
//   imu.txt                      "timestamp gx gy gz ax ay az": the IMU, body frame (x forward,
//                                y left, z up), rad/s and m/s^2
//   imu_biases.txt               "timestamp bgx bgy bgz bax bay baz": the true biases
//   camera.txt                   "fx fy cx cy width height", T_body_camera (x y z qx qy qz qw)
//                                and "sensor simulator" (drivers/tum/tum_lists.h reads it)
// Time stamps are seconds with six decimals (common/time.h). Every failure to write is an
// InputError naming the file.

#include <Eigen/Geometry>
#include <cstdint>
#include <fstream>
#include <string>

#include "common/rgbd_frame.h"
#include "drivers/sim/imu.h"

namespace kestrel::sim {

class TumFolderWriter {
 public:
  /// Creates `folder` (and rgb/, depth/) and the list files with their headers.
  TumFolderWriter(const std::string& folder, const PinholeCamera& camera, const Eigen::Isometry3d& T_body_camera);

  void add_frame(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera);
  void add_imu(int64_t utime, const ImuSample& sample, const Eigen::Isometry3d& T_world_camera);
  /// Flushes and closes every list; throws InputError on a write error.
  void close();

  int64_t frames() const { return frames_; }

 private:
  void add_pose(int64_t utime, const Eigen::Isometry3d& T_world_camera);
  // in-place: a recording, its lists appended a line per sample
  std::ofstream open(const std::string& name, const char* header);

  std::string folder_;
  Eigen::Isometry3d T_body_camera_;
  // in-place: a recording, its lists appended a line per sample
  std::ofstream rgb_, depth_, ground_truth_, accelerometer_, imu_, biases_;
  int64_t last_pose_utime_ = -1;
  int64_t frames_ = 0;
};

}  // namespace kestrel::sim
