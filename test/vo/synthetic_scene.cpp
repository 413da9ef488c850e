#include "test/vo/synthetic_scene.h"

#include <cmath>
#include <limits>

namespace kestrel::vo::test {
namespace {

uint32_t hash(uint32_t a, uint32_t b, uint32_t c) {
  uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 0x165667B1u) * 0xC2B2AE3Du;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  h *= 0x297A2D39u;
  h ^= h >> 15;
  return h;
}

}  // namespace

PinholeCamera test_camera() {
  PinholeCamera c;
  c.width = 640;
  c.height = 480;
  c.fx = 517.3;
  c.fy = 516.5;
  c.cx = 318.6;
  c.cy = 255.3;
  return c;
}

SyntheticScene::SyntheticScene(unsigned seed, double depth_m) {
  const double w = 2.0, h = 1.5;
  auto add = [&](Eigen::Vector3d origin, Eigen::Vector3d u, Eigen::Vector3d v, double width,
                 double height) {
    Plane p;
    p.origin = origin;
    p.u = u.normalized();
    p.v = v.normalized();
    p.normal = p.u.cross(p.v);
    p.width = width;
    p.height = height;
    p.seed = seed * 131u + static_cast<unsigned>(planes_.size());
    planes_.push_back(p);
  };
  // Back wall, floor (y down is +y in the optical frame of a level camera), ceiling, sides.
  add({-w, -h, depth_m}, {1, 0, 0}, {0, 1, 0}, 2 * w, 2 * h);
  add({-w, h, -1.0}, {1, 0, 0}, {0, 0, 1}, 2 * w, depth_m + 1.0);
  add({-w, -h, -1.0}, {1, 0, 0}, {0, 0, 1}, 2 * w, depth_m + 1.0);
  add({-w, -h, -1.0}, {0, 1, 0}, {0, 0, 1}, 2 * h, depth_m + 1.0);
  add({w, -h, -1.0}, {0, 1, 0}, {0, 0, 1}, 2 * h, depth_m + 1.0);
  // A block standing in the room, for depth discontinuities and parallax.
  const double bz = 0.55 * depth_m;
  add({-0.9, 0.1, bz}, {1, 0, 0}, {0, 1, 0}, 0.7, h - 0.1);
  add({-0.2, 0.1, bz}, {0, 0, 1}, {0, 1, 0}, 0.5, h - 0.1);
}

double SyntheticScene::noise(unsigned seed, double s, double t, double cell) const {
  const double x = s / cell, y = t / cell;
  const double fx = std::floor(x), fy = std::floor(y);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const double ax = x - fx, ay = y - fy;
  auto value = [&](int i, int j) {
    return double(hash(seed, static_cast<uint32_t>(i), static_cast<uint32_t>(j)) & 0xFFFFu) / 65535.0;
  };
  // Smoothstep weights: continuous gradients, so subpixel positions are well defined.
  const double sx = ax * ax * (3 - 2 * ax), sy = ay * ay * (3 - 2 * ay);
  const double top = (1 - sx) * value(ix, iy) + sx * value(ix + 1, iy);
  const double bottom = (1 - sx) * value(ix, iy + 1) + sx * value(ix + 1, iy + 1);
  return (1 - sy) * top + sy * bottom;
}

double SyntheticScene::intensity(int plane, const Eigen::Vector3d& p) const {
  const Plane& pl = planes_[static_cast<size_t>(plane)];
  const Eigen::Vector3d d = p - pl.origin;
  const double s = d.dot(pl.u), t = d.dot(pl.v);
  const double n = 0.65 * noise(pl.seed, s, t, 0.04) + 0.35 * noise(pl.seed + 7777u, s, t, 0.013);
  return std::clamp(255.0 * (1.6 * (n - 0.5) + 0.5), 0.0, 255.0);
}

RgbdFrame SyntheticScene::render(const Eigen::Isometry3d& T_world_camera, const PinholeCamera& camera,
                                 int64_t utime) const {
  RgbdFrame f;
  f.utime = utime;
  f.depth_utime = utime;
  f.camera = camera;
  f.rgb.create(camera.height, camera.width, CV_8UC3);
  f.depth_mm.create(camera.height, camera.width, CV_16UC1);
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d c = T_world_camera.translation();
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray_cam((x - camera.cx) / camera.fx, (y - camera.cy) / camera.fy, 1.0);
      const Eigen::Vector3d ray = R * ray_cam;
      double best = std::numeric_limits<double>::infinity();
      int hit = -1;
      for (size_t i = 0; i < planes_.size(); ++i) {
        const Plane& p = planes_[i];
        const double denom = p.normal.dot(ray);
        if (std::abs(denom) < 1e-12) continue;
        const double lambda = p.normal.dot(p.origin - c) / denom;
        if (!(lambda > 1e-6) || lambda >= best) continue;
        const Eigen::Vector3d q = c + lambda * ray - p.origin;
        const double s = q.dot(p.u), t = q.dot(p.v);
        if (s < 0 || t < 0 || s > p.width || t > p.height) continue;
        best = lambda;
        hit = static_cast<int>(i);
      }
      uint8_t grey = 0;
      uint16_t mm = 0;
      if (hit >= 0) {
        grey = static_cast<uint8_t>(std::lround(intensity(hit, c + best * ray)));
        const double z = best;  // ray_cam has unit z, so lambda is the optical-axis depth
        mm = z < 65.0 ? static_cast<uint16_t>(std::lround(z * 1000.0)) : 0;
      }
      f.rgb.at<cv::Vec3b>(y, x) = cv::Vec3b(grey, grey, grey);
      f.depth_mm.at<uint16_t>(y, x) = mm;
    }
  }
  return f;
}

}  // namespace kestrel::vo::test
