// FeatureSensor: range / azimuth / elevation of point features, and the information it gives.
#include "planner/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/numbers.h"
#include "common/gaussian/information.h"

namespace kestrel::planner {
namespace {
// Field-of-view edges are decided by atan2 only within this of the edge: far above the
// rounding of atan2 and of the dot products (~1e-15 rad), far below anything a field of view
// could mean. Fields of view within 1e-3 rad of 0 or of the widest always ask atan2.
constexpr double kFovMargin_rad = 1e-9;
constexpr double kFastFovLimit_rad = 1e-3;

// gaussian::measurement_information(H, diag(variances)), H^T Q^-1 H, for a diagonal Q in the
// arithmetic Eigen's LLT solve and product perform there (Q's factor is diag(sqrt(v)), each
// triangular solve multiplies by its reciprocal, the product sums k = 0, 1, 2 in order): the
// same values (test InformationTermEqualsTheEstimators) without a 3 x 3 factorisation and a
// general matrix product per feature. A Q the estimator would reject goes to it (and throws).
Mat4 diagonal_information(const Eigen::Matrix<double, 3, 4>& H, const Eigen::Vector3d& variances) {
  if (!(variances.array() > 0.0).all() || !variances.allFinite())
    return gaussian::measurement_information(H, Eigen::Matrix3d(variances.asDiagonal()));
  Eigen::Matrix<double, 3, 4> X;
  for (int k = 0; k < 3; ++k) {
    const double inv = 1.0 / std::sqrt(variances[k]);
    X.row(k) = (H.row(k) * inv) * inv;
  }
  Mat4 M;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) M(i, j) = (H(0, i) * X(0, j) + H(1, i) * X(1, j)) + H(2, i) * X(2, j);
  return 0.5 * (M + M.transpose());
}
}  // namespace

Mat4 FeatureSensor::information_term(const FeatureMeasurement& m) { return diagonal_information(m.H, m.variances); }

FeatureSensorOptions FeatureSensorOptions::paper_camera() { return {}; }

FeatureSensorOptions FeatureSensorOptions::kinect() {
  FeatureSensorOptions o;
  o.max_range_m = 4.0;
  o.min_range_m = 0.5;
  o.horizontal_fov_rad = 57.0 * kPi / 180.0;
  o.vertical_fov_rad = 43.0 * kPi / 180.0;
  o.range_sigma_m = 0.0;
  o.range_sigma_per_m2 = 1.4e-3;
  o.bearing_sigma_rad = 1e-3;  // about one pixel at 580 px focal length
  return o;
}

FeatureSensorOptions FeatureSensorOptions::planar_laser(double range_m) {
  FeatureSensorOptions o;
  o.max_range_m = range_m;
  o.min_range_m = 0.1;
  o.horizontal_fov_rad = 2.0 * kPi;
  o.vertical_fov_rad = kPi;
  o.range_sigma_m = 0.01;
  o.bearing_sigma_rad = 0.5 * kPi / 180.0;
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
  fine_m_ = 0.25 * o.max_range_m;
  fine_nx_ = static_cast<int>(std::floor((box.max().x() - box.min().x()) / fine_m_)) + 1;
  fine_ny_ = static_cast<int>(std::floor((box.max().y() - box.min().y()) / fine_m_)) + 1;
  const auto fine_cell = [&](const Feature& f) {
    const Eigen::Vector2d c = (f.position.head<2>() - cell_origin_) / fine_m_;
    const int x = std::clamp(static_cast<int>(c.x()), 0, fine_nx_ - 1), y = std::clamp(static_cast<int>(c.y()), 0, fine_ny_ - 1);
    return static_cast<size_t>(y) * fine_nx_ + x;
  };
  fine_start_.assign(static_cast<size_t>(fine_nx_) * fine_ny_ + 1, 0);
  for (const Feature& f : features) ++fine_start_[fine_cell(f) + 1];
  for (size_t c = 1; c < fine_start_.size(); ++c) fine_start_[c] += fine_start_[c - 1];
  fine_.resize(features.size());
  std::vector<int> fill(fine_start_.begin(), fine_start_.end() - 1);
  for (int i = 0; i < static_cast<int>(features.size()); ++i)
    fine_[static_cast<size_t>(fill[fine_cell(features[i])]++)] = {features[i].position, features[i].normal, i};
  const double half_h = 0.5 * o.horizontal_fov_rad, half_v = 0.5 * o.vertical_fov_rad;
  fast_azimuth_ = half_h > kFastFovLimit_rad && half_h < kPi - kFastFovLimit_rad;
  cos_h_out_ = std::cos(half_h + kFovMargin_rad);
  cos_h_in_ = std::cos(half_h - kFovMargin_rad);
  fast_elevation_ = half_v > kFastFovLimit_rad && half_v < 0.5 * kPi - kFastFovLimit_rad;
  tan_v_out_ = std::tan(half_v + kFovMargin_rad);
  tan_v_in_ = std::tan(half_v - kFovMargin_rad);
}

std::vector<int> FeatureSensor::visible_reference(const Config& q) const {
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
        if (half_h < kPi && std::abs(wrap_angle(std::atan2(d.y(), d.x()) - q[3])) > half_h) continue;
        if (std::abs(std::atan2(d.z(), rho)) > half_v) continue;
        if (!env_.line_of_sight(p, features[i].position)) continue;
        out.push_back(i);
      }
  std::sort(out.begin(), out.end());  // a stable order: sums do not depend on the bucketing
  return out;
}

std::vector<int> FeatureSensor::visible(const Config& q) const {
  // The same tests as visible_reference, in the same order and arithmetic where they decide;
  // what is new only skips work whose outcome is certain (see the header and the test
  // FastVisibilityEqualsTheDefinition).
  std::vector<int> out;
  if (fine_.empty() || !q.allFinite()) return out;
  // Features that pass every test but line of sight; then all their rays at once.
  thread_local std::vector<int> candidates;
  thread_local std::vector<Eigen::Vector3d> targets;
  thread_local std::vector<char> seen;
  candidates.clear();
  targets.clear();
  const Eigen::Vector3d p = position(q);
  const double half_h = 0.5 * options_.horizontal_fov_rad, half_v = 0.5 * options_.vertical_fov_rad;
  const double range = options_.max_range_m;
  const double cos_yaw = std::cos(q[3]), sin_yaw = std::sin(q[3]);
  // The wedge of the horizontal field of view, widened by 1e-6 rad, as two half-planes
  // n . (x - p) >= 0 (when it is narrower than a half-plane).
  const bool wedge = fast_azimuth_ && half_h + 1e-6 < 0.5 * kPi;
  const double edge = half_h + 1e-6;
  const Eigen::Vector2d n_left(std::sin(q[3] + edge), -std::cos(q[3] + edge));
  const Eigen::Vector2d n_right(-std::sin(q[3] - edge), std::cos(q[3] - edge));
  constexpr double kCellSlack_m = 1e-6;  // a feature filed by rounding lies this close to its cell
  const double reach = range + kCellSlack_m;
  const auto index_of = [&](double v, double origin, int n) {
    return std::clamp(static_cast<int>(std::floor((v - origin) / fine_m_)), 0, n - 1);
  };
  const int x0 = index_of(p.x() - reach, cell_origin_.x(), fine_nx_), x1 = index_of(p.x() + reach, cell_origin_.x(), fine_nx_);
  const int y0 = index_of(p.y() - reach, cell_origin_.y(), fine_ny_), y1 = index_of(p.y() + reach, cell_origin_.y(), fine_ny_);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const size_t cell = static_cast<size_t>(y) * fine_nx_ + x;
      if (fine_start_[cell] == fine_start_[cell + 1]) continue;
      // The cell's rectangle relative to p, grown by the slack; the edge cells take in
      // everything beyond (features clamped into them).
      const double lx = x == 0 ? -1e300 : cell_origin_.x() + x * fine_m_ - kCellSlack_m - p.x();
      const double hx = x == fine_nx_ - 1 ? 1e300 : cell_origin_.x() + (x + 1) * fine_m_ + kCellSlack_m - p.x();
      const double ly = y == 0 ? -1e300 : cell_origin_.y() + y * fine_m_ - kCellSlack_m - p.y();
      const double hy = y == fine_ny_ - 1 ? 1e300 : cell_origin_.y() + (y + 1) * fine_m_ + kCellSlack_m - p.y();
      const double dx = std::max({lx, 0.0, -hx}), dy = std::max({ly, 0.0, -hy});
      if (dx * dx + dy * dy > reach * reach) continue;  // beyond the range
      if (wedge) {
        const auto outside = [&](const Eigen::Vector2d& n) {  // every point of the cell behind n
          return std::max(n.x() * lx, n.x() * hx) + std::max(n.y() * ly, n.y() * hy) < -1e-9;
        };
        if (outside(n_left) || outside(n_right)) continue;
      }
      for (int k = fine_start_[cell]; k < fine_start_[cell + 1]; ++k) {
        const CellFeature& f = fine_[static_cast<size_t>(k)];
        const Eigen::Vector3d d = f.position - p;
        const double r = d.norm();
        if (r > options_.max_range_m || r < options_.min_range_m) continue;
        if (f.normal.dot(d) >= 0.0) continue;  // seen from behind its surface
        const double rho = d.head<2>().norm();
        if (half_h < kPi) {
          // Outside the horizontal field of view: |wrap(atan2(dy, dx) - yaw)| > half_h. The
          // cosine of that angle, d . heading / rho, decides away from the edge.
          int decided = 0;  // -1 outside, +1 inside, 0 ask atan2
          if (fast_azimuth_) {
            const double along = d.x() * cos_yaw + d.y() * sin_yaw;
            if (along < rho * cos_h_out_) decided = -1;
            else if (along > rho * cos_h_in_) decided = 1;
          }
          if (decided < 0) continue;
          if (decided == 0 && std::abs(wrap_angle(std::atan2(d.y(), d.x()) - q[3])) > half_h) continue;
        }
        {
          // Outside the vertical field of view: |atan2(dz, rho)| > half_v, i.e. |dz| > rho tan.
          int decided = 0;
          if (fast_elevation_) {
            const double up = std::abs(d.z());
            if (up > rho * tan_v_out_) decided = -1;
            else if (up < rho * tan_v_in_) decided = 1;
          }
          if (decided < 0) continue;
          if (decided == 0 && std::abs(std::atan2(d.z(), rho)) > half_v) continue;
        }
        candidates.push_back(f.index);
        targets.push_back(f.position);
      }
    }
  env_.lines_of_sight(p, targets, seen);
  for (size_t k = 0; k < candidates.size(); ++k)
    if (seen[k]) out.push_back(candidates[k]);
  std::sort(out.begin(), out.end());  // a stable order: sums do not depend on the bucketing
  return out;
}

Eigen::Vector3d FeatureSensor::predict(const Config& q, int index, double reference_azimuth) const {
  const Eigen::Vector3d d = env_.features()[index].position - position(q);
  const double rho = d.head<2>().norm();
  const double az = reference_azimuth + wrap_angle(std::atan2(d.y(), d.x()) - q[3] - reference_azimuth);
  return {d.norm(), az, std::atan2(d.z(), rho)};
}

void FeatureSensor::jacobian_and_noise(const Config& q, int index, FeatureMeasurement& m) const {
  const Eigen::Vector3d d = env_.features()[index].position - position(q);
  const double r2 = d.squaredNorm(), r = std::sqrt(r2);
  const double rho2 = std::max(d.head<2>().squaredNorm(), 1e-12), rho = std::sqrt(rho2);
  // d = f - p, so every derivative with respect to p is minus the one with respect to d.
  m.H.setZero();
  m.H.block<1, 3>(0, 0) = -d.transpose() / r;
  m.H.block<1, 3>(1, 0) << d.y() / rho2, -d.x() / rho2, 0.0;
  m.H(1, 3) = -1.0;
  m.H.block<1, 3>(2, 0) << d.z() * d.x() / (rho * r2), d.z() * d.y() / (rho * r2), -rho / r2;
  const double sr = options_.range_sigma_m + options_.range_sigma_per_m2 * r2;
  const double sb = options_.bearing_sigma_rad;
  m.variances = {sr * sr, sb * sb, sb * sb};
}

FeatureMeasurement FeatureSensor::measure(const Config& q, int index) const {
  const Eigen::Vector3d d = env_.features()[index].position - position(q);
  const double rho = std::sqrt(std::max(d.head<2>().squaredNorm(), 1e-12));
  FeatureMeasurement m;
  m.z = {d.norm(), wrap_angle(std::atan2(d.y(), d.x()) - q[3]), std::atan2(d.z(), rho)};
  jacobian_and_noise(q, index, m);
  return m;
}

Mat4 FeatureSensor::information(const Config& q) const {
  Mat4 M = Mat4::Zero();
  FeatureMeasurement m;
  for (int i : visible(q)) {
    jacobian_and_noise(q, i, m);  // z is not needed here: two atan2 fewer per feature
    M += diagonal_information(m.H, m.variances);
  }
  return M;
}

Mat4 FeatureSensor::ukf_information(const Config& q, const Mat4& prior) const {
  // Eq. 27 with the estimator's sigma points, but never forming the 3k x 3k innovation
  // covariance S = Q + D W D^T (D: the 2n+1 centred predicted measurements, W: their
  // covariance weights). Q is diagonal, so with G = D^T Q^-1 D (9 x 9) the push-through
  // identity gives D^T S^-1 D = (I + G W)^-1 G, hence K S K^T = X W (I + G W)^-1 G W X^T:
  // linear in the number of measurements instead of cubic, and the same value as
  // gaussian::ukf_measurement_information (test UkfInformationEqualsTheGenericUkf).
  const std::vector<int> seen = visible(q);
  if (seen.empty()) return Mat4::Zero();
  const auto prior_llt = prior.llt();
  if (prior_llt.info() != Eigen::Success || !prior.allFinite())
    throw std::invalid_argument("ukf_information: prior covariance is not positive definite");
  const gaussian::UnscentedWeights w = gaussian::unscented_weights(4, {});
  const Eigen::Matrix<double, 4, Eigen::Dynamic> X = gaussian::sigma_offsets(prior, w);
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
  const Mat4 posterior = gaussian::update_covariance(prior, M);
  return 0.5 * (std::log(prior.determinant()) - std::log(posterior.determinant()));
}

}  // namespace kestrel::planner
