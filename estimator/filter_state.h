#pragma once
// The full filter state: the navigation state, up to kMaxClones cloned body poses, and the
// joint covariance.
//
// A clone is a copy of T_world_body taken at a past utime (a visual-odometry keyframe):
// stochastic cloning (Roumeliotis & Burdick 2002). Its error [dp (world); dtheta (body)]
// follows the navigation error in the state vector:
//   [nav (15) | clone 0 (6) | clone 1 (6) | ...]
// so the dimension is 15 + 6 * num_clones. A relative-pose measurement between a clone and
// now is then an ordinary measurement of the state, however long the keyframe is kept.
// Invariants: clones are ordered by utime, no two share a utime, P is symmetric and has the
// dimension of the mean.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "common/geometry/se3.h"
#include "estimator/nav_state.h"

namespace kestrel::estimator {

inline constexpr int kMaxClones = 3;
inline constexpr int kMaxDim = idx::kNav + 6 * kMaxClones;

/// Dynamic size up to kMaxDim, stored inline (no allocation at IMU rate).
using Covariance = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor,
                                 kMaxDim, kMaxDim>;
using ErrorVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxDim, 1>;

struct Clone {
  int64_t utime = 0;
  Eigen::Vector3d p_world_body = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_world_body = Eigen::Matrix3d::Identity();
  /// The VO reference frame whose own error (common to every update against it) has been
  /// added to this clone's covariance (estimator_events.cpp), -1 none: the clone then stands
  /// for the pose the VO believes that keyframe at, which is what its updates measure from.
  /// A reference, not a flag: an anchor's clone may also become a later reference's.
  int64_t keyframe_error_of = -1;
};

struct FilterMean {
  int64_t utime = 0;
  NavState nav;
  std::array<Clone, kMaxClones> clones{};
  int num_clones = 0;

  int dim() const { return idx::kNav + 6 * num_clones; }
  /// Index of the clone taken at `utime`, or -1.
  int find_clone(int64_t utime) const;
  /// Offset of clone i in the error state.
  static int clone_offset(int i) { return idx::kNav + 6 * i; }
};

/// x ⊞ dx for the whole state (dx has x.dim() entries).
FilterMean boxplus(const FilterMean& x, const Eigen::Ref<const ErrorVector>& dx);
/// a ⊟ b; a and b must hold clones at the same utimes.
ErrorVector boxminus(const FilterMean& a, const FilterMean& b);

struct FilterState {
  FilterMean mean;
  Covariance P;
  /// VO updates refused by the gate since the last one fused: kept with the state (not in
  /// the estimator) so that re-playing history reproduces it exactly.
  int vo_gated_in_row = 0;

  /// Symmetric, finite, of the right size, with a non-negative diagonal. Without
  /// check_symmetry, the cheap part of it for every IMU step: the diagonal and the
  /// navigation columns (a prediction writes only those and keeps P symmetric to rounding;
  /// updates symmetrise; the full check runs after every re-play).
  bool is_valid(bool check_symmetry = true) const;
};

/// Clones the current body pose at mean.utime (P grows by the copied rows and columns). When
/// kMaxClones are held already, the oldest is marginalised first. Does nothing if a clone at
/// this utime exists.
void add_clone(FilterState& s);
/// Marginalises clone i out of the state.
void remove_clone(FilterState& s, int i);

/// Moves the mean by an estimated error dx (after an update) and maps P into the error state
/// around the new mean: for each rotation block, dtheta_new = dtheta - dx_theta - dx_theta x
/// dtheta / 2 to first order, so P <- G P G^T with G = I - [dx_theta]x / 2 on those blocks.
void inject(FilterState& s, const Eigen::Ref<const ErrorVector>& dx);

/// The change of world x' = R_z x + t (R_z a turn about the vertical, which gravity leaves
/// free) that takes the pose `ours` onto `theirs` in position and yaw; their tilts are taken
/// to agree (both worlds level by gravity).
Eigen::Isometry3d world_change(const Eigen::Isometry3d& ours, const Eigen::Isometry3d& theirs);

/// Turns the rows and columns of a covariance at `block` (a world-frame 3-vector's error) by
/// R_z: the covariance's part of a change of world.
template <typename Matrix>
void turn_world_block(Matrix& P, int block, const Eigen::Matrix3d& R_z) {
  P.middleRows(block, 3) = (R_z * P.middleRows(block, 3)).eval();
  P.middleCols(block, 3) = (P.middleCols(block, 3) * R_z.transpose()).eval();
}

/// Expresses the state in another world frame (world_change): positions, velocity and
/// attitudes of the mean, and the world blocks of P (position and velocity errors; rotation
/// errors are in the body frame).
void change_world(FilterState& s, const Eigen::Isometry3d& change);

/// The uncertainty of a change of world taken onto `theirs` (world_change) when `theirs` is
/// known to `covariance` ([dp (world); dtheta (body)]), over the change's (translation, yaw
/// about the vertical): the pose changed onto `theirs` is then exactly as uncertain as
/// `theirs` in position and yaw, and others more so with their distance from it.
Eigen::Matrix4d world_change_covariance(const Eigen::Isometry3d& theirs, const Matrix6d& covariance);

/// How a pose's error [dp (world); dtheta (body)] moves under a small error (dt, dyaw) of a
/// change of world, at the pose after the change: dp = dt + dyaw e_z x p, dtheta = dyaw R^T e_z.
Eigen::Matrix<double, 6, 4> world_change_jacobian(const Eigen::Vector3d& p_world_body,
                                                  const Eigen::Matrix3d& R_world_body);

/// Adds the uncertainty `sigma` of the change of world just made (change_world) to P: the
/// position, velocity and attitude errors and every clone's move together with the world,
/// so measurements between them (VO) are unaffected and absolute ones (SLAM) are weighed
/// against the world's uncertainty rather than the old world's.
void widen_for_world_change(FilterState& s, const Eigen::Matrix4d& sigma);

/// Makes P exactly symmetric (rounding in the updates breaks it slowly): the filter's
/// Covariance and the visual-only estimator's fixed 6 x 6 blocks alike. Evaluated into a
/// temporary first: P and its transpose alias.
template <class Derived>
void symmetrize(Eigen::MatrixBase<Derived>& P) {
  P.derived() = 0.5 * (P + P.transpose()).eval();
}

}  // namespace kestrel::estimator
