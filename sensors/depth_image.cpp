#include "sensors/depth_image.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace kestrel::sensors {

float reliable_depth_m(const cv::Mat& depth_mm, float u, float v, const DepthValidity& validity) {
  const int x = static_cast<int>(std::lround(u));
  const int y = static_cast<int>(std::lround(v));
  if (x < 1 || y < 1 || x >= depth_mm.cols - 1 || y >= depth_mm.rows - 1) return 0.0f;
  const uint16_t centre = depth_mm.at<uint16_t>(y, x);
  const float z = 1e-3f * static_cast<float>(centre);
  if (centre == 0 || z < float(validity.min_m) || z > float(validity.max_m)) return 0.0f;
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
  if (static_cast<float>(hi - lo) > static_cast<float>(validity.max_discontinuity) * centre)
    return 0.0f;
  return z;
}

double depth_time_offset_s(const DepthTiming& timing, int64_t rgb_utime, int64_t depth_utime) {
  if (!timing.from_stamps) return timing.offset_s;
  constexpr int64_t kMaxStampOffsetUs = 100000;
  const int64_t offset_us = depth_utime - rgb_utime;
  return std::abs(offset_us) < kMaxStampOffsetUs ? 1e-6 * double(offset_us) + timing.offset_s : 0.0;
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

}  // namespace kestrel::sensors
