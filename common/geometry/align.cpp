#include "common/geometry/align.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace kestrel {

std::optional<Eigen::Isometry3d> align_rigid(const Eigen::Matrix3Xd& src,
                                             const Eigen::Matrix3Xd& dst) {
  const Eigen::Index n = src.cols();
  if (n < 3 || dst.cols() != n) return std::nullopt;
  const Eigen::Vector3d mu_src = src.rowwise().mean();
  const Eigen::Vector3d mu_dst = dst.rowwise().mean();
  const Eigen::Matrix3Xd a = src.colwise() - mu_src;
  const Eigen::Matrix3Xd b = dst.colwise() - mu_dst;

  // Collinear points leave the rotation about their line free: the second singular value of
  // the spread of the source points vanishes.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread(a * a.transpose());
  const double largest = spread.eigenvalues()(2);
  if (!(largest > 0.0) || spread.eigenvalues()(1) < 1e-12 * largest) return std::nullopt;

  const Eigen::Matrix3d cov = b * a.transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * S * svd.matrixV().transpose();
  T.translation() = mu_dst - T.linear() * mu_src;
  if (!T.matrix().allFinite()) return std::nullopt;
  return T;
}

}  // namespace kestrel
