// IMU propagation: the discrete map, its exact Jacobians against finite differences, the
// structured process noise against information.h's R = V W V^T, and the structured covariance
// transform against the dense Phi P Phi^T.

#include <gtest/gtest.h>

#include <random>

#include "common/geometry/so3.h"
#include "estimator/filter.h"
#include "common/gaussian/information.h"
#include "estimator/propagation.h"
#include "test/support/numerical.h"

namespace kestrel::estimator {
namespace {

NavState random_state(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const auto v3 = [&](double s) { return Eigen::Vector3d(s * n(rng), s * n(rng), s * n(rng)); };
  NavState x;
  x.p_world_body = v3(2.0);
  x.v_world_body = v3(1.0);
  x.R_world_body = so3::exp(v3(1.0));
  x.gyro_bias = v3(0.02);
  x.accel_bias = v3(0.1);
  return x;
}

ImuInterval random_interval(std::mt19937& rng, double dt) {
  std::normal_distribution<double> n(0.0, 1.0);
  const auto v3 = [&](double s) { return Eigen::Vector3d(s * n(rng), s * n(rng), s * n(rng)); };
  ImuInterval u;
  u.dt = dt;
  u.gyro0 = v3(1.5);
  u.gyro1 = u.gyro0 + v3(0.2);
  u.accel0 = Eigen::Vector3d(0, 0, kStandardGravity) + v3(3.0);
  u.accel1 = u.accel0 + v3(0.5);
  return u;
}

TEST(Propagation, JacobianMatchesFiniteDifferences) {
  std::mt19937 rng(3);
  for (double dt : {0.005, 0.05}) {
    for (int trial = 0; trial < 20; ++trial) {
      const NavState x = random_state(rng);
      const ImuInterval u = random_interval(rng, dt);
      const ImuStep step = propagate(x, u, kStandardGravity);
      const Matrix15d F = step.phi.dense();
      const Matrix15d numeric = test::numerical_jacobian<15>([&](const Vector15d& d) -> Vector15d {
        return boxminus(propagate_mean(boxplus(x, d), u, kStandardGravity), step.next);
      });
      EXPECT_LT((F - numeric).cwiseAbs().maxCoeff(), 1e-6) << "dt " << dt << "\n" << F - numeric;
    }
  }
}

TEST(Propagation, ConstantRateAndAccelerationIsExact) {
  // Rotating at a constant body rate while the specific force, seen from the world, stays
  // constant: p(t) = p0 + v0 t + a t^2 / 2 and R(t) = R0 Exp(w t) exactly.
  NavState x;
  x.v_world_body = {0.5, -0.2, 0.1};
  const Eigen::Vector3d w(0.0, 0.0, 0.8);  // about world z = body z: gravity stays along z
  const Eigen::Vector3d a_world(0.3, 0.0, 0.0);
  const double dt = 0.01;
  NavState cur = x;
  double t = 0.0;
  for (int i = 0; i < 500; ++i, t += dt) {
    ImuInterval u;
    u.dt = dt;
    const Eigen::Matrix3d R0 = so3::exp(w * t), R1 = so3::exp(w * (t + dt));
    u.gyro0 = u.gyro1 = w;
    u.accel0 = R0.transpose() * (a_world + Eigen::Vector3d(0, 0, kStandardGravity));
    u.accel1 = R1.transpose() * (a_world + Eigen::Vector3d(0, 0, kStandardGravity));
    cur = propagate_mean(cur, u, kStandardGravity);
  }
  EXPECT_LT((cur.p_world_body - (x.v_world_body * t + 0.5 * a_world * t * t)).norm(), 1e-9);
  EXPECT_LT((cur.v_world_body - (x.v_world_body + a_world * t)).norm(), 1e-9);
  EXPECT_LT(so3::angle(cur.R_world_body.transpose() * so3::exp(w * t)), 1e-9);
}

TEST(Propagation, ProcessNoiseIsVWVt) {
  std::mt19937 rng(5);
  ImuNoise noise;
  for (bool gap : {false, true}) {
    const ImuStep step = propagate(random_state(rng), random_interval(rng, 0.005), kStandardGravity);
    const Matrix15d structured = process_noise(step.phi, noise, gap);
    const Matrix15d generic = gaussian::process_noise_diagonal(noise_jacobian(step.phi),
                                                     noise_variances(noise, step.phi.dt, gap));
    EXPECT_LT((structured - generic).cwiseAbs().maxCoeff(), 1e-18 + 1e-12 * generic.norm());
  }
}

TEST(Propagation, GapNoiseGrowsWithTheGap) {
  ImuNoise noise;
  Transition phi;
  phi.dt = 0.5;
  phi.v_ba = -phi.dt * Eigen::Matrix3d::Identity();
  const Matrix15d quiet = process_noise(phi, noise, false);
  const Matrix15d gap = process_noise(phi, noise, true);
  // Half a second of 2 m/s^2 unknown acceleration: about 1 m/s of velocity uncertainty.
  EXPECT_NEAR(std::sqrt(gap(idx::kV, idx::kV)), noise.gap_accel_sigma * phi.dt, 0.01);
  EXPECT_GT(gap(idx::kV, idx::kV), 100 * quiet(idx::kV, idx::kV));
}

TEST(Propagation, StructuredCovarianceTransformMatchesDenseProduct) {
  std::mt19937 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int clones = 0; clones <= kMaxClones; ++clones) {
    const int dim = idx::kNav + 6 * clones;
    Eigen::MatrixXd A(dim, dim);
    for (int i = 0; i < A.size(); ++i) A.data()[i] = n(rng);
    Covariance P = A * A.transpose();
    const ImuStep step = propagate(random_state(rng), random_interval(rng, 0.02), kStandardGravity);
    Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(dim, dim);
    Phi.topLeftCorner<15, 15>() = step.phi.dense();
    const Eigen::MatrixXd expected = Phi * P * Phi.transpose();
    transform_covariance(step.phi, P);
    EXPECT_LT((Eigen::MatrixXd(P) - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.norm())
        << "clones " << clones;
  }
}

}  // namespace
}  // namespace kestrel::estimator
