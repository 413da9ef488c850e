#include "ros/camera_source.h"

#include "common/error.h"
#include "common/rgbd_frame.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"

namespace kestrel::ros1 {

std::vector<uint8_t> frame_message(int64_t colour_utime, int64_t depth_utime, int64_t seq, const PinholeCamera& camera,
                                   const cv::Mat& rgb, const cv::Mat& depth_mm, const CameraTopicOptions& options) {
  RgbdFrame f;
  f.utime = colour_utime;
  f.depth_utime = depth_utime;
  f.seq = seq;
  f.camera = camera;
  f.sensor = options.sensor;
  f.rgb = rgb;
  f.depth_mm = depth_mm;
  return transport::encode_message(transport::encode_rgbd(f, options.encoding));
}

std::vector<uint8_t> imu_message(const ImuReading& r, int64_t seq) {
  kestrel::imu_t m{};
  m.utime = r.utime;
  m.seq = seq;
  m.fields = static_cast<int8_t>((r.has_gyro ? kestrel::imu_t::HAS_GYRO : 0) | (r.has_accel ? kestrel::imu_t::HAS_ACCEL : 0));
  for (int k = 0; k < 3; ++k) {
    m.angular_velocity[k] = r.angular_velocity[k];
    m.linear_acceleration[k] = r.linear_acceleration[k];
  }
  return transport::encode_message(m);
}

std::vector<uint8_t> ground_truth_message(int64_t utime, const Eigen::Isometry3d& T_world_camera) {
  kestrel::ground_truth_t m{};
  m.utime = utime;
  // The import's body is the camera (T_body_camera = identity), so the camera's pose is also
  // the body's; FRAME_CAMERA says which it is, as TUM's truth does.
  m.frame = kestrel::ground_truth_t::FRAME_CAMERA;
  m.T_world_frame = transport::to_message(T_world_camera);
  m.fields = 0;
  return transport::encode_message(m);
}

void check_depth_size(int colour_w, int colour_h, int depth_w, int depth_h, const CameraTopicOptions& o,
                      const std::string& source) {
  if (colour_w != depth_w || colour_h != depth_h)
    throw InputError(source + ": " + o.depth_topic + ": depth images are " + std::to_string(depth_w) + "x" +
                     std::to_string(depth_h) + ", the colour images on " + o.colour_topic + " " +
                     std::to_string(colour_w) + "x" + std::to_string(colour_h) +
                     " (kestrel needs depth registered to the colour camera)");
}

void check_camera_size(const PinholeCamera& camera, int colour_w, int colour_h, const CameraTopicOptions& o,
                       const std::string& source) {
  if (camera.width != colour_w || camera.height != colour_h)
    throw InputError(source + ": " + o.camera_info_topic + ": CameraInfo is " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + ", the images on " + o.colour_topic + " " +
                     std::to_string(colour_w) + "x" + std::to_string(colour_h));
}

PinholeCamera intrinsics_camera(const PinholeCamera& intrinsics, int width, int height) {
  PinholeCamera c = intrinsics;
  c.width = width;
  c.height = height;
  c.validate("--intrinsics");
  return c;
}

bool same_camera(const PinholeCamera& a, const PinholeCamera& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx &&
         a.cy == b.cy && a.distortion == b.distortion;
}

}  // namespace kestrel::ros1
