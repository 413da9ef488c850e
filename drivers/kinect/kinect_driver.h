#pragma once
// The loop of the kestrel-kinect process: frames from FreenectDevice -> FramePairer ->
// DepthRegistration -> CAMERA_RGBD, and the accelerometer -> IMU, into a sink (LCM or a log).
//
// Messages:
//  * CAMERA_RGBD: utime = host clock when the RGB frame arrived, depth_utime = host clock
//    when its depth frame arrived (both later than the exposure by the USB transfer, about
//    one frame period; pairing itself uses the device's clock, frame_pairer.h); seq counts
//    the frames published; rgb = the bytes libfreenect delivered; depth registered to the RGB
//    camera in millimetres; camera = the calibration's RGB camera and T_body_camera.
//  * IMU: polled at accel_rate_hz; utime = host clock of the read; linear_acceleration in the
//    body frame (R_body_camera * accel_to_camera(a)), or the accelerometer's own axes; a
//    reading of exactly zero on all axes (no reading yet) is skipped.
// Health (heartbeat message): the pairing counters, about once a second; DEGRADED once frames
// have been dropped.

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/transport/rgbd_codec.h"
#include "drivers/kinect/depth_registration.h"
#include "drivers/kinect/frame_pairer.h"
#include "drivers/kinect/freenect_device.h"

namespace kestrel::kinect {

struct DriverOptions {
  int64_t max_frames = 0;     ///< stop after this many frames (0 = no limit)
  double duration_s = 0.0;    ///< stop after this many seconds (0 = no limit)
  double accel_rate_hz = 100.0;  ///< accelerometer reads per second (0 = none)
  bool raw_accel_axes = false;
  PairerOptions pairing;
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  transport::RgbdEncoding encoding;
};

struct DriverSink {
  std::function<void(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes)> publish;
  std::function<bool()> stopping = [] { return false; };
  std::function<void()> idle = [] {};
  /// Health report: degraded or not, and a one-line summary of the counters.
  std::function<void(bool degraded, const std::string& summary)> health = [](bool, const std::string&) {};
};

struct DriverResult {
  int64_t frames = 0;
  int64_t imu_samples = 0;
  PairerStats pairing;
  bool limit_reached = false;  ///< max_frames or duration reached
  bool stream_ended = false;   ///< libfreenect failed: device gone, or end of a fakenect dump
  bool stopped = false;        ///< sink.stopping()
};

class KinectDriver {
 public:
  /// Opens Kinect `device_index` (FreenectDevice's exceptions). `registration` must outlive
  /// the driver.
  KinectDriver(const DriverOptions& options, const DepthRegistration& registration, int device_index);

  /// Runs until a limit, the end of the stream or sink.stopping().
  DriverResult run(const DriverSink& sink);

  const FreenectDevice& device() const { return device_; }

 private:
  void publish_frame(const PairedFrame& pair, const DriverSink& sink);
  void publish_accel(int64_t host_utime, const DriverSink& sink);

  DriverOptions options_;
  const DepthRegistration& registration_;
  DeviceClock clock_;
  FramePairer pairer_;
  FreenectDevice device_;  // last: its callbacks use the members above
  DriverResult result_;
  int64_t imu_seq_ = 0;
};

/// One line: "rgb 30, depth 30, paired 30, unpaired rgb 0, ..." for logs and heartbeats.
std::string summary(const PairerStats& s);

}  // namespace kestrel::kinect
