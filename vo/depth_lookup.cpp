#include "vo/depth_lookup.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "sensors/depth_image.h"

namespace kestrel::vo {

void attach_depth(const cv::Mat& depth_mm, const sensors::Lens& lens, const DepthOptions& options,
                  const sensors::FrameMotion& motion, Frame& frame) {
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
    float z = sensors::reliable_depth_m(depth_mm, f.u0, f.v0, options.validity());
    if (z > 0.0f && compensate) {
      // Where the point seen now at this pixel was at depth time; read the depth there.
      const Eigen::Vector3f p_depth = T_depth_rgb * (z * ray);
      const Eigen::Vector2f ideal_at_depth(fx * p_depth.x() / p_depth.z() + cx,
                                           fy * p_depth.y() / p_depth.z() + cy);
      const Eigen::Vector2f raw_at_depth = Eigen::Vector2f(f.u0, f.v0) + (ideal_at_depth - f.ideal);
      const float z_depth = sensors::reliable_depth_m(depth_mm, raw_at_depth.x(), raw_at_depth.y(), options.validity());
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
    f.p_camera = sensors::point_at_frame_time(lens, motion, f.u0, f.v0, z, &f.ideal);
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
