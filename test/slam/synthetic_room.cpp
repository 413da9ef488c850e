#include "test/slam/synthetic_room.h"

#include "common/numbers.h"

#include <cmath>
#include <cstdint>
#include <limits>

namespace kestrel::slam::test {
namespace {

// A well-mixed 32-bit hash of a cell (splitmix-style), so that neighbouring cells are unrelated.
uint32_t hash(uint32_t seed, int face, int64_t i, int64_t j, int scale) {
  uint64_t h = seed * 0x9E3779B97F4A7C15ull;
  for (const uint64_t v : {static_cast<uint64_t>(face), static_cast<uint64_t>(i),
                           static_cast<uint64_t>(j), static_cast<uint64_t>(scale)}) {
    h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
    h ^= h >> 31;
  }
  return static_cast<uint32_t>(h);
}

}  // namespace

SyntheticRoom::SyntheticRoom(unsigned seed, double half_x_m, double half_y_m, double height_m)
    : seed_(seed), lo_(-half_x_m, -half_y_m, 0.0), hi_(half_x_m, half_y_m, height_m) {}

double SyntheticRoom::texture(int face, double s, double t) const {
  // Cells of 0.36, 0.12 and 0.04 m: coarse ones for distant views, fine ones for corners.
  static constexpr double kCell[3] = {0.36, 0.12, 0.04};
  static constexpr double kWeight[3] = {0.5, 0.3, 0.2};
  double grey = 0.0;
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<int64_t>(std::floor(s / kCell[k]));
    const auto j = static_cast<int64_t>(std::floor(t / kCell[k]));
    grey += kWeight[k] * static_cast<double>(hash(seed_, face, i, j, k) & 0xFF);
  }
  return grey;
}

RgbdFrame SyntheticRoom::render(const Eigen::Isometry3d& T_world_camera, const PinholeCamera& camera,
                                int64_t utime) const {
  RgbdFrame frame;
  frame.utime = frame.depth_utime = utime;
  frame.camera = camera;
  frame.rgb = cv::Mat(camera.height, camera.width, CV_8UC3);
  frame.depth_mm = cv::Mat(camera.height, camera.width, CV_16UC1, cv::Scalar(0));
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d o = T_world_camera.translation();
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      // Ray with unit optical-axis component: its parameter at a hit is the depth z.
      const Eigen::Vector3d d = R * Eigen::Vector3d((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      double z = std::numeric_limits<double>::infinity();
      int axis = -1;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12) continue;
        const double t = ((d[a] > 0 ? hi_[a] : lo_[a]) - o[a]) / d[a];
        if (t > 0 && t < z) {
          z = t;
          axis = a;
        }
      }
      double grey = 0.0;
      if (axis >= 0) {
        const Eigen::Vector3d p = o + z * d;
        const int face = 2 * axis + (d[axis] > 0 ? 1 : 0);
        grey = texture(face, p[(axis + 1) % 3], p[(axis + 2) % 3]);
        frame.depth_mm.at<uint16_t>(v, u) = static_cast<uint16_t>(std::lround(z * 1000.0));
      }
      const auto g = static_cast<uint8_t>(std::lround(std::min(grey, 255.0)));
      frame.rgb.at<cv::Vec3b>(v, u) = cv::Vec3b(g, g, g);
    }
  }
  return frame;
}

Eigen::Isometry3d level_camera(const Eigen::Vector3d& position, double yaw_rad) {
  // Optical z along the heading, optical x to its right, optical y down.
  const Eigen::Vector3d forward(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = down.cross(forward);
  T.linear().col(1) = down;
  T.linear().col(2) = forward;
  T.translation() = position;
  return T;
}

std::vector<Eigen::Isometry3d> circle_path(int n, double radius_m, double turns) {
  std::vector<Eigen::Isometry3d> path;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * kPi * turns * k / std::max(n - 1, 1);
    path.push_back(level_camera(Eigen::Vector3d(radius_m * std::cos(a), radius_m * std::sin(a), 1.0), a));
  }
  return path;
}

std::vector<Eigen::Isometry3d> straight_path(int n, double length_m) {
  std::vector<Eigen::Isometry3d> path;
  for (int k = 0; k < n; ++k) {
    const double x = -0.5 * length_m + length_m * k / std::max(n - 1, 1);
    path.push_back(level_camera(Eigen::Vector3d(x, 0.0, 1.0), -kPi / 2));
  }
  return path;
}

PinholeCamera test_camera() {
  PinholeCamera c;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 0.5 * c.width / std::tan(kPi / 6);
  c.cx = 159.5;
  c.cy = 119.5;
  return c;
}

}  // namespace kestrel::slam::test
