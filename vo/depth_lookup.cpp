#include "vo/depth_lookup.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "common/geometry/se3.h"

namespace kestrel::vo {

float reliable_depth_m(const cv::Mat& depth_mm, float u, float v, const DepthOptions& options) {
  const int x = static_cast<int>(std::lround(u));
  const int y = static_cast<int>(std::lround(v));
  if (x < 1 || y < 1 || x >= depth_mm.cols - 1 || y >= depth_mm.rows - 1) return 0.0f;
  const uint16_t centre = depth_mm.at<uint16_t>(y, x);
  const float z = 1e-3f * static_cast<float>(centre);
  if (centre == 0 || z < float(options.min_m) || z > float(options.max_m)) return 0.0f;
  int lo = centre, hi = centre;
  for (int dy = -1; dy <= 1; ++dy) {
    const uint16_t* row = depth_mm.ptr<uint16_t>(y + dy);
    for (int dx = -1; dx <= 1; ++dx) {
      const int d = row[x + dx];
      if (d == 0) continue;  // holes beside a reading are common on valid surfaces
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  if (static_cast<float>(hi - lo) > static_cast<float>(options.max_discontinuity) * centre)
    return 0.0f;
  return z;
}

Eigen::Vector3f point_at_frame_time(const Lens& lens, const FrameMotion& motion, float u0, float v0,
                                    float z, Eigen::Vector2f* ideal) {
  const PinholeCamera& cam = lens.camera();
  *ideal = lens.ideal(u0, v0);
  Eigen::Vector3f p(z * (ideal->x() - float(cam.cx)) / float(cam.fx),
                    z * (ideal->y() - float(cam.cy)) / float(cam.fy), z);
  if (!motion.known || motion.readout_s <= 0.0) return p;
  // The row was exposed s seconds after the middle row: carry its point into the middle row's
  // camera, to first order in s * twist (sub-millimetre at the speeds a Kinect can image).
  const float s = (v0 - 0.5f * float(cam.height - 1)) *
                  static_cast<float>(motion.readout_s) / float(cam.height);
  const Eigen::Vector3f rho = motion.twist_per_s.head<3>().cast<float>();
  const Eigen::Vector3f phi = motion.twist_per_s.tail<3>().cast<float>();
  p += s * (phi.cross(p) + rho);
  *ideal = Eigen::Vector2f(float(cam.fx) * p.x() / p.z() + float(cam.cx), float(cam.fy) * p.y() / p.z() + float(cam.cy));
  return p;
}

double depth_time_offset_s(const DepthOptions& options, int64_t rgb_utime, int64_t depth_utime) {
  if (!options.time_offset_from_stamps) return options.time_offset_s;
  constexpr int64_t kMaxStampOffsetUs = 100000;
  const int64_t offset_us = depth_utime - rgb_utime;
  return std::abs(offset_us) < kMaxStampOffsetUs ? 1e-6 * double(offset_us) + options.time_offset_s : 0.0;
}

void attach_depth(const cv::Mat& depth_mm, const Lens& lens, const DepthOptions& options,
                  const FrameMotion& motion, Frame& frame) {
  const PinholeCamera& cam = lens.camera();
  const float fx = float(cam.fx), fy = float(cam.fy), cx = float(cam.cx), cy = float(cam.cy);
  const bool compensate = options.compensate_time_offset && motion.known && motion.depth_offset_s != 0.0;
  const Eigen::Isometry3f T_rgb_depth =
      compensate ? motion.T_rgb_depth().cast<float>() : Eigen::Isometry3f::Identity();
  const Eigen::Isometry3f T_depth_rgb = T_rgb_depth.inverse();
  std::array<int, kMaxLevels + 1> begin = frame.level_begin;
  size_t kept = 0;
  int level = 0;
  for (size_t i = 0; i < frame.features.size(); ++i) {
    while (level < kMaxLevels && static_cast<int>(i) >= begin[static_cast<size_t>(level + 1)]) {
      ++level;
      frame.level_begin[static_cast<size_t>(level)] = static_cast<int>(kept);
    }
    Feature f = frame.features[i];
    f.ideal = lens.ideal(f.u0, f.v0);
    const Eigen::Vector3f ray((f.ideal.x() - cx) / fx, (f.ideal.y() - cy) / fy, 1.0f);
    float z = reliable_depth_m(depth_mm, f.u0, f.v0, options);
    if (z > 0.0f && compensate) {
      // Where the point seen now at this pixel was at depth time; read the depth there.
      const Eigen::Vector3f p_depth = T_depth_rgb * (z * ray);
      const Eigen::Vector2f ideal_at_depth(fx * p_depth.x() / p_depth.z() + cx,
                                           fy * p_depth.y() / p_depth.z() + cy);
      const Eigen::Vector2f raw_at_depth = Eigen::Vector2f(f.u0, f.v0) + (ideal_at_depth - f.ideal);
      const float z_depth = reliable_depth_m(depth_mm, raw_at_depth.x(), raw_at_depth.y(), options);
      if (z_depth > 0.0f) {
        const Eigen::Vector3f ray_depth((ideal_at_depth.x() - cx) / fx,
                                        (ideal_at_depth.y() - cy) / fy, 1.0f);
        z = (T_rgb_depth * (z_depth * ray_depth)).z();
        if (!(z >= float(options.min_m) && z <= float(options.max_m))) z = 0.0f;
      } else {
        z = 0.0f;
      }
    }
    if (!(z > 0.0f)) continue;
    f.depth_m = z;
    f.p_camera = point_at_frame_time(lens, motion, f.u0, f.v0, z, &f.ideal);
    f.sigma_z = static_cast<float>(options.sigma_z_coeff) * z * z;
    frame.features[kept++] = f;
  }
  while (level < kMaxLevels) {
    ++level;
    frame.level_begin[static_cast<size_t>(level)] = static_cast<int>(kept);
  }
  frame.features.resize(kept);
}

}  // namespace kestrel::vo
