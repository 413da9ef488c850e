#include "drivers/kinect/depth_warp.h"

#include <cmath>
#include <limits>

namespace kestrel::kinect {

DepthWarp::DepthWarp(const PinholeCamera& from, const PinholeCamera& to, const Eigen::Isometry3d& T_to_from)
    : from_(from), to_(to), t_to_from_(T_to_from.translation().cast<float>()) {
  const Eigen::Matrix3d R = T_to_from.linear();
  ray_in_to_.resize(static_cast<size_t>(from.width) * static_cast<size_t>(from.height));
  for (int v = 0; v < from.height; ++v) {
    for (int u = 0; u < from.width; ++u) {
      const Eigen::Vector3d ray((u - from.cx) / from.fx, (v - from.cy) / from.fy, 1.0);
      ray_in_to_[static_cast<size_t>(v) * from.width + u] = (R * ray).cast<float>();
    }
  }
}

cv::Mat DepthWarp::operator()(const cv::Mat& depth_from) const {
  CV_Assert(depth_from.type() == CV_32FC1 && depth_from.cols == from_.width &&
            depth_from.rows == from_.height);
  constexpr float kEmpty = std::numeric_limits<float>::infinity();
  cv::Mat out(to_.height, to_.width, CV_32FC1, cv::Scalar(static_cast<double>(kEmpty)));
  const float fx = static_cast<float>(to_.fx), fy = static_cast<float>(to_.fy);
  const float cx = static_cast<float>(to_.cx), cy = static_cast<float>(to_.cy);
  // Pixel centres are at integer coordinates, so a pixel covers [u - 0.5, u + 0.5).
  const float max_u = static_cast<float>(to_.width) - 0.5f;
  const float max_v = static_cast<float>(to_.height) - 0.5f;
  for (int v = 0; v < from_.height; ++v) {
    const float* z_row = depth_from.ptr<float>(v);
    const Eigen::Vector3f* rays = ray_in_to_.data() + static_cast<size_t>(v) * from_.width;
    for (int u = 0; u < from_.width; ++u) {
      const float z = z_row[u];
      if (!(z > 0.0f)) continue;  // also skips NaN
      const Eigen::Vector3f p = z * rays[u] + t_to_from_;
      if (!(p.z() > 0.0f)) continue;
      const float inv_z = 1.0f / p.z();
      const float pu = fx * p.x() * inv_z + cx;
      const float pv = fy * p.y() * inv_z + cy;
      if (!(pu >= -0.5f && pu < max_u && pv >= -0.5f && pv < max_v)) continue;
      float& target = out.at<float>(static_cast<int>(pv + 0.5f), static_cast<int>(pu + 0.5f));
      if (p.z() < target) target = p.z();
    }
  }
  for (int v = 0; v < out.rows; ++v) {
    float* row = out.ptr<float>(v);
    for (int u = 0; u < out.cols; ++u)
      if (row[u] == kEmpty) row[u] = 0.0f;
  }
  return out;
}

}  // namespace kestrel::kinect
