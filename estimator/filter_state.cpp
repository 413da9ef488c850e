#include "estimator/filter_state.h"

#include <cmath>

#include "common/geometry/so3.h"

namespace kestrel::estimator {

int FilterMean::find_clone(int64_t t) const {
  for (int i = 0; i < num_clones; ++i)
    if (clones[static_cast<size_t>(i)].utime == t) return i;
  return -1;
}

FilterMean boxplus(const FilterMean& x, const Eigen::Ref<const ErrorVector>& dx) {
  FilterMean out = x;
  out.nav = boxplus(x.nav, dx.head<idx::kNav>());
  for (int i = 0; i < x.num_clones; ++i) {
    const int o = FilterMean::clone_offset(i);
    Clone& c = out.clones[static_cast<size_t>(i)];
    c.p_world_body += dx.segment<3>(o);
    c.R_world_body = c.R_world_body * so3::exp(dx.segment<3>(o + 3));
  }
  return out;
}

ErrorVector boxminus(const FilterMean& a, const FilterMean& b) {
  ErrorVector dx(a.dim());
  dx.head<idx::kNav>() = boxminus(a.nav, b.nav);
  for (int i = 0; i < a.num_clones; ++i) {
    const int o = FilterMean::clone_offset(i);
    const Clone& ca = a.clones[static_cast<size_t>(i)];
    const Clone& cb = b.clones[static_cast<size_t>(i)];
    dx.segment<3>(o) = ca.p_world_body - cb.p_world_body;
    dx.segment<3>(o + 3) = so3::log(cb.R_world_body.transpose() * ca.R_world_body);
  }
  return dx;
}

bool FilterState::is_valid(bool check_symmetry) const {
  const int n = mean.dim();
  if (P.rows() != n || P.cols() != n || !mean.nav.all_finite()) return false;
  // NaN fails this too; a NaN from an update spreads over its whole row, diagonal included.
  if (!(P.diagonal().array() >= 0.0).all() || !P.diagonal().allFinite()) return false;
  if (!check_symmetry) {
    // A prediction only changes the navigation rows and columns: by symmetry, the leading
    // columns hold every entry it wrote.
    return P.leftCols<idx::kNav>().allFinite();
  }
  if (!P.allFinite()) return false;
  const double scale = std::max(1e-300, P.cwiseAbs().maxCoeff());
  return (P - P.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale;
}

void remove_clone(FilterState& s, int i) {
  const int n = s.mean.dim();
  const int o = FilterMean::clone_offset(i);
  const int tail = n - o - 6;
  // Shift the later blocks up and left over the removed one.
  if (tail > 0) {
    s.P.block(o, 0, tail, n) = s.P.block(o + 6, 0, tail, n).eval();
    s.P.block(0, o, n, tail) = s.P.block(0, o + 6, n, tail).eval();
  }
  s.P.conservativeResize(n - 6, n - 6);
  for (int k = i; k + 1 < s.mean.num_clones; ++k)
    s.mean.clones[static_cast<size_t>(k)] = s.mean.clones[static_cast<size_t>(k + 1)];
  --s.mean.num_clones;
}

void add_clone(FilterState& s) {
  if (s.mean.find_clone(s.mean.utime) >= 0) return;
  if (s.mean.num_clones == kMaxClones) remove_clone(s, 0);  // the oldest: clones sorted by utime
  const int n = s.mean.dim();
  Clone c;
  c.utime = s.mean.utime;
  c.p_world_body = s.mean.nav.p_world_body;
  c.R_world_body = s.mean.nav.R_world_body;
  s.mean.clones[static_cast<size_t>(s.mean.num_clones)] = c;
  ++s.mean.num_clones;
  // The clone's error is a copy of the current [dp; dtheta]: rows and columns copied.
  s.P.conservativeResize(n + 6, n + 6);
  s.P.block(n, 0, 3, n) = s.P.block(idx::kP, 0, 3, n);
  s.P.block(n + 3, 0, 3, n) = s.P.block(idx::kTheta, 0, 3, n);
  s.P.block(0, n, n, 3) = s.P.block(0, idx::kP, n, 3);
  s.P.block(0, n + 3, n, 3) = s.P.block(0, idx::kTheta, n, 3);
  s.P.block<3, 3>(n, n) = s.P.block<3, 3>(idx::kP, idx::kP);
  s.P.block<3, 3>(n, n + 3) = s.P.block<3, 3>(idx::kP, idx::kTheta);
  s.P.block<3, 3>(n + 3, n) = s.P.block<3, 3>(idx::kTheta, idx::kP);
  s.P.block<3, 3>(n + 3, n + 3) = s.P.block<3, 3>(idx::kTheta, idx::kTheta);
}

void inject(FilterState& s, const Eigen::Ref<const ErrorVector>& dx) {
  s.mean = boxplus(s.mean, dx);
  const int n = s.mean.dim();
  for (int b = -1; b < s.mean.num_clones; ++b) {
    const int o = b < 0 ? idx::kTheta : FilterMean::clone_offset(b) + 3;
    const Eigen::Matrix3d G = Eigen::Matrix3d::Identity() - 0.5 * so3::hat(dx.segment<3>(o));
    s.P.block(o, 0, 3, n) = (G * s.P.block(o, 0, 3, n)).eval();
    s.P.block(0, o, n, 3) = (s.P.block(0, o, n, 3) * G.transpose()).eval();
  }
  symmetrize(s.P);
}

Eigen::Isometry3d world_change(const Eigen::Isometry3d& ours, const Eigen::Isometry3d& theirs) {
  const Eigen::Matrix3d R_delta = theirs.linear() * ours.linear().transpose();
  Eigen::Isometry3d change = Eigen::Isometry3d::Identity();
  change.linear() = Eigen::AngleAxisd(std::atan2(R_delta(1, 0), R_delta(0, 0)), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  change.translation() = theirs.translation() - change.linear() * ours.translation();
  return change;
}

void change_world(FilterState& s, const Eigen::Isometry3d& change) {
  const Eigen::Matrix3d& R_z = change.linear();
  NavState& nav = s.mean.nav;
  nav.p_world_body = change * nav.p_world_body;
  nav.v_world_body = R_z * nav.v_world_body;
  nav.R_world_body = R_z * nav.R_world_body;
  turn_world_block(s.P, idx::kP, R_z);
  turn_world_block(s.P, idx::kV, R_z);
  for (int i = 0; i < s.mean.num_clones; ++i) {
    Clone& c = s.mean.clones[static_cast<size_t>(i)];
    c.p_world_body = change * c.p_world_body;
    c.R_world_body = R_z * c.R_world_body;
    turn_world_block(s.P, FilterMean::clone_offset(i), R_z);
  }
}

Eigen::Matrix4d world_change_covariance(const Eigen::Isometry3d& theirs, const Matrix6d& covariance) {
  // (dp, dyaw) of `theirs`, then the change's (dt, dyaw): an error dyaw turns the world about
  // `theirs`, not about the origin, so dt = dp - dyaw e_z x p.
  Eigen::Matrix<double, 4, 6> A = Eigen::Matrix<double, 4, 6>::Zero();
  A.topLeftCorner<3, 3>().setIdentity();
  A.block<1, 3>(3, 3) = (theirs.linear().transpose() * Eigen::Vector3d::UnitZ()).transpose();
  Eigen::Matrix4d B = Eigen::Matrix4d::Identity();
  B.block<3, 1>(0, 3) = -Eigen::Vector3d::UnitZ().cross(theirs.translation());
  return B * A * covariance * A.transpose() * B.transpose();
}

Eigen::Matrix<double, 6, 4> world_change_jacobian(const Eigen::Vector3d& p_world_body,
                                                  const Eigen::Matrix3d& R_world_body) {
  Eigen::Matrix<double, 6, 4> J = Eigen::Matrix<double, 6, 4>::Zero();
  J.topLeftCorner<3, 3>().setIdentity();
  J.block<3, 1>(0, 3) = Eigen::Vector3d::UnitZ().cross(p_world_body);
  J.block<3, 1>(3, 3) = R_world_body.transpose() * Eigen::Vector3d::UnitZ();
  return J;
}

void widen_for_world_change(FilterState& s, const Eigen::Matrix4d& sigma) {
  const int n = s.mean.dim();
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::ColMajor, kMaxDim, 4> J =
      Eigen::MatrixXd::Zero(n, 4);
  const NavState& nav = s.mean.nav;
  const Eigen::Matrix<double, 6, 4> J_pose = world_change_jacobian(nav.p_world_body, nav.R_world_body);
  J.middleRows<3>(idx::kP) = J_pose.topRows<3>();
  J.middleRows<3>(idx::kTheta) = J_pose.bottomRows<3>();
  J.block<3, 1>(idx::kV, 3) = Eigen::Vector3d::UnitZ().cross(nav.v_world_body);
  for (int i = 0; i < s.mean.num_clones; ++i) {
    const Clone& c = s.mean.clones[static_cast<size_t>(i)];
    J.middleRows<6>(FilterMean::clone_offset(i)) = world_change_jacobian(c.p_world_body, c.R_world_body);
  }
  s.P.noalias() += J * sigma * J.transpose();
  symmetrize(s.P);
}

}  // namespace kestrel::estimator
