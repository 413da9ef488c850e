#pragma once
// Non-linear refinement of the motion T_ref_cur between two frames from matched features, by
// minimising reprojection error: each match's current point projected into the reference image
// (and, bidirectionally, its reference point projected into the current image) against the
// measured feature position. The pose error is [dp; dtheta] with p = p_est + dp (reference frame)
// and R = R_est * Exp(dtheta) (current frame), the convention of every covariance in kestrel.
//
// Residuals are whitened: a pixel noise sigma_px plus, when depth_weighted, the depth noise of
// the projected point carried into the image (it stretches the error along the direction in
// which that point moves when its depth changes), then a Huber loss. Gauss-Newton uses the
// projection Jacobian at the predicted pixel; ESM averages it with the Jacobian at the measured
// pixel (where the prediction lands at the optimum), which converges in fewer iterations.
//
// With a DenseTerm, point-to-plane residuals of the current frame's depth grid against the
// reference's (DenseOptions) join the features': associated and linearised once at the start
// pose, then kept as a quadratic in the pose error (see motion_refinement.cpp); their
// information is added to the reported one.
//
// Invariant: `information` is the whitened Gauss-Newton information at the returned estimate,
// each measurement counted once (a reprojection residual carries the noise of two pixels, and
// a bidirectional pair measures the same two pixels twice); it is only as right as the pixel
// noise (pixel_sigma, or by default the spread the final residuals show across their depth
// direction) and the depth model (vo/README.md checks it against ground truth).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "common/camera.h"
#include "common/geometry/se3.h"
#include "vo/dense_depth.h"
#include "vo/options.h"

namespace kestrel::vo {

struct Correspondence {
  Eigen::Vector3d ref_point;   ///< metres, reference camera frame
  Eigen::Vector3d cur_point;   ///< metres, current camera frame
  Eigen::Vector2d ref_pixel;   ///< measured ideal pixel in the reference image
  Eigen::Vector2d cur_pixel;   ///< measured ideal pixel in the current image
  double ref_sigma_z = 0.0;    ///< depth standard deviation of ref_point, metres
  double cur_sigma_z = 0.0;
};

/// The dense geometric term (DenseOptions): current-frame grid points against the reference's
/// points and normals, associated by projection into the reference grid.
struct DenseTerm {
  const DenseDepth* ref = nullptr;
  const DenseDepth* cur = nullptr;
  DenseOptions options;
  double sigma_z_coeff = 0.0;   ///< depth noise sigma_z = coeff * z^2
  bool use_distortion = false;  ///< the grids are on the raw pixel grid of a distorted lens
};

struct RefinementResult {
  Eigen::Isometry3d T_ref_cur = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Zero();  ///< of the estimate: inverse of its covariance
  double rms_error_px = 0.0;                ///< unwhitened, over the residuals used
  double pixel_sigma = 0.0;                 ///< the pixel noise `information` assumes
  int iterations = 0;
  bool converged = false;
  int dense_residuals = 0;  ///< associated dense residuals at the estimate
};

/// Whether refine_motion() reports `information` (and `pixel_sigma`): a pass over the residuals
/// of its own, worth skipping for an estimate that only seeds another refinement.
enum class Information { kReport, kSkip };

/// Refines `T_ref_cur` over the correspondences whose index is in `use`. With Information::kSkip,
/// `information` stays zero and `pixel_sigma` 0.
RefinementResult refine_motion(const std::vector<Correspondence>& correspondences,
                               const std::vector<int>& use, const PinholeCamera& camera,
                               const Eigen::Isometry3d& T_ref_cur, const RefinementOptions& options,
                               const DenseTerm* dense = nullptr, Information report = Information::kReport);

/// Reprojection error (pixels) of correspondence `c` under `T_ref_cur`: the larger of the two
/// directions when bidirectional, else that of the reference point in the current image.
double reprojection_error_px(const Correspondence& c, const PinholeCamera& camera,
                             const Eigen::Isometry3d& T_ref_cur, bool bidirectional);

}  // namespace kestrel::vo
