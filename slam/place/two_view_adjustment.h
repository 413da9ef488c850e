#pragma once
// Two-frame sparse bundle adjustment (Ceres): the relative pose of two RGB-D keyframes and the
// 3-D points they share, from each point's pixel in both images and depth in both frames
// (depth fixes the scale that pixels alone leave free). Robust (Huber) on every residual.
//
// Parametrisation: T_a_b = T0 * (Exp(phi), rho) with xi = [rho; phi] — the right-perturbation
// convention of the pose graph (slam/posegraph/spaces.h) — so that the covariance of xi is
// directly that of a right perturbation of T_a_b.

#include <Eigen/Geometry>
#include <vector>

#include "common/camera.h"
#include "common/geometry/se3.h"

namespace kestrel::slam {

/// One point seen in both frames: pixel and depth (metres) in each.
struct TwoViewObservation {
  Eigen::Vector2d pixel_a, pixel_b;
  double depth_a = 0.0, depth_b = 0.0;
};

struct TwoViewOptions {
  double pixel_sigma = 1.0;        ///< pixel noise, pixels
  double depth_noise = 1.4e-3;     ///< depth sigma = depth_noise * z^2 (Khoshelham 2011), metres
  double depth_sigma_floor = 0.005;  ///< added in quadrature, metres
  double huber = 2.0;              ///< on whitened residuals (sigmas)
  int max_iterations = 20;
};

struct TwoViewResult {
  bool ok = false;
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();  ///< of xi = [rho; phi] (see above)
  std::vector<double> pixel_errors;        ///< per observation: the larger of its two reprojection errors
  double rms_px = 0.0;
};

/// Refines T_a_b (maps points of frame b into frame a) from `initial`.
TwoViewResult adjust_two_views(const PinholeCamera& camera_a, const PinholeCamera& camera_b,
                               const std::vector<TwoViewObservation>& observations,
                               const Eigen::Isometry3d& initial, const TwoViewOptions& options = {});

}  // namespace kestrel::slam
