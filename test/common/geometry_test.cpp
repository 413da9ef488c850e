// One property harness for the rotation and rigid-transform helpers (the identities every
// Lie-group implementation must satisfy), run on random and near-singular samples.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/geometry/align.h"
#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "test/support/numerical.h"

namespace kestrel {
namespace {

std::vector<Eigen::Vector3d> rotation_samples() {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Eigen::Vector3d> out = {Eigen::Vector3d::Zero(), Eigen::Vector3d(1e-9, 0, 0),
                                      Eigen::Vector3d(0, 1e-5, -1e-5),
                                      Eigen::Vector3d(kPi - 1e-7, 0, 0),
                                      Eigen::Vector3d(0, 0, kPi * 0.999)};
  for (int i = 0; i < 50; ++i) {
    Eigen::Vector3d axis(n(rng), n(rng), n(rng));
    out.push_back(axis.normalized() * std::uniform_real_distribution<double>(0.0, 3.1)(rng));
  }
  return out;
}

TEST(So3, HatVeeAndCrossProduct) {
  const Eigen::Vector3d a(1, -2, 3), b(0.5, 4, -1);
  EXPECT_TRUE((so3::hat(a) * b).isApprox(a.cross(b)));
  EXPECT_TRUE(so3::vee(so3::hat(a)).isApprox(a));
}

TEST(So3, ExpMatchesAngleAxisAndLogInvertsIt) {
  for (const auto& phi : rotation_samples()) {
    const Eigen::Matrix3d R = so3::exp(phi);
    const double angle = phi.norm();
    const Eigen::Matrix3d expected =
        angle > 0 ? Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
    EXPECT_LT((R - expected).norm(), 1e-12) << phi.transpose();
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_LT((so3::log(R) - phi).norm(), 1e-9) << phi.transpose();
  }
}

TEST(So3, RightJacobianMatchesFiniteDifferences) {
  // Exp(phi + d) ~= Exp(phi) Exp(Jr(phi) d).
  const double h = 1e-6;
  for (const auto& phi : rotation_samples()) {
    if (phi.norm() > 3.0) continue;  // log is not smooth at pi
    const Eigen::Matrix3d numeric = test::numerical_jacobian<3>(
        [&](const Eigen::Vector3d& d) -> Eigen::Vector3d { return so3::log(so3::exp(phi).transpose() * so3::exp(phi + d)); }, h);
    EXPECT_LT((so3::right_jacobian(phi) - numeric).norm(), 1e-6) << phi.transpose();
    EXPECT_LT((so3::right_jacobian(phi) * so3::right_jacobian_inverse(phi) -
               Eigen::Matrix3d::Identity()).norm(), 1e-9);
  }
}

TEST(So3, OrthonormalizeRepairsDrift) {
  Eigen::Matrix3d R = so3::exp(Eigen::Vector3d(0.3, -0.2, 1.0));
  R(0, 1) += 1e-3;
  const Eigen::Matrix3d Q = so3::orthonormalize(R);
  EXPECT_LT((Q.transpose() * Q - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(Q.determinant(), 1.0, 1e-12);
  EXPECT_LT((Q - R).norm(), 2e-3);
}

std::vector<Eigen::Isometry3d> pose_samples() {
  std::vector<Eigen::Isometry3d> out;
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  for (const auto& phi : rotation_samples()) {
    out.push_back(se3::make(so3::exp(phi), Eigen::Vector3d(n(rng), n(rng), n(rng)) * 3.0));
  }
  return out;
}

TEST(Se3, ExpLogRoundTrip) {
  for (const auto& T : pose_samples()) {
    if (so3::angle(T.linear()) > 3.0) continue;
    const Eigen::Isometry3d back = se3::exp(se3::log(T));
    EXPECT_LT((back.matrix() - T.matrix()).norm(), 1e-9);
  }
}

TEST(Se3, AdjointConjugatesTheExponential) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 0.3);
  for (const auto& T : pose_samples()) {
    Vector6d xi;
    for (int i = 0; i < 6; ++i) xi[i] = n(rng);
    const Eigen::Isometry3d lhs = T * se3::exp(xi) * T.inverse();
    const Eigen::Isometry3d rhs = se3::exp(se3::adjoint(T) * xi);
    EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-9);
  }
}

TEST(Se3, BoxminusInvertsBoxplus) {
  Vector6d d;
  d << 0.1, -0.2, 0.3, 0.05, -0.4, 0.2;
  for (const auto& T : pose_samples()) {
    const Eigen::Isometry3d Tp = se3::boxplus(T, d);
    EXPECT_LT((se3::boxminus(Tp, T) - d).norm(), 1e-12);
    // Rotation perturbation is on the right: R_est * Exp(dtheta).
    EXPECT_LT((Tp.linear() - T.linear() * so3::exp(d.tail<3>())).norm(), 1e-12);
  }
}

TEST(Se3, InterpolateHitsEndsAndMidpoint) {
  const Eigen::Isometry3d A = se3::make(so3::exp(Eigen::Vector3d(0, 0, 0.2)), Eigen::Vector3d(1, 2, 3));
  const Eigen::Isometry3d B = se3::make(so3::exp(Eigen::Vector3d(0, 0, 0.8)), Eigen::Vector3d(3, 2, 1));
  EXPECT_TRUE(se3::interpolate(A, B, 0.0).isApprox(A));
  EXPECT_TRUE(se3::interpolate(A, B, 1.0).isApprox(B));
  const Eigen::Isometry3d M = se3::interpolate(A, B, 0.5);
  EXPECT_TRUE(M.translation().isApprox(Eigen::Vector3d(2, 2, 2)));
  EXPECT_NEAR(so3::log(M.linear()).z(), 0.5, 1e-12);
}

TEST(So3, ValidityRejectsReflectionsScalingAndNan) {
  EXPECT_TRUE(so3::is_valid(so3::exp(Eigen::Vector3d(0.3, -1.2, 2.0)), 1e-12));
  EXPECT_FALSE(so3::is_valid(Eigen::Vector3d(1, 1, -1).asDiagonal().toDenseMatrix()));  // det -1
  EXPECT_FALSE(so3::is_valid(1.001 * Eigen::Matrix3d::Identity(), 1e-6));
  EXPECT_TRUE(so3::is_valid(1.001 * Eigen::Matrix3d::Identity(), 1e-2));
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R(2, 1) = std::nan("");
  EXPECT_FALSE(so3::is_valid(R, 1e9));
}

TEST(Se3, ValidityRejectsNanAndNonRotations) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  EXPECT_TRUE(se3::is_valid(T));
  T.linear()(0, 0) = 2.0;
  EXPECT_FALSE(se3::is_valid(T));
  T = Eigen::Isometry3d::Identity();
  T.translation().x() = std::nan("");
  EXPECT_FALSE(se3::is_valid(T));
}

TEST(AlignRigid, RecoversAKnownTransformExactly) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Eigen::Matrix3Xd src(3, 20);
  for (int i = 0; i < 20; ++i) src.col(i) = Eigen::Vector3d(u(rng), u(rng), u(rng));
  const Eigen::Isometry3d T = se3::make(so3::exp(Eigen::Vector3d(0.4, -1.2, 2.0)), Eigen::Vector3d(3, -1, 0.5));
  const Eigen::Matrix3Xd dst = T * src;
  const auto est = align_rigid(src, dst);
  ASSERT_TRUE(est.has_value());
  EXPECT_LT((est->matrix() - T.matrix()).norm(), 1e-10);
}

TEST(AlignRigid, NeverReturnsAReflection) {
  // A mirrored copy: the best rotation is not the mirror.
  // The origin and the three unit points (set one by one: GCC's -O1 takes the comma
  // initialiser's copy for a read of uninitialised memory).
  Eigen::Matrix3Xd src = Eigen::Matrix3Xd::Zero(3, 4);
  src(0, 1) = src(1, 2) = src(2, 3) = 1.0;
  Eigen::Matrix3Xd dst = src;
  dst.row(2) *= -1.0;
  const auto est = align_rigid(src, dst);
  ASSERT_TRUE(est.has_value());
  EXPECT_NEAR(est->linear().determinant(), 1.0, 1e-12);
}

TEST(AlignRigid, RefusesDegenerateInput) {
  Eigen::Matrix3Xd two(3, 2);
  two.setRandom();
  EXPECT_FALSE(align_rigid(two, two).has_value());
  Eigen::Matrix3Xd line(3, 5);
  for (int i = 0; i < 5; ++i) line.col(i) = Eigen::Vector3d(1, 2, 3) * i;
  EXPECT_FALSE(align_rigid(line, line).has_value());
}

}  // namespace
}  // namespace kestrel
