#include "metrics/alignment.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <stdexcept>
#include <utility>
#include <vector>

#include "common/geometry/align.h"

namespace kestrel::metrics {
namespace {

// Positions closer than this to their mean count as one point (metres).
constexpr double kCoincident_m = 1e-9;

}  // namespace

Alignment align_poses(const Trajectory& est, const Trajectory& gt, int64_t max_gap_us) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  std::vector<std::pair<Eigen::Isometry3d, Eigen::Isometry3d>> pairs;  // (est, gt)
  for (const StampedPose& p : est.poses()) {
    if (const auto t = gt.at(p.utime, max_gap_us)) {
      pairs.emplace_back(p.T, *t);
      sum += t->linear() * p.T.linear().transpose();
    }
  }
  if (pairs.empty()) throw std::invalid_argument("align_poses: the ground truth covers no pose of the estimate");
  // The rotation nearest (Frobenius) to the sum: U diag(1, 1, det) V^T of its SVD.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  Alignment a;
  a.kind = AlignmentKind::kRigid;
  a.T_gt_est.linear() = svd.matrixU() * D * svd.matrixV().transpose();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (const auto& [T_est, T_gt] : pairs) t += T_gt.translation() - a.T_gt_est.linear() * T_est.translation();
  a.T_gt_est.translation() = t / static_cast<double>(pairs.size());
  return a;
}

Alignment align_positions(const Eigen::Matrix3Xd& p_est, const Eigen::Matrix3Xd& p_gt) {
  if (p_est.cols() == 0 || p_est.cols() != p_gt.cols())
    throw std::invalid_argument("align_positions: need the same number (>= 1) of points");
  Alignment result;
  if (const auto T = align_rigid(p_est, p_gt)) {
    result.T_gt_est = *T;
    result.kind = AlignmentKind::kRigid;
    return result;
  }
  const Eigen::Vector3d mean_est = p_est.rowwise().mean();
  const Eigen::Vector3d mean_gt = p_gt.rowwise().mean();
  const Eigen::Matrix3Xd a = p_est.colwise() - mean_est;
  const Eigen::Matrix3Xd b = p_gt.colwise() - mean_gt;

  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (a.colwise().norm().maxCoeff() <= kCoincident_m) {
    result.kind = AlignmentKind::kTranslation;
  } else {
    result.kind = AlignmentKind::kCollinear;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread(a * a.transpose());
    const Eigen::Vector3d d = spread.eigenvectors().col(2);
    const Eigen::Vector3d v = b * (a.transpose() * d);
    if (v.norm() > 0.0) R = Eigen::Quaterniond::FromTwoVectors(d, v).toRotationMatrix();
  }
  result.T_gt_est.linear() = R;
  result.T_gt_est.translation() = mean_gt - R * mean_est;
  return result;
}

const char* to_string(AlignmentKind kind) {
  switch (kind) {
    case AlignmentKind::kNone:
      return "none";
    case AlignmentKind::kRigid:
      return "rigid";
    case AlignmentKind::kCollinear:
      return "rigid (estimate collinear: rotation about its line is free)";
    case AlignmentKind::kTranslation:
      return "translation only (estimate never moves: rotation is free)";
  }
  return "?";
}

}  // namespace kestrel::metrics
