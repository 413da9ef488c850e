#include "common/transport/convert.h"

#include <cmath>

#include "common/error.h"

namespace kestrel::transport {

kestrel::pose3_t to_message(const Eigen::Isometry3d& T) {
  kestrel::pose3_t m{};
  const Eigen::Quaterniond q(T.linear());
  for (int i = 0; i < 3; ++i) m.position[i] = T.translation()[i];
  m.orientation[0] = q.w();
  m.orientation[1] = q.x();
  m.orientation[2] = q.y();
  m.orientation[3] = q.z();
  return m;
}

Eigen::Isometry3d from_message(const kestrel::pose3_t& m, const char* what) {
  for (double v : m.position)
    if (!std::isfinite(v)) throw InputError(std::string(what) + ": non-finite position");
  for (double v : m.orientation)
    if (!std::isfinite(v)) throw InputError(std::string(what) + ": non-finite orientation");
  const Eigen::Quaterniond q(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  if (std::abs(q.norm() - 1.0) > 1e-3)
    throw InputError(std::string(what) + ": orientation quaternion is not of unit length");
  return se3::make(q, Eigen::Vector3d(m.position[0], m.position[1], m.position[2]));
}

kestrel::camera_info_t to_message(const PinholeCamera& c, const Eigen::Isometry3d& T_body_camera) {
  kestrel::camera_info_t m{};
  m.width = c.width;
  m.height = c.height;
  m.fx = c.fx;
  m.fy = c.fy;
  m.cx = c.cx;
  m.cy = c.cy;
  bool distorted = false;
  for (int i = 0; i < 5; ++i) {
    m.distortion[i] = c.distortion[i];
    distorted = distorted || c.distortion[i] != 0.0;
  }
  m.distortion_model = distorted ? kestrel::camera_info_t::DISTORTION_RADTAN
                                 : kestrel::camera_info_t::DISTORTION_NONE;
  m.T_body_camera = to_message(T_body_camera);
  return m;
}

PinholeCamera from_message(const kestrel::camera_info_t& m, const char* what) {
  PinholeCamera c;
  c.width = m.width;
  c.height = m.height;
  c.fx = m.fx;
  c.fy = m.fy;
  c.cx = m.cx;
  c.cy = m.cy;
  if (m.distortion_model == kestrel::camera_info_t::DISTORTION_RADTAN) {
    for (int i = 0; i < 5; ++i) c.distortion[i] = m.distortion[i];
  } else if (m.distortion_model != kestrel::camera_info_t::DISTORTION_NONE) {
    throw InputError(std::string(what) + ": unknown distortion model " +
                     std::to_string(m.distortion_model));
  }
  c.validate(what);
  return c;
}

Matrix6d covariance_from(const double (&c)[36]) {
  return Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(c);
}

void covariance_to(const Matrix6d& m, double (&c)[36]) {
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> out(c);
  out = m;
}

Matrix6d pose_covariance_from(const kestrel::state_t& m) {
  Matrix6d P = Matrix6d::Zero();
  if (m.cov_dim < 9) return P;
  constexpr size_t kIndex[6] = {0, 1, 2, 6, 7, 8};
  for (size_t r = 0; r < 6; ++r) {
    if (m.covariance.size() <= kIndex[r]) return Matrix6d::Zero();
    const std::vector<double>& row = m.covariance[kIndex[r]];
    for (size_t c = 0; c < 6; ++c) {
      if (row.size() <= kIndex[c]) return Matrix6d::Zero();
      P(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = row[kIndex[c]];
    }
  }
  return P;
}

}  // namespace kestrel::transport
