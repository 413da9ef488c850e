#include "vo/lens.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

namespace kestrel::vo {

void Lens::reset(const PinholeCamera& camera, bool use_distortion) {
  camera_ = camera;
  use_distortion_ = use_distortion;
  prepared_ = true;
  table_.clear();
  const bool any = std::any_of(camera.distortion.begin(), camera.distortion.end(),
                               [](double d) { return d != 0.0; });
  if (!use_distortion || !any) return;

  const int w = camera.width, h = camera.height;
  cv::Mat raw(w * h, 1, CV_32FC2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) raw.at<cv::Vec2f>(y * w + x) = cv::Vec2f(float(x), float(y));
  const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  const cv::Mat D(1, 5, CV_64F, const_cast<double*>(camera.distortion.data()));
  cv::Mat ideal;
  // Many iterations: the fixed-point inversion converges slowly in the corners of a strongly
  // distorted lens, and this table is built once per camera.
  cv::undistortPoints(raw, ideal, K, D, cv::noArray(), K,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-10));
  table_.resize(static_cast<size_t>(w) * static_cast<size_t>(h));
  for (size_t i = 0; i < table_.size(); ++i) {
    const cv::Vec2f p = ideal.at<cv::Vec2f>(static_cast<int>(i));
    table_[i] = Eigen::Vector2f(p[0], p[1]);
  }
}

bool Lens::prepared_for(const PinholeCamera& c, bool use_distortion) const {
  return prepared_ && use_distortion == use_distortion_ && c.width == camera_.width &&
         c.height == camera_.height && c.fx == camera_.fx && c.fy == camera_.fy &&
         c.cx == camera_.cx && c.cy == camera_.cy && c.distortion == camera_.distortion;
}

Eigen::Vector2f Lens::ideal(float u, float v) const {
  if (table_.empty()) return {u, v};
  const int w = camera_.width, h = camera_.height;
  const float uc = std::clamp(u, 0.0f, float(w - 1) - 1e-3f);
  const float vc = std::clamp(v, 0.0f, float(h - 1) - 1e-3f);
  const int x = static_cast<int>(uc), y = static_cast<int>(vc);
  const float fx = uc - float(x), fy = vc - float(y);
  const size_t i = static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x);
  const size_t ws = static_cast<size_t>(w);
  const Eigen::Vector2f top = (1 - fx) * table_[i] + fx * table_[i + 1];
  const Eigen::Vector2f bottom = (1 - fx) * table_[i + ws] + fx * table_[i + ws + 1];
  // Outside the table (a coordinate clamped above) the map continues with unit slope.
  return (1 - fy) * top + fy * bottom + Eigen::Vector2f(u - uc, v - vc);
}

Eigen::Vector3f Lens::ray(float u, float v) const {
  const Eigen::Vector2f p = ideal(u, v);
  return {(p.x() - float(camera_.cx)) / float(camera_.fx),
          (p.y() - float(camera_.cy)) / float(camera_.fy), 1.0f};
}

Eigen::Vector2d distort_pixel(const PinholeCamera& c, bool use_distortion, double u, double v) {
  if (!use_distortion) return {u, v};
  const double k1 = c.distortion[0], k2 = c.distortion[1], p1 = c.distortion[2], p2 = c.distortion[3],
               k3 = c.distortion[4];
  const double x = (u - c.cx) / c.fx, y = (v - c.cy) / c.fy;
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  const double yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
  return {c.fx * xd + c.cx, c.fy * yd + c.cy};
}

}  // namespace kestrel::vo
