#pragma once
// A tiny analytic scene for the mapper's tests: a room (axis-aligned, inward-facing walls) with
// solid axis-aligned boxes, and exact depth images of it from any camera pose. Known geometry
// lets the tests say which cells must be occupied, free or unknown.

#include <Eigen/Geometry>
#include <limits>
#include <optional>
#include <vector>

#include "common/camera.h"
#include "common/rgbd_frame.h"

namespace kestrel::mapper::test {

struct SceneBox {
  Eigen::Vector3d min, max;
};

class Scene {
 public:
  /// A room from `room_min` to `room_max` (walls, floor and ceiling), empty.
  Scene(const Eigen::Vector3d& room_min, const Eigen::Vector3d& room_max)
      : room_{room_min, room_max} {}
  void add_box(const Eigen::Vector3d& min, const Eigen::Vector3d& max) { boxes_.push_back({min, max}); }
  void clear_boxes() { boxes_.clear(); }
  const std::vector<SceneBox>& boxes() const { return boxes_; }
  const SceneBox& room() const { return room_; }

  /// Distance along the unit direction `d` from `o` to the first surface, if any.
  std::optional<double> raycast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double best = std::numeric_limits<double>::infinity();
    // Inside the room: the exit distance through its walls.
    double exit = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (d[a] > 0) exit = std::min(exit, (room_.max[a] - o[a]) / d[a]);
      if (d[a] < 0) exit = std::min(exit, (room_.min[a] - o[a]) / d[a]);
    }
    best = exit;
    for (const SceneBox& b : boxes_) {
      double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
      bool hit = true;
      for (int a = 0; a < 3 && hit; ++a) {
        if (d[a] == 0.0) {
          hit = o[a] >= b.min[a] && o[a] <= b.max[a];
          continue;
        }
        double ta = (b.min[a] - o[a]) / d[a], tb = (b.max[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        hit = t0 <= t1;
      }
      if (hit && t0 > 0.0) best = std::min(best, t0);
    }
    if (!std::isfinite(best)) return std::nullopt;
    return best;
  }

  /// Depth image (millimetres, 0 where nothing is within 65 m) of `camera` at T_world_camera.
  RgbdFrame render(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_camera,
                   int64_t utime) const {
    RgbdFrame f;
    f.utime = f.depth_utime = utime;
    f.camera = camera;
    f.depth_mm = cv::Mat(camera.height, camera.width, CV_16UC1, cv::Scalar(0));
    const Eigen::Matrix3d R = T_world_camera.linear();
    const Eigen::Vector3d o = T_world_camera.translation();
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
        const Eigen::Vector3d d = (R * ray).normalized();
        const auto t = raycast(o, d);
        if (!t) continue;
        const double depth_m = *t / ray.norm();  // along the optical axis
        const double mm = std::round(depth_m * 1000.0);
        if (mm > 0 && mm < 65535) f.depth_mm.at<uint16_t>(v, u) = static_cast<uint16_t>(mm);
      }
    }
    return f;
  }

 private:
  SceneBox room_;
  std::vector<SceneBox> boxes_;
};

/// The mapper tests' room: 5 x 4 x 2.5 m with one table-sized box in it.
inline Scene room_with_a_box() {
  Scene scene(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(3.0, 2.0, 2.5));
  scene.add_box(Eigen::Vector3d(0.8, -0.4, 0.0), Eigen::Vector3d(1.4, 0.3, 0.9));
  return scene;
}

/// Camera at `position` looking at `target` (optical z towards it, image x right, y down with
/// world z up).
inline Eigen::Isometry3d look_at(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - position).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = position;
  return T;
}

/// A Kinect-like camera with `width` x `height` pixels (57 degree horizontal field of view).
inline PinholeCamera kinect_camera(int width = 640, int height = 480) {
  PinholeCamera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 525.0 * width / 640.0;
  c.cx = (width - 1) / 2.0;
  c.cy = (height - 1) / 2.0;
  return c;
}

}  // namespace kestrel::mapper::test
