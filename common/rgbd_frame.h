#pragma once
// An RGB-D frame in memory, as every library takes it (no LCM here; see
// transport/rgbd_codec.h for the message form).
//
// Invariants once built by a source or decoded: `rgb` is CV_8UC3 in R, G, B channel order
// (as on the wire and from libfreenect; use cv::COLOR_RGB2GRAY), or empty; `depth_mm` is
// CV_16UC1 millimetres with 0 = no reading, registered to `rgb`, or empty; both are
// camera.width x camera.height.

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>

#include "common/camera.h"

namespace kestrel {

/// The sensor models a source names in RgbdFrame::sensor. Consumers key their timing and
/// noise profiles by them (sensors/profiles/<name>.yaml); the name travels with every frame, so a log
/// replays with the model of the camera that recorded it.
namespace sensor_model {
inline constexpr const char* kSimulator = "simulator";  ///< kestrel-sim's rendered camera
inline constexpr const char* kKinect1 = "kinect1";      ///< Kinect v1: libfreenect, TUM freiburg1
}  // namespace sensor_model

struct RgbdFrame {
  int64_t utime = 0;        ///< RGB exposure time, microseconds
  int64_t depth_utime = 0;  ///< depth image time, microseconds
  int64_t seq = 0;          ///< source frame counter
  PinholeCamera camera;
  std::string sensor;       ///< the sensor's model (sensor_model::k*), "" when the source does not know
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  cv::Mat rgb;       ///< CV_8UC3, R,G,B
  cv::Mat depth_mm;  ///< CV_16UC1, millimetres, 0 = none

  /// Throws InputError (naming `what`) unless the invariants above hold.
  void validate(const char* what) const;
};

/// Depth in metres as float (NaN where there is no reading).
cv::Mat depth_to_metres(const cv::Mat& depth_mm);
/// Depth in millimetres from metres; NaN, non-positive and values above 65.535 m give 0.
cv::Mat depth_to_millimetres(const cv::Mat& depth_m);

}  // namespace kestrel
