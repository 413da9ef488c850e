#include "vo/rotation_prior.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/geometry/so3.h"

namespace kestrel::vo {
namespace {

// Central differences (one-sided at the border), in grey levels per pixel.
void gradients(const cv::Mat& f, cv::Mat& gx, cv::Mat& gy) {
  gx.create(f.size(), CV_32F);
  gy.create(f.size(), CV_32F);
  for (int y = 0; y < f.rows; ++y) {
    const int y0 = std::max(0, y - 1), y1 = std::min(f.rows - 1, y + 1);
    const float* up = f.ptr<float>(y0);
    const float* row = f.ptr<float>(y);
    const float* down = f.ptr<float>(y1);
    float* ox = gx.ptr<float>(y);
    float* oy = gy.ptr<float>(y);
    const float sy = 1.0f / float(y1 - y0);
    for (int x = 0; x < f.cols; ++x) {
      const int x0 = std::max(0, x - 1), x1 = std::min(f.cols - 1, x + 1);
      ox[x] = (row[x1] - row[x0]) / float(x1 - x0);
      oy[x] = (down[x] - up[x]) * sy;
    }
  }
}

}  // namespace

RotationPriorResult RotationPrior::estimate(const cv::Mat& prev, const cv::Mat& cur,
                                            const PinholeCamera& camera,
                                            const Eigen::Matrix3d& R_init, int max_iterations) {
  RotationPriorResult result;
  result.R_cur_prev = R_init;
  prev.convertTo(prev_f_, CV_32F);
  cur.convertTo(cur_f_, CV_32F);
  gradients(prev_f_, prev_gx_, prev_gy_);
  gradients(cur_f_, cur_gx_, cur_gy_);
  const float fx = float(camera.fx), fy = float(camera.fy);
  const float cx = float(camera.cx), cy = float(camera.cy);
  const int w = prev.cols, h = prev.rows;

  // The reference half of the ESM Jacobian, b x (grad I_prev * dpi/dp)^T at each pixel, does
  // not change between iterations.
  const size_t n_px = static_cast<size_t>(w) * static_cast<size_t>(h);
  jref_.resize(n_px);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3f b((float(x) - cx) / fx, (float(y) - cy) / fy, 1.0f);
      const float gx = prev_gx_.at<float>(y, x), gy = prev_gy_.at<float>(y, x);
      const Eigen::Vector3f a(gx * fx, gy * fy, -(gx * fx * b.x() + gy * fy * b.y()));
      jref_[static_cast<size_t>(y * w + x)] = b.cross(a);
    }
  }

  Eigen::Matrix3d R = R_init;
  double bias = 0.0;
  double last_cost = std::numeric_limits<double>::infinity();
  for (int it = 0; it < max_iterations; ++it) {
    const Eigen::Matrix3f Rf = R.cast<float>();
    const Eigen::Matrix3f Rt = Rf.transpose();
    const float bias_f = static_cast<float>(bias);
    Eigen::Matrix4f H = Eigen::Matrix4f::Zero();
    Eigen::Vector4f g = Eigen::Vector4f::Zero();
    double cost = 0.0;
    int n = 0;
    for (int y = 0; y < h; ++y) {
      const float* prev_row = prev_f_.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        const Eigen::Vector3f b((float(x) - cx) / fx, (float(y) - cy) / fy, 1.0f);
        const Eigen::Vector3f q = Rf * b;
        if (q.z() <= 1e-3f) continue;
        const float iz = 1.0f / q.z();
        const float u = fx * q.x() * iz + cx, v = fy * q.y() * iz + cy;
        if (!(u >= 0.0f && v >= 0.0f && u < float(w - 1) && v < float(h - 1))) continue;
        const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);
        const float ax = u - float(x0), ay = v - float(y0);
        const float w00 = (1 - ax) * (1 - ay), w01 = ax * (1 - ay), w10 = (1 - ax) * ay, w11 = ax * ay;
        auto sample = [&](const cv::Mat& m) {
          const float* r0 = m.ptr<float>(y0) + x0;
          const float* r1 = m.ptr<float>(y0 + 1) + x0;
          return w00 * r0[0] + w01 * r0[1] + w10 * r1[0] + w11 * r1[1];
        };
        const float r = sample(cur_f_) - prev_row[x] - bias_f;
        const float gx = sample(cur_gx_), gy = sample(cur_gy_);
        // grad I_cur * dpi/dq, carried back through R: the derivative for R * Exp(omega) is
        // b x (R^T a).
        const Eigen::Vector3f a(gx * fx * iz, gy * fy * iz, -(gx * fx * q.x() + gy * fy * q.y()) * iz * iz);
        const Eigen::Vector3f jcur = b.cross(Rt * a);
        const Eigen::Vector3f j = 0.5f * (jcur + jref_[static_cast<size_t>(y * w + x)]);
        // J = (j, -1): the upper triangle of J J^T and J r, written out (see subpixel.cpp).
        H(0, 0) += j.x() * j.x();
        H(0, 1) += j.x() * j.y();
        H(0, 2) += j.x() * j.z();
        H(1, 1) += j.y() * j.y();
        H(1, 2) += j.y() * j.z();
        H(2, 2) += j.z() * j.z();
        H(0, 3) -= j.x();
        H(1, 3) -= j.y();
        H(2, 3) -= j.z();
        H(3, 3) += 1.0f;
        g.head<3>() += j * r;
        g(3) -= r;
        cost += double(r) * double(r);
        ++n;
      }
    }
    if (n < 16) return result;
    // Diverging: keep the estimate of the previous iteration.
    if (it > 0 && cost / n > last_cost * 1.0001) return result;
    last_cost = cost / n;
    result.R_cur_prev = R;
    result.rms_error = std::sqrt(cost / n);
    H.triangularView<Eigen::StrictlyLower>() = H.transpose();
    const Eigen::Vector4d delta = H.cast<double>().ldlt().solve(-g.cast<double>());
    if (!delta.allFinite()) return result;
    R = so3::orthonormalize(R * so3::exp(delta.head<3>()));
    bias += delta(3);
    result.iterations = it + 1;
    if (delta.head<3>().norm() < 1e-4) {  // 0.006 degrees: far below what the windows need
      result.converged = true;
      break;
    }
  }
  result.R_cur_prev = R;
  return result;
}

}  // namespace kestrel::vo
