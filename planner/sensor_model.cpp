// FeatureSensor: range / azimuth / elevation of point features, and the information it gives.
#include "planner/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "estimator/information.h"

namespace kestrel::planner {

FeatureSensorOptions FeatureSensorOptions::paper_camera() { return {}; }

FeatureSensorOptions FeatureSensorOptions::kinect() {
  FeatureSensorOptions o;
  o.max_range_m = 4.0;
  o.min_range_m = 0.5;
  o.horizontal_fov_rad = 57.0 * M_PI / 180.0;
  o.vertical_fov_rad = 43.0 * M_PI / 180.0;
  o.range_sigma_m = 0.0;
  o.range_sigma_per_m2 = 1.4e-3;
  o.bearing_sigma_rad = 1e-3;  // about one pixel at 580 px focal length
  return o;
}

FeatureSensorOptions FeatureSensorOptions::planar_laser(double range_m) {
  FeatureSensorOptions o;
  o.max_range_m = range_m;
  o.min_range_m = 0.1;
  o.horizontal_fov_rad = 2.0 * M_PI;
  o.vertical_fov_rad = M_PI;
  o.range_sigma_m = 0.01;
  o.bearing_sigma_rad = 0.5 * M_PI / 180.0;
  return o;
}

FeatureSensor::FeatureSensor(const Environment& env, FeatureSensorOptions options)
    : env_(env), options_(options) {
  const auto& o = options_;
  if (!(o.max_range_m > o.min_range_m) || !(o.min_range_m >= 0.0) || !(o.horizontal_fov_rad > 0.0) ||
      !(o.vertical_fov_rad > 0.0) || !(o.bearing_sigma_rad > 0.0) ||
      !(o.range_sigma_m > 0.0 || o.range_sigma_per_m2 > 0.0))
    throw std::invalid_argument("FeatureSensor: ranges, fields of view and noise must be positive");
  const auto& features = env_.features();
  if (features.empty()) return;
  Eigen::AlignedBox2d box;
  for (const Feature& f : features) box.extend(f.position.head<2>());
  cell_m_ = o.max_range_m;
  cell_origin_ = box.min();
  nx_ = static_cast<int>(std::floor((box.max().x() - box.min().x()) / cell_m_)) + 1;
  ny_ = static_cast<int>(std::floor((box.max().y() - box.min().y()) / cell_m_)) + 1;
  cells_.assign(static_cast<size_t>(nx_) * ny_, {});
  for (int i = 0; i < static_cast<int>(features.size()); ++i) {
    const Eigen::Vector2d c = (features[i].position.head<2>() - cell_origin_) / cell_m_;
    cells_[static_cast<size_t>(c.y()) * nx_ + static_cast<size_t>(c.x())].push_back(i);
  }
}

std::vector<int> FeatureSensor::visible(const Config& q) const {
  std::vector<int> out;
  if (cells_.empty() || !q.allFinite()) return out;
  const Eigen::Vector3d p = position(q);
  const auto& features = env_.features();
  const double half_h = 0.5 * options_.horizontal_fov_rad, half_v = 0.5 * options_.vertical_fov_rad;
  const Eigen::Vector2d c = (p.head<2>() - cell_origin_) / cell_m_;
  const int cx = static_cast<int>(std::floor(c.x())), cy = static_cast<int>(std::floor(c.y()));
  for (int y = std::max(0, cy - 1); y <= std::min(ny_ - 1, cy + 1); ++y)
    for (int x = std::max(0, cx - 1); x <= std::min(nx_ - 1, cx + 1); ++x)
      for (int i : cells_[static_cast<size_t>(y) * nx_ + x]) {
        const Eigen::Vector3d d = features[i].position - p;
        const double r = d.norm();
        if (r > options_.max_range_m || r < options_.min_range_m) continue;
        if (features[i].normal.dot(d) >= 0.0) continue;  // seen from behind its surface
        const double rho = d.head<2>().norm();
        if (half_h < M_PI && std::abs(wrap_angle(std::atan2(d.y(), d.x()) - q[3])) > half_h) continue;
        if (std::abs(std::atan2(d.z(), rho)) > half_v) continue;
        if (!env_.line_of_sight(p, features[i].position)) continue;
        out.push_back(i);
      }
  std::sort(out.begin(), out.end());  // a stable order: sums do not depend on the bucketing
  return out;
}

Eigen::Vector3d FeatureSensor::predict(const Config& q, int index, double reference_azimuth) const {
  const Eigen::Vector3d d = env_.features()[index].position - position(q);
  const double rho = d.head<2>().norm();
  const double az = reference_azimuth + wrap_angle(std::atan2(d.y(), d.x()) - q[3] - reference_azimuth);
  return {d.norm(), az, std::atan2(d.z(), rho)};
}

FeatureMeasurement FeatureSensor::measure(const Config& q, int index) const {
  const Eigen::Vector3d d = env_.features()[index].position - position(q);
  const double r2 = d.squaredNorm(), r = std::sqrt(r2);
  const double rho2 = std::max(d.head<2>().squaredNorm(), 1e-12), rho = std::sqrt(rho2);
  FeatureMeasurement m;
  m.z = {r, wrap_angle(std::atan2(d.y(), d.x()) - q[3]), std::atan2(d.z(), rho)};
  // d = f - p, so every derivative with respect to p is minus the one with respect to d.
  m.H.setZero();
  m.H.block<1, 3>(0, 0) = -d.transpose() / r;
  m.H.block<1, 3>(1, 0) << d.y() / rho2, -d.x() / rho2, 0.0;
  m.H(1, 3) = -1.0;
  m.H.block<1, 3>(2, 0) << d.z() * d.x() / (rho * r2), d.z() * d.y() / (rho * r2), -rho / r2;
  const double sr = options_.range_sigma_m + options_.range_sigma_per_m2 * r2;
  const double sb = options_.bearing_sigma_rad;
  m.variances = {sr * sr, sb * sb, sb * sb};
  return m;
}

Mat4 FeatureSensor::information(const Config& q) const {
  Mat4 M = Mat4::Zero();
  for (int i : visible(q)) {
    const FeatureMeasurement m = measure(q, i);
    M += estimator::measurement_information(m.H, Eigen::Matrix3d(m.variances.asDiagonal()));
  }
  return M;
}

Mat4 FeatureSensor::ukf_information(const Config& q, const Mat4& prior) const {
  // Eq. 27 with the estimator's sigma points, but never forming the 3k x 3k innovation
  // covariance S = Q + D W D^T (D: the 2n+1 centred predicted measurements, W: their
  // covariance weights). Q is diagonal, so with G = D^T Q^-1 D (9 x 9) the push-through
  // identity gives D^T S^-1 D = (I + G W)^-1 G, hence K S K^T = X W (I + G W)^-1 G W X^T:
  // linear in the number of measurements instead of cubic, and the same value as
  // estimator::ukf_measurement_information (test UkfInformationEqualsTheGenericUkf).
  const std::vector<int> seen = visible(q);
  if (seen.empty()) return Mat4::Zero();
  const auto prior_llt = prior.llt();
  if (prior_llt.info() != Eigen::Success || !prior.allFinite())
    throw std::invalid_argument("ukf_information: prior covariance is not positive definite");
  const estimator::UnscentedWeights w = estimator::unscented_weights(4, {});
  const Eigen::Matrix<double, 4, Eigen::Dynamic> X = estimator::sigma_offsets(prior, w);
  constexpr int kPoints = 9;
  Eigen::Matrix<double, kPoints, 1> wc;
  wc.setConstant(w.other);
  wc[0] = w.cov0;
  Eigen::Matrix<double, kPoints, 1> wm = wc;
  wm[0] = w.mean0;
  Eigen::Matrix<double, kPoints, kPoints> G = Eigen::Matrix<double, kPoints, kPoints>::Zero();
  for (int i : seen) {
    const FeatureMeasurement fm = measure(q, i);
    Eigen::Matrix<double, 3, kPoints> Z;
    for (int j = 0; j < kPoints; ++j) Z.col(j) = predict(q + X.col(j), i, fm.z[1]);
    const Eigen::Vector3d z_bar = Z * wm;
    const Eigen::Matrix<double, 3, kPoints> D = Z.colwise() - z_bar;
    G.noalias() += D.transpose() * fm.variances.cwiseInverse().asDiagonal() * D;
  }
  const Eigen::Matrix<double, kPoints, kPoints> IGW =
      Eigen::Matrix<double, kPoints, kPoints>::Identity() + G * wc.asDiagonal();
  const Eigen::Matrix<double, 4, kPoints> XW = X * wc.asDiagonal();
  const Mat4 KSK = XW * IGW.partialPivLu().solve(G) * XW.transpose();
  Mat4 posterior = prior - KSK;
  posterior = 0.5 * (posterior + posterior.transpose()).eval();
  const auto post_llt = posterior.llt();
  if (post_llt.info() != Eigen::Success)
    throw std::invalid_argument("ukf_information: UKF posterior covariance is not positive definite");
  const Mat4 M = post_llt.solve(Mat4::Identity()) - prior_llt.solve(Mat4::Identity());
  return 0.5 * (M + M.transpose());
}

double FeatureSensor::ukf_information_gain(const Config& q, const Mat4& prior) const {
  const Mat4 M = ukf_information(q, prior);
  const Mat4 posterior = estimator::update_covariance(prior, M);
  return 0.5 * (std::log(prior.determinant()) - std::log(posterior.determinant()));
}

}  // namespace kestrel::planner
