#pragma once
// Measurement models of the filter state, in the form both filters use: a residual g(x) =
// prediction minus observation in the observation's tangent space (zero at the true state
// without noise), its Jacobian H = dg/d(dx) with respect to the error state, and the noise
// covariance Q of g. The EKF linearises g once (H); the UKF evaluates g at sigma points.
//
// Pose observations use the message convention [dp; dtheta], p = p_obs + dp (parent frame),
// R = R_obs Exp(dtheta) (child frame), so a covariance from a message is Q as it is.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/geometry/se3.h"
#include "estimator/filter_state.h"

namespace kestrel::estimator {

inline constexpr int kMaxMeasurementDim = 6;
using Residual = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxMeasurementDim, 1>;
using MeasurementJacobian = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor,
                                          kMaxMeasurementDim, kMaxDim>;
using MeasurementNoise = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor,
                                       kMaxMeasurementDim, kMaxMeasurementDim>;

class Measurement {
 public:
  virtual ~Measurement() = default;
  virtual Residual residual(const FilterMean& x) const = 0;
  virtual MeasurementJacobian jacobian(const FilterMean& x) const = 0;
  virtual const MeasurementNoise& noise() const = 0;
};

/// Visual odometry: T_refcam_curcam, the camera's motion from the pose cloned at the
/// reference frame to the current body pose, seen through the camera mounting T_body_camera.
class RelativePoseMeasurement final : public Measurement {
 public:
  RelativePoseMeasurement(int clone_index, const Eigen::Isometry3d& T_refcam_curcam,
                          const Matrix6d& covariance, const Eigen::Isometry3d& T_body_camera);
  Residual residual(const FilterMean& x) const override;
  MeasurementJacobian jacobian(const FilterMean& x) const override;
  const MeasurementNoise& noise() const override { return Q_; }

  /// The camera motion the state x predicts.
  Eigen::Isometry3d predict(const FilterMean& x) const;
  /// The error of the reference clone that moves the prediction by an error of covariance
  /// Q_ref: H_r^-1 Q_ref H_r^-T, H_r the Jacobian's clone block at x with J_r^-1 taken as I
  /// (block triangular with rotations on the diagonal: always invertible).
  Matrix6d reference_covariance(const FilterMean& x, const Matrix6d& Q_ref) const;

 private:
  /// The Jacobian's block of the reference clone, with J_r^-1 given.
  Matrix6d reference_block(const FilterMean& x, const Eigen::Matrix3d& Jr_inv) const;

  int clone_;
  Eigen::Isometry3d z_;
  MeasurementNoise Q_;
  Eigen::Isometry3d T_body_camera_;
};

/// A measurement's innovation y = -g(x) at the state, linearised there: H P and the factored
/// S = H P H^T + Q, what the EKF update and the tests of how far a measurement lies from what
/// the state expects need. `valid` is false when S is not positive definite or y not finite.
struct Innovation {
  Residual y;
  MeasurementJacobian HP;
  Eigen::LLT<MeasurementNoise> S;
  bool valid = false;

  /// y^T S^-1 y (chi^2 with dim(y) degrees of freedom); infinity when not valid.
  double mahalanobis2() const;
};
Innovation innovation(const Measurement& m, const FilterState& s);

/// An absolute body pose T_world_body (a SLAM correction) at the state's time.
class AbsolutePoseMeasurement final : public Measurement {
 public:
  AbsolutePoseMeasurement(const Eigen::Isometry3d& T_world_body, const Matrix6d& covariance);
  Residual residual(const FilterMean& x) const override;
  MeasurementJacobian jacobian(const FilterMean& x) const override;
  const MeasurementNoise& noise() const override { return Q_; }

 private:
  Eigen::Isometry3d z_;
  MeasurementNoise Q_;
};

}  // namespace kestrel::estimator
