#pragma once
// The navigation state the filters estimate, and its 15-dimensional error state.
//
// State: T_world_body as (p_world_body, R_world_body), v_world_body, and the gyro and
// accelerometer biases (added to the true rate / specific force in a reading). The error
// state follows state_t.lcm, in this order:
//   [dp (world); dv (world); dtheta (body); d_bg; d_ba]
// with p = p_est + dp, v = v_est + dv, R = R_est * Exp(dtheta), b = b_est + db. boxplus and
// boxminus are exact inverses of each other (for |dtheta| < pi).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kestrel::estimator {

using Vector15d = Eigen::Matrix<double, 15, 1>;
using Matrix15d = Eigen::Matrix<double, 15, 15>;

/// Offsets of the blocks in the 15-dimensional error state.
namespace idx {
inline constexpr int kP = 0;
inline constexpr int kV = 3;
inline constexpr int kTheta = 6;
inline constexpr int kBg = 9;
inline constexpr int kBa = 12;
inline constexpr int kNav = 15;  ///< dimension of the navigation error state
}  // namespace idx

struct NavState {
  Eigen::Vector3d p_world_body = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world_body = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_world_body = Eigen::Matrix3d::Identity();
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< rad/s
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  ///< m/s^2

  Eigen::Isometry3d T_world_body() const;
  bool all_finite() const;
};

/// x ⊞ dx: the state the error `dx` (15-vector, order above) points to from `x`.
NavState boxplus(const NavState& x, const Eigen::Ref<const Vector15d>& dx);
/// a ⊟ b: the error dx with boxplus(b, dx) = a.
Vector15d boxminus(const NavState& a, const NavState& b);

}  // namespace kestrel::estimator
