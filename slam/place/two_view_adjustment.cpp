#include "slam/place/two_view_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <cmath>
#include <limits>

#include "common/geometry/so3.h"

namespace kestrel::slam {
namespace {

template <class T>
void project(const PinholeCamera& c, const T* p, T* uv) {
  uv[0] = T(c.fx) * p[0] / p[2] + T(c.cx);
  uv[1] = T(c.fy) * p[1] / p[2] + T(c.cy);
}

// The point X_b (in frame b) seen by camera b: pixel and depth.
struct ObservedInB {
  const PinholeCamera* camera;
  Eigen::Vector2d pixel;
  double depth;
  double pixel_sigma, depth_sigma;
  template <class T>
  bool operator()(const T* X_b, T* r) const {
    T uv[2];
    project(*camera, X_b, uv);
    r[0] = (uv[0] - T(pixel.x())) / T(pixel_sigma);
    r[1] = (uv[1] - T(pixel.y())) / T(pixel_sigma);
    r[2] = (X_b[2] - T(depth)) / T(depth_sigma);
    return true;
  }
};

// The same point seen by camera a through T_a_b = T0 (Exp(phi), rho).
struct ObservedInA {
  const PinholeCamera* camera;
  Eigen::Matrix3d R0;
  Eigen::Vector3d t0;
  Eigen::Vector2d pixel;
  double depth;
  double pixel_sigma, depth_sigma;
  template <class T>
  bool operator()(const T* xi, const T* X_b, T* r) const {
    T Y[3];
    ceres::AngleAxisRotatePoint(xi + 3, X_b, Y);
    for (int k = 0; k < 3; ++k) Y[k] += xi[k];
    T X_a[3];
    for (int k = 0; k < 3; ++k) {
      X_a[k] = T(R0(k, 0)) * Y[0] + T(R0(k, 1)) * Y[1] + T(R0(k, 2)) * Y[2] + T(t0(k));
    }
    T uv[2];
    project(*camera, X_a, uv);
    r[0] = (uv[0] - T(pixel.x())) / T(pixel_sigma);
    r[1] = (uv[1] - T(pixel.y())) / T(pixel_sigma);
    r[2] = (X_a[2] - T(depth)) / T(depth_sigma);
    return true;
  }
};

double depth_sigma(const TwoViewOptions& o, double z) {
  const double s = o.depth_noise * z * z;
  return std::sqrt(s * s + o.depth_sigma_floor * o.depth_sigma_floor);
}

}  // namespace

TwoViewResult adjust_two_views(const PinholeCamera& camera_a, const PinholeCamera& camera_b,
                               const std::vector<TwoViewObservation>& observations,
                               const Eigen::Isometry3d& initial, const TwoViewOptions& options) {
  TwoViewResult result;
  if (observations.size() < 3) return result;
  double xi[6] = {0, 0, 0, 0, 0, 0};
  std::vector<Eigen::Vector3d> points;
  points.reserve(observations.size());
  for (const auto& o : observations) {
    points.push_back(camera_b.backproject(o.pixel_b.x(), o.pixel_b.y(), o.depth_b));
  }
  const Eigen::Matrix3d R0 = initial.linear();
  const Eigen::Vector3d t0 = initial.translation();

  ceres::Problem::Options problem_options;
  ceres::Problem problem(problem_options);
  problem.AddParameterBlock(xi, 6);
  for (size_t i = 0; i < observations.size(); ++i) {
    const auto& o = observations[i];
    auto* in_b = new ceres::AutoDiffCostFunction<ObservedInB, 3, 3>(new ObservedInB{
        &camera_b, o.pixel_b, o.depth_b, options.pixel_sigma, depth_sigma(options, o.depth_b)});
    auto* in_a = new ceres::AutoDiffCostFunction<ObservedInA, 3, 6, 3>(new ObservedInA{
        &camera_a, R0, t0, o.pixel_a, o.depth_a, options.pixel_sigma, depth_sigma(options, o.depth_a)});
    problem.AddResidualBlock(in_b, new ceres::HuberLoss(options.huber), points[i].data());
    problem.AddResidualBlock(in_a, new ceres::HuberLoss(options.huber), xi, points[i].data());
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_SCHUR;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable()) return result;

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  covariance_options.num_threads = 1;
  ceres::Covariance covariance(covariance_options);
  const std::vector<std::pair<const double*, const double*>> blocks = {{xi, xi}};
  if (!covariance.Compute(blocks, &problem)) return result;
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> cov;
  covariance.GetCovarianceBlock(xi, xi, cov.data());

  Eigen::Isometry3d P = Eigen::Isometry3d::Identity();
  P.linear() = so3::exp(Eigen::Vector3d(xi[3], xi[4], xi[5]));
  P.translation() = Eigen::Vector3d(xi[0], xi[1], xi[2]);
  result.T_a_b = initial * P;
  result.covariance = cov;
  double sum = 0.0;
  for (size_t i = 0; i < observations.size(); ++i) {
    const Eigen::Vector3d X_a = result.T_a_b * points[i];
    const double e_b = (camera_b.project(points[i]) - observations[i].pixel_b).norm();
    const double e_a = X_a.z() > 0 ? (camera_a.project(X_a) - observations[i].pixel_a).norm()
                                   : std::numeric_limits<double>::infinity();
    result.pixel_errors.push_back(std::max(e_a, e_b));
    sum += e_a * e_a + e_b * e_b;
  }
  result.rms_px = std::sqrt(sum / (2.0 * static_cast<double>(observations.size())));
  result.ok = result.covariance.allFinite() && std::isfinite(result.rms_px);
  return result;
}

}  // namespace kestrel::slam
