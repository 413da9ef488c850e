#include "fuzz/examples.h"

#include <Eigen/Geometry>

#include "common/transport/convert.h"

namespace kestrel::fuzz {

PinholeCamera small_camera(int width, int height) {
  PinholeCamera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 0.8203125 * width;  // 52.5 px at 64 px across
  c.cx = 0.5 * width - 0.5;
  c.cy = 0.5 * height - 0.5;
  return c;
}

kestrel::slam_keyframe_t keyframe(int64_t id, double x_m) {
  kestrel::slam_keyframe_t k{};
  k.id = id;
  k.utime = id;
  k.T_world_camera = transport::to_message(Eigen::Isometry3d(Eigen::Translation3d(x_m, 0.0, 1.0)));
  k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
  return k;
}

}  // namespace kestrel::fuzz
