#include "sensors/lens.h"

#include <algorithm>
#include <cmath>

namespace kestrel::sensors {

void Lens::reset(const PinholeCamera& camera, bool use_distortion) {
  camera_ = camera;
  use_distortion_ = use_distortion;
  prepared_ = true;
  table_.clear();
  if (!use_distortion || !camera.distorted()) return;

  // Each raw pixel's ideal one by Newton's method on the forward model (PinholeCamera::distort_normalized), in
  // normalised coordinates, started from the row's previous solution: 2-4 iterations a pixel
  // (a fixed-point inversion needs tens in the corners of a strongly distorted lens), so the
  // table costs milliseconds, not a stall of the first frame.
  const int w = camera.width, h = camera.height;
  cols_ = (w - 1) / kStep + 2;
  rows_ = (h - 1) / kStep + 2;
  table_.resize(static_cast<size_t>(cols_) * static_cast<size_t>(rows_));
  for (int gy = 0; gy < rows_; ++gy) {
    const double yd = (double(gy * kStep) - camera.cy) / camera.fy;
    double xu = (0.0 - camera.cx) / camera.fx, yu = yd;  // the guess for the row's first node
    for (int gx = 0; gx < cols_; ++gx) {
      const double xd = (double(gx * kStep) - camera.cx) / camera.fx;
      for (int it = 0; it < 30; ++it) {
        Eigen::Matrix2d J;
        const Eigen::Vector2d d = camera.distort_normalized(xu, yu, &J);
        const double fx = d.x() - xd, fy = d.y() - yd;
        if (std::abs(fx) < 1e-13 && std::abs(fy) < 1e-13) break;
        const double det = J(0, 0) * J(1, 1) - J(0, 1) * J(0, 1);  // the Jacobian is symmetric
        xu -= (J(1, 1) * fx - J(0, 1) * fy) / det;
        yu -= (J(0, 0) * fy - J(0, 1) * fx) / det;
      }
      table_[static_cast<size_t>(gy) * static_cast<size_t>(cols_) + static_cast<size_t>(gx)] =
          Eigen::Vector2f(float(camera.fx * xu + camera.cx), float(camera.fy * yu + camera.cy));
    }
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
  const float uc = std::clamp(u, 0.0f, float(w - 1));
  const float vc = std::clamp(v, 0.0f, float(h - 1));
  const float gu = uc * (1.0f / kStep), gv = vc * (1.0f / kStep);
  const int x = std::min(static_cast<int>(gu), cols_ - 2), y = std::min(static_cast<int>(gv), rows_ - 2);
  const float fx = gu - float(x), fy = gv - float(y);
  const size_t i = static_cast<size_t>(y) * static_cast<size_t>(cols_) + static_cast<size_t>(x);
  const size_t c = static_cast<size_t>(cols_);
  const Eigen::Vector2f top = (1 - fx) * table_[i] + fx * table_[i + 1];
  const Eigen::Vector2f bottom = (1 - fx) * table_[i + c] + fx * table_[i + c + 1];
  // Outside the image (a coordinate clamped above) the map continues with unit slope.
  return (1 - fy) * top + fy * bottom + Eigen::Vector2f(u - uc, v - vc);
}

Eigen::Vector3f Lens::ray(float u, float v) const {
  const Eigen::Vector2f p = ideal(u, v);
  return {(p.x() - float(camera_.cx)) / float(camera_.fx),
          (p.y() - float(camera_.cy)) / float(camera_.fy), 1.0f};
}

}  // namespace kestrel::sensors
