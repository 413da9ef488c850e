#include "estimator/measurements.h"

#include <Eigen/LU>
#include <limits>

#include "common/geometry/so3.h"

namespace kestrel::estimator {
namespace {

// g for a pose prediction T_h against an observation T_z: [t_h - t_z; Log(R_z^T R_h)].
Residual pose_residual(const Eigen::Isometry3d& T_h, const Eigen::Isometry3d& T_z) {
  Residual g(6);
  g.head<3>() = T_h.translation() - T_z.translation();
  g.tail<3>() = so3::log(T_z.linear().transpose() * T_h.linear());
  return g;
}

}  // namespace

RelativePoseMeasurement::RelativePoseMeasurement(int clone_index,
                                                 const Eigen::Isometry3d& T_refcam_curcam,
                                                 const Matrix6d& covariance,
                                                 const Eigen::Isometry3d& T_body_camera)
    : clone_(clone_index), z_(T_refcam_curcam), Q_(covariance), T_body_camera_(T_body_camera) {}

Eigen::Isometry3d RelativePoseMeasurement::predict(const FilterMean& x) const {
  const Clone& c = x.clones[static_cast<size_t>(clone_)];
  const Eigen::Isometry3d T_world_ref = se3::make(c.R_world_body, c.p_world_body);
  return T_body_camera_.inverse() * T_world_ref.inverse() * x.nav.T_world_body() * T_body_camera_;
}

Residual RelativePoseMeasurement::residual(const FilterMean& x) const {
  return pose_residual(predict(x), z_);
}

Matrix6d RelativePoseMeasurement::reference_block(const FilterMean& x, const Eigen::Matrix3d& Jr_inv) const {
  const Clone& c = x.clones[static_cast<size_t>(clone_)];
  const Eigen::Matrix3d& Rr = c.R_world_body;
  const Eigen::Matrix3d& Rc = x.nav.R_world_body;
  const Eigen::Matrix3d R_bc = T_body_camera_.linear();
  // Camera centre now, seen from the reference body frame.
  const Eigen::Vector3d d =
      Rr.transpose() * (x.nav.p_world_body + Rc * T_body_camera_.translation() - c.p_world_body);
  Matrix6d H_ref = Matrix6d::Zero();
  H_ref.topLeftCorner<3, 3>() = -(R_bc.transpose() * Rr.transpose());
  H_ref.topRightCorner<3, 3>() = R_bc.transpose() * so3::hat(d);
  H_ref.bottomRightCorner<3, 3>() = -Jr_inv * R_bc.transpose() * Rc.transpose() * Rr;
  return H_ref;
}

MeasurementJacobian RelativePoseMeasurement::jacobian(const FilterMean& x) const {
  const Clone& c = x.clones[static_cast<size_t>(clone_)];
  const Eigen::Matrix3d& Rc = x.nav.R_world_body;
  const Eigen::Matrix3d R_bc = T_body_camera_.linear();
  const Eigen::Vector3d t_bc = T_body_camera_.translation();
  const Eigen::Matrix3d A = R_bc.transpose() * c.R_world_body.transpose();
  const Eigen::Matrix3d Jr_inv = so3::right_jacobian_inverse(residual(x).tail<3>());

  MeasurementJacobian H = MeasurementJacobian::Zero(6, x.dim());
  H.block<3, 3>(0, idx::kP) = A;
  H.block<3, 3>(0, idx::kTheta) = -A * Rc * so3::hat(t_bc);
  H.block<3, 3>(3, idx::kTheta) = Jr_inv * R_bc.transpose();
  H.block<6, 6>(0, FilterMean::clone_offset(clone_)) = reference_block(x, Jr_inv);
  return H;
}

Matrix6d RelativePoseMeasurement::reference_covariance(const FilterMean& x,
                                                       const Matrix6d& Q_ref) const {
  // With J_r^-1 = I: the keyframe's error must not depend on how far this one update (perhaps
  // a gross one the gate refuses) lies from the state.
  const Matrix6d H_inv = reference_block(x, Eigen::Matrix3d::Identity()).partialPivLu().inverse();
  const Matrix6d C = H_inv * Q_ref * H_inv.transpose();
  return 0.5 * (C + C.transpose());
}

AbsolutePoseMeasurement::AbsolutePoseMeasurement(const Eigen::Isometry3d& T_world_body,
                                                 const Matrix6d& covariance)
    : z_(T_world_body), Q_(covariance) {}

Residual AbsolutePoseMeasurement::residual(const FilterMean& x) const {
  return pose_residual(x.nav.T_world_body(), z_);
}

MeasurementJacobian AbsolutePoseMeasurement::jacobian(const FilterMean& x) const {
  MeasurementJacobian H = MeasurementJacobian::Zero(6, x.dim());
  H.block<3, 3>(0, idx::kP).setIdentity();
  H.block<3, 3>(3, idx::kTheta) = so3::right_jacobian_inverse(residual(x).tail<3>());
  return H;
}

Innovation innovation(const Measurement& m, const FilterState& s) {
  Innovation in;
  in.y = -m.residual(s.mean);
  const MeasurementJacobian H = m.jacobian(s.mean);
  in.HP = H * s.P;
  in.S.compute(in.HP * H.transpose() + m.noise());
  in.valid = in.S.info() == Eigen::Success && in.y.allFinite();
  return in;
}

double Innovation::mahalanobis2() const {
  return valid ? y.dot(S.solve(y)) : std::numeric_limits<double>::infinity();
}

}  // namespace kestrel::estimator
