#include "estimator/propagation.h"

#include "common/geometry/so3.h"
#include "common/numbers.h"

namespace kestrel::estimator {

Matrix15d Transition::dense() const {
  Matrix15d F = Matrix15d::Identity();
  F.block<3, 3>(idx::kP, idx::kV) = dt * Eigen::Matrix3d::Identity();
  F.block<3, 3>(idx::kP, idx::kTheta) = 0.5 * dt * v_theta;
  F.block<3, 3>(idx::kP, idx::kBg) = 0.5 * dt * v_bg;
  F.block<3, 3>(idx::kP, idx::kBa) = 0.5 * dt * v_ba;
  F.block<3, 3>(idx::kV, idx::kTheta) = v_theta;
  F.block<3, 3>(idx::kV, idx::kBg) = v_bg;
  F.block<3, 3>(idx::kV, idx::kBa) = v_ba;
  F.block<3, 3>(idx::kTheta, idx::kTheta) = theta_theta;
  F.block<3, 3>(idx::kTheta, idx::kBg) = theta_bg;
  return F;
}

namespace {

struct MeanStep {
  NavState next;
  Eigen::Matrix3d dR;     // Exp(w dt)
  Eigen::Vector3d w_dt;   // bias-corrected rotation of the step
  Eigen::Vector3d a0, a1; // bias-corrected specific forces
};

MeanStep integrate(const NavState& x, const ImuInterval& u, double gravity) {
  MeanStep s;
  // Rotation vector of a rate varying linearly over the step, to third order: the mean rate
  // plus the coning term (w0 x w1) dt^2 / 12.
  const Eigen::Vector3d w0 = u.gyro0 - x.gyro_bias, w1 = u.gyro1 - x.gyro_bias;
  s.w_dt = 0.5 * (w0 + w1) * u.dt + (u.dt * u.dt / 12.0) * w0.cross(w1);
  s.dR = so3::exp(s.w_dt);
  s.a0 = u.accel0 - x.accel_bias;
  s.a1 = u.accel1 - x.accel_bias;
  NavState& n = s.next;
  n.R_world_body = x.R_world_body * s.dR;
  Eigen::Vector3d a_world = 0.5 * (x.R_world_body * s.a0 + n.R_world_body * s.a1);
  a_world.z() -= gravity;
  n.v_world_body = x.v_world_body + a_world * u.dt;
  n.p_world_body = x.p_world_body + x.v_world_body * u.dt + 0.5 * u.dt * u.dt * a_world;
  n.gyro_bias = x.gyro_bias;
  n.accel_bias = x.accel_bias;
  return s;
}

}  // namespace

NavState propagate_mean(const NavState& x, const ImuInterval& u, double gravity) {
  return integrate(x, u, gravity).next;
}

ImuStep propagate(const NavState& x, const ImuInterval& u, double gravity) {
  const MeanStep s = integrate(x, u, gravity);
  const double dt = u.dt;
  const Eigen::Matrix3d& R0 = x.R_world_body;
  const Eigen::Matrix3d& R1 = s.next.R_world_body;
  ImuStep step;
  step.next = s.next;
  Transition& phi = step.phi;
  phi.dt = dt;
  // theta' = Exp(-w dt) theta + Jr(w dt) d(w dt)/d(b_g) d_bg.
  phi.theta_theta = s.dR.transpose();
  const Eigen::Matrix3d dwdt_dbg =
      -dt * Eigen::Matrix3d::Identity() + (dt * dt / 12.0) * so3::hat(u.gyro1 - u.gyro0);
  phi.theta_bg = so3::right_jacobian(s.w_dt) * dwdt_dbg;
  // v' = v + dt/2 (R0 Exp(theta) a0 + R1 Exp(theta') a1) + ...
  const Eigen::Matrix3d R1_a1x = R1 * so3::hat(s.a1);
  phi.v_theta = -0.5 * dt * (R0 * so3::hat(s.a0) + R1_a1x * phi.theta_theta);
  phi.v_bg = -0.5 * dt * R1_a1x * phi.theta_bg;
  phi.v_ba = -0.5 * dt * (R0 + R1);
  return step;
}

NoiseJacobian noise_jacobian(const Transition& phi) {
  NoiseJacobian V = NoiseJacobian::Zero();
  const double h = 0.5 * phi.dt;
  // Reading noise acts like a bias error over the step.
  V.block<3, 3>(idx::kP, 0) = h * phi.v_bg;
  V.block<3, 3>(idx::kV, 0) = phi.v_bg;
  V.block<3, 3>(idx::kTheta, 0) = phi.theta_bg;
  V.block<3, 3>(idx::kP, 3) = h * phi.v_ba;
  V.block<3, 3>(idx::kV, 3) = phi.v_ba;
  V.block<3, 3>(idx::kBg, 6) = phi.dt * Eigen::Matrix3d::Identity();
  V.block<3, 3>(idx::kBa, 9) = phi.dt * Eigen::Matrix3d::Identity();
  return V;
}

Eigen::Matrix<double, 12, 1> noise_variances(const ImuNoise& noise, double dt, bool gap) {
  double gyro = sq(noise.gyro_noise_density) / dt;
  double accel = sq(noise.accel_noise_density) / dt;
  if (gap) {
    gyro += sq(noise.gap_gyro_sigma);
    accel += sq(noise.gap_accel_sigma);
  }
  Eigen::Matrix<double, 12, 1> w;
  w << Eigen::Vector3d::Constant(gyro), Eigen::Vector3d::Constant(accel),
      Eigen::Vector3d::Constant(sq(noise.gyro_bias_random_walk) / dt),
      Eigen::Vector3d::Constant(sq(noise.accel_bias_random_walk) / dt);
  return w;
}

Matrix15d process_noise(const Transition& phi, const ImuNoise& noise, bool gap) {
  const Eigen::Matrix<double, 12, 1> w = noise_variances(noise, phi.dt, gap);
  const double qg = w[0], qa = w[3], qbg = w[6], qba = w[9];
  const double h = 0.5 * phi.dt;
  // Columns of V for the gyro noise (rows p, v, theta) and the accel noise (rows p, v).
  Eigen::Matrix<double, 9, 3> Vg;
  Vg << h * phi.v_bg, phi.v_bg, phi.theta_bg;
  Eigen::Matrix<double, 6, 3> Va;
  Va << h * phi.v_ba, phi.v_ba;
  Matrix15d Q = Matrix15d::Zero();
  Q.topLeftCorner<9, 9>().noalias() = qg * Vg * Vg.transpose();
  Q.topLeftCorner<6, 6>().noalias() += qa * Va * Va.transpose();
  const double dt2 = phi.dt * phi.dt;
  Q.block<3, 3>(idx::kBg, idx::kBg).diagonal().setConstant(qbg * dt2);
  Q.block<3, 3>(idx::kBa, idx::kBa).diagonal().setConstant(qba * dt2);
  return Q;
}

void interpolate_reading(const ImuInterval& u, double s, Eigen::Vector3d& gyro,
                         Eigen::Vector3d& accel) {
  gyro = u.gyro0 + s * (u.gyro1 - u.gyro0);
  accel = u.accel0 + s * (u.accel1 - u.accel0);
}

}  // namespace kestrel::estimator
